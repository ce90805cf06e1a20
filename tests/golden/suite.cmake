# Golden tests: every tests/golden/*.sg states its expected diagnostics in
# `# expect:` comments (none: it must load and lower cleanly); one runner.
add_executable(golden_runner ${CMAKE_CURRENT_LIST_DIR}/golden.c)
target_link_libraries(golden_runner splatc)
file(GLOB GOLDEN_FILES CONFIGURE_DEPENDS ${CMAKE_CURRENT_LIST_DIR}/*.sg)
foreach(g ${GOLDEN_FILES})
  get_filename_component(name ${g} NAME_WE)
  file(RELATIVE_PATH rel ${PROJECT_SOURCE_DIR} ${g})
  add_test(NAME golden.${name} COMMAND golden_runner ${rel}
           WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
  set_tests_properties(golden.${name} PROPERTIES LABELS golden)
endforeach()
