# Hot reload of every input kind (label `render`, SPLAT_VALIDATE=1):
# reload.sh makes one variant per input of packs built by splatc;
# test_reload swaps each into a renderer, which must refuse data changes by
# name and take shader and parameter changes.  packedit comes from
# tests/pack.
if(TARGET splatrt AND TARGET splatc_cli AND TARGET packedit)
  add_executable(test_reload ${CMAKE_CURRENT_LIST_DIR}/test_reload.c)
  target_link_libraries(test_reload splat_testkit)
  add_test(NAME reload.inputs
           COMMAND sh ${CMAKE_CURRENT_LIST_DIR}/reload.sh $<TARGET_FILE:splatc_cli>
                   $<TARGET_FILE:packedit> $<TARGET_FILE:test_reload>
                   ${CMAKE_CURRENT_BINARY_DIR}/reload)
  set_tests_properties(reload.inputs PROPERTIES LABELS "render;asan" TIMEOUT 600
                       ENVIRONMENT "SPLAT_VALIDATE=1")
endif()
