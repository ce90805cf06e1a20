# Extreme-value tests (extreme-value stability), label `extreme`: mask nodes at extreme
# inputs on the CPU reference and the device (compute harness), Listing 1's
# normal filter at extreme heights and scales (double vs fp32), and renders
# of extreme scenes through splatc build + splatview --float-out (no NaN/Inf,
# masks within 0..1, flat ground's normal exact).  Each prints its table.
# Suites are included in name order, before tests/harness defines
# splat_harness: the harness sources are compiled in here.
set(EXTREME_HARNESS ${PROJECT_SOURCE_DIR}/tests/harness)
if(TARGET splatrt AND TARGET splatview AND TARGET splatc_cli AND EXISTS ${EXTREME_HARNESS}/harness_ir.c)
  add_executable(extreme ${CMAKE_CURRENT_LIST_DIR}/extreme.c ${EXTREME_HARNESS}/harness.c
                 ${EXTREME_HARNESS}/harness_ref.c ${EXTREME_HARNESS}/harness_ir.c)
  target_include_directories(extreme PRIVATE ${EXTREME_HARNESS})
  target_link_libraries(extreme splatrt)
  add_test(NAME extreme.nodes COMMAND extreme nodes WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
  add_test(NAME extreme.normals COMMAND extreme normals WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
  add_test(NAME extreme.renders
    COMMAND sh ${CMAKE_CURRENT_LIST_DIR}/run.sh $<TARGET_FILE:extreme>
            $<TARGET_FILE:splatc_cli> $<TARGET_FILE:splatview> ${CMAKE_BINARY_DIR}/tests/extreme_out
    WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
  set_tests_properties(extreme.nodes extreme.normals extreme.renders PROPERTIES
    LABELS extreme TIMEOUT 600 ENVIRONMENT SPLAT_VALIDATE=1)
endif()
