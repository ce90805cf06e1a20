# Pack tests: `splatc build` end to end on examples/minimal (manifest and
# grid, glslangValidator + spirv-val on every shader, byte-identical and
# incremental rebuilds, bad scenes leaving an existing pack untouched).
add_executable(test_pack ${CMAKE_CURRENT_LIST_DIR}/test_pack.c)
target_link_libraries(test_pack PkgConfig::CMOCKA PkgConfig::JANSSON)
add_dependencies(test_pack splatc_cli)
add_test(NAME pack.test_pack COMMAND test_pack $<TARGET_FILE:splatc_cli>
         WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
set_tests_properties(pack.test_pack PROPERTIES LABELS pack TIMEOUT 300)
