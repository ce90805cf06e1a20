# Benchmarks: splatbench renders pack variants side by side on
# fixed camera paths; tests/bench/run.sh drives it (`make bench`, 20 min on
# lavapipe) and its smoke mode is this suite's one test (label `bench`): a
# few small frames of examples/minimal through the whole pipeline, so the
# benchmark cannot rot.  Figures are printed, never asserted (compiler/DESIGN.md §9).
if(TARGET splatrt AND TARGET splatview AND TARGET splatc_cli)
  add_executable(splatbench ${CMAKE_CURRENT_LIST_DIR}/splatbench.c
                 ${CMAKE_CURRENT_LIST_DIR}/bench_util.c ${CMAKE_CURRENT_LIST_DIR}/bench_tools.c
                 ${CMAKE_CURRENT_LIST_DIR}/bench_device.c ${CMAKE_CURRENT_LIST_DIR}/bench_lanes.c)
  target_link_libraries(splatbench splatrt)
  add_test(NAME bench.smoke
    COMMAND sh ${CMAKE_CURRENT_LIST_DIR}/run.sh ${CMAKE_BINARY_DIR} --smoke
            --out ${CMAKE_BINARY_DIR}/tests/bench/smoke
    WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
  set_tests_properties(bench.smoke PROPERTIES LABELS bench TIMEOUT 600)
  # splatbench --lanes (bench_lanes.c): its model of subgroup efficiency
  # against the device's own counters, on the render tests' minimal pack
  if(TARGET splatc_cli)
    add_test(NAME bench.lanes
      COMMAND sh ${CMAKE_CURRENT_LIST_DIR}/lanes_check.sh $<TARGET_FILE:splatbench>
              ${CMAKE_BINARY_DIR}/tests/render/minimal ${CMAKE_BINARY_DIR}/tests/bench/lanes)
    set_tests_properties(bench.lanes PROPERTIES LABELS render TIMEOUT 300
      FIXTURES_REQUIRED minimal_pack ENVIRONMENT "SPLAT_VALIDATE=1")
  endif()
endif()

# The scaled-down synthetic world (gen_world.c: B biomes x M materials with
# painted biome masks on an fBm heightfield; issue 29), 4 x 8 + 1 = 33
# materials, more than colorado's 15: test_world.c asserts the analysis's
# structure on it (combinations from leaf cells only, none a coarse node's
# union, the largest within the largest leaf overlap, merging covering every
# leaf within its bound, sound at random points), then world.sh builds its
# pack with --max-combinations and reads the build report.
# peakrss: wall time and peak memory of a command where GNU time is not
# installed (scale_world.sh, the scale_world group of `make bench`)
add_executable(peakrss ${CMAKE_CURRENT_LIST_DIR}/peakrss.c)
if(TARGET splatc)
  add_executable(gen_world ${CMAKE_CURRENT_LIST_DIR}/gen_world.c)
  target_link_libraries(gen_world splatc m)
  if(TARGET splat_unit_helpers)
    add_executable(test_world ${CMAKE_CURRENT_LIST_DIR}/test_world.c)
    target_link_libraries(test_world splatc splat_unit_helpers PkgConfig::CMOCKA m)
    set(WORLD_OUT ${CMAKE_BINARY_DIR}/tests/bench/world)
    add_test(NAME bench.world_gen
      COMMAND sh -c "rm -rf '${WORLD_OUT}' && mkdir -p '${WORLD_OUT}' && '$<TARGET_FILE:gen_world>' '${WORLD_OUT}' 4 8 512 16")
    set_tests_properties(bench.world_gen PROPERTIES LABELS unit FIXTURES_SETUP world_scene)
    add_test(NAME bench.world_structure COMMAND test_world ${WORLD_OUT}
             WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
    set_tests_properties(bench.world_structure PROPERTIES LABELS unit
                         FIXTURES_REQUIRED world_scene TIMEOUT 300)
    if(TARGET splatc_cli)
      # gen_world --textures (a texture each, two sizes): the pack builds,
      # every texture a layer of one of at most 20 arrays (two here)
      add_test(NAME bench.world_textures
        COMMAND sh ${CMAKE_CURRENT_LIST_DIR}/world_textures.sh $<TARGET_FILE:gen_world>
                $<TARGET_FILE:splatc_cli> ${CMAKE_BINARY_DIR}/tests/bench/world_textures
        WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
      set_tests_properties(bench.world_textures PROPERTIES LABELS cli TIMEOUT 600)
      add_test(NAME bench.world_merge
        COMMAND sh ${CMAKE_CURRENT_LIST_DIR}/world.sh $<TARGET_FILE:splatc_cli> ${WORLD_OUT}
        WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
      set_tests_properties(bench.world_merge PROPERTIES LABELS cli
                           FIXTURES_REQUIRED world_scene TIMEOUT 600)
      if(TARGET splatview)
        # 265 materials cost what 9 do at a view inside one biome: every
        # tile classified (material sets past 256 bits), the same layers
        # and samples per pixel, the same picture (issue 29)
        add_test(NAME bench.world_presence
          COMMAND sh ${CMAKE_CURRENT_LIST_DIR}/world_presence.sh $<TARGET_FILE:gen_world>
                  $<TARGET_FILE:splatc_cli> $<TARGET_FILE:splatview> $<TARGET_FILE:imgcheck>
                  ${CMAKE_BINARY_DIR}/tests/bench/world_presence
          WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
        set_tests_properties(bench.world_presence PROPERTIES LABELS render TIMEOUT 900
                             ENVIRONMENT "SPLAT_VALIDATE=1")
      endif()
      if(TARGET splatrt AND TARGET splatview)
        # uber_deep.sh: 105 layers seen deep in the über-shader's chain; it
        # draws what the composites draw on both paths (issue 29); imgcheck
        # is the render suite's (included after this one, on the same terms)
        add_test(NAME bench.uber_deep
          COMMAND sh ${CMAKE_CURRENT_LIST_DIR}/uber_deep.sh $<TARGET_FILE:gen_world>
                  $<TARGET_FILE:splatc_cli> $<TARGET_FILE:splatview> $<TARGET_FILE:imgcheck>
                  ${CMAKE_BINARY_DIR}/tests/bench/uber_deep
          WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
        set_tests_properties(bench.uber_deep PROPERTIES LABELS render TIMEOUT 600)
      endif()
    endif()
  endif()
endif()
