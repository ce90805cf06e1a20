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
  set_tests_properties(pack.example_${name} PROPERTIES LABELS pack TIMEOUT 600)
endforeach()
