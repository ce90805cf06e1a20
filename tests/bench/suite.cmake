# Benchmarks: splatbench renders pack variants side by side on
# fixed camera paths; tests/bench/run.sh drives it (`make bench`, 20 min on
# lavapipe) and its smoke mode is this suite's one test (label `bench`): a
# few small frames of examples/minimal through the whole pipeline, so the
# benchmark cannot rot.  Figures are printed, never asserted (compiler/DESIGN.md §9).
if(TARGET splatrt AND TARGET splatview AND TARGET splatc_cli)
  add_executable(splatbench ${CMAKE_CURRENT_LIST_DIR}/splatbench.c)
  target_link_libraries(splatbench splatrt)
  add_test(NAME bench.smoke
    COMMAND sh ${CMAKE_CURRENT_LIST_DIR}/run.sh ${CMAKE_BINARY_DIR} --smoke
            --out ${CMAKE_BINARY_DIR}/tests/bench/smoke
    WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
  set_tests_properties(bench.smoke PROPERTIES LABELS bench TIMEOUT 600)
endif()
