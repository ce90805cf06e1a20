# Large worlds and real data (large worlds): rasters through GDAL, terrain
# holes.  test_gdal writes its GeoTIFFs with GDAL's C API; the colorado twin
# builds examples/colorado from GeoTIFFs made from its PNGs at test time
# (gen_geotiff) and checks it gives the same pack; test_holes renders holes.

add_executable(test_gdal ${CMAKE_CURRENT_LIST_DIR}/test_gdal.c)
target_link_libraries(test_gdal splatc PkgConfig::CMOCKA PkgConfig::GDAL)
add_test(NAME world.test_gdal COMMAND test_gdal WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
set_tests_properties(world.test_gdal PROPERTIES LABELS unit)

add_executable(gen_geotiff ${CMAKE_CURRENT_LIST_DIR}/gen_geotiff.c)
target_link_libraries(gen_geotiff splatc PkgConfig::GDAL)

if(TARGET splatc_cli)
  add_test(NAME world.colorado_geotiff_twin
           COMMAND sh ${CMAKE_CURRENT_LIST_DIR}/colorado_twin.sh
                   $<TARGET_FILE:splatc_cli> $<TARGET_FILE:gen_geotiff>
                   ${CMAKE_CURRENT_BINARY_DIR}/colorado_twin
           WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
  set_tests_properties(world.colorado_geotiff_twin PROPERTIES LABELS cli TIMEOUT 600)
endif()

# Terrain holes on the device (label `render`, SPLAT_VALIDATE=1): a GeoTIFF
# with nodata and a painted holes mask over a spike, built and rendered.
if(TARGET splatrt)
  set(HOLES_OUT ${CMAKE_BINARY_DIR}/tests/holes)
  file(MAKE_DIRECTORY ${HOLES_OUT})
  add_executable(test_holes ${CMAKE_CURRENT_LIST_DIR}/test_holes.c)
  target_link_libraries(test_holes splat_testkit PkgConfig::GDAL)
  add_test(NAME world.holes COMMAND test_holes ${HOLES_OUT}
           WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
  set_tests_properties(world.holes PROPERTIES LABELS render TIMEOUT 600
                       ENVIRONMENT "SPLAT_VALIDATE=1")
endif()

# Shading far from the origin (label `render`, SPLAT_VALIDATE=1): the same
# three views (straight down inside a patch; low over a corner where four
# 10 km patches meet; the same over four 320 km patches) near the origin
# and 100 / 1,000 / 5,000 km away on a 10,240 km terrain, forward and
# screen-space (rasterised and ray-cast depth): at most 0.5 % of the
# pixels over 8/255 and no line of differing pixels (issue 34), the noise
# mask against the double-precision reference.
if(TARGET splatrt)
  set(FAR_OUT ${CMAKE_BINARY_DIR}/tests/far)
  file(MAKE_DIRECTORY ${FAR_OUT})
  add_executable(test_far ${CMAKE_CURRENT_LIST_DIR}/test_far.c)
  target_link_libraries(test_far splat_testkit)
  add_test(NAME world.far COMMAND test_far ${FAR_OUT}
           WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
  set_tests_properties(world.far PROPERTIES LABELS render TIMEOUT 600
                       ENVIRONMENT "SPLAT_VALIDATE=1")
endif()

# A painted mask at its own resolution (label `render`, SPLAT_VALIDATE=1): a
# 1 px/m road mask over 10 x 10 km of colorado (10^8 texels) placed with
# { origin, size }: build memory, sparse share, road widths in the mask
# view, composites against the über-shader.
if(TARGET splatrt)
  set(PLACED_OUT ${CMAKE_BINARY_DIR}/tests/placed)
  file(MAKE_DIRECTORY ${PLACED_OUT})
  add_executable(test_placed ${CMAKE_CURRENT_LIST_DIR}/test_placed.c)
  target_link_libraries(test_placed splat_testkit PkgConfig::GDAL)
  add_test(NAME world.placed_mask COMMAND test_placed ${PLACED_OUT}
           WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
  set_tests_properties(world.placed_mask PROPERTIES LABELS render TIMEOUT 600
                       ENVIRONMENT "SPLAT_VALIDATE=1")
endif()
