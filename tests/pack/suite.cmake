# Pack tests: `splatc build` end to end on examples/minimal (manifest and
# grid, glslangValidator + spirv-val on every shader, byte-identical and
# incremental rebuilds, bad scenes leaving an existing pack untouched).
add_executable(test_pack ${CMAKE_CURRENT_LIST_DIR}/test_pack.c)
target_link_libraries(test_pack PkgConfig::CMOCKA PkgConfig::JANSSON)
add_dependencies(test_pack splatc_cli)
add_test(NAME pack.test_pack COMMAND test_pack $<TARGET_FILE:splatc_cli>
         WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
set_tests_properties(pack.test_pack PROPERTIES LABELS pack TIMEOUT 300)

# Every example scene builds, and every shader of its pack passes spirv-val
# and glslangValidator (the cache lives in the build tree: reruns are fast).
file(GLOB PACK_EXAMPLE_SCENES CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/examples/*/scene.sg)
foreach(scene ${PACK_EXAMPLE_SCENES})
  get_filename_component(dir ${scene} DIRECTORY)
  get_filename_component(name ${dir} NAME)
  add_test(NAME pack.example_${name}
           COMMAND sh ${CMAKE_CURRENT_LIST_DIR}/check_pack.sh $<TARGET_FILE:splatc_cli>
                   ${scene} ${CMAKE_CURRENT_BINARY_DIR}/pack_${name}
                   ${CMAKE_CURRENT_BINARY_DIR}/spv_cache
           WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
  set_tests_properties(pack.example_${name} PROPERTIES LABELS pack TIMEOUT 1500)
endforeach()

# The corrupt-pack suite (corrupt.sh): packs built by splatc, corrupted in
# 40-odd ways, each refused by splatview with exit 1 and a message naming
# the file and the problem, no validation message, in under 5 s.
if(TARGET splatview AND TARGET splatc_cli)
  add_executable(packedit ${CMAKE_CURRENT_LIST_DIR}/packedit.c)
  target_link_libraries(packedit PkgConfig::JANSSON PkgConfig::STB)
  add_test(NAME pack.corrupt
           COMMAND sh ${CMAKE_CURRENT_LIST_DIR}/corrupt.sh $<TARGET_FILE:splatc_cli>
                   $<TARGET_FILE:splatview> $<TARGET_FILE:packedit>
                   ${CMAKE_CURRENT_BINARY_DIR}/corrupt)
  set_tests_properties(pack.corrupt PROPERTIES LABELS "pack;render;asan" TIMEOUT 600
                       ENVIRONMENT "SPLAT_VALIDATE=1")
endif()

# The checks splatview cannot show alone (test_pack_checks.c): each size of
# a pack against a device's limits (rt_pack_check_device) with devices made
# too small on purpose, and the compute variants against the compute role
# of the SPIR-V check; the packs of the render and destruction suites and
# examples/minimal built with --compute-spirv.
if(TARGET splatrt AND TARGET splatc_cli)
  set(PACK_OUT ${CMAKE_CURRENT_BINARY_DIR}/checks)
  file(MAKE_DIRECTORY ${PACK_OUT})
  add_test(NAME pack.compute_pack
           COMMAND $<TARGET_FILE:splatc_cli> build ${PROJECT_SOURCE_DIR}/examples/minimal/scene.sg
                   -o ${PACK_OUT}/compute --compute-spirv --no-cache)
  set_tests_properties(pack.compute_pack PROPERTIES LABELS "pack;asan" FIXTURES_SETUP compute_pack)
  add_executable(test_pack_checks ${CMAKE_CURRENT_LIST_DIR}/test_pack_checks.c)
  target_link_libraries(test_pack_checks splatrt PkgConfig::CMOCKA)
  add_test(NAME pack.checks
           COMMAND test_pack_checks ${CMAKE_BINARY_DIR}/tests/render/minimal
                   ${CMAKE_BINARY_DIR}/tests/destruction/pack ${PACK_OUT}/compute)
  set_tests_properties(pack.checks PROPERTIES LABELS "pack;asan" TIMEOUT 300
                       FIXTURES_REQUIRED "minimal_pack;destruction_pack;compute_pack")
endif()
