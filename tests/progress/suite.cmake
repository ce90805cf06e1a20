# splatc build's progress on stderr (progress.sh says what is held).
if(TARGET splatc_cli)
  add_test(NAME progress.build
    COMMAND sh ${CMAKE_CURRENT_LIST_DIR}/progress.sh $<TARGET_FILE:splatc_cli>
            ${PROJECT_SOURCE_DIR}/examples/minimal/scene.sg ${CMAKE_BINARY_DIR}/tests)
  set_tests_properties(progress.build PROPERTIES LABELS unit TIMEOUT 300)
endif()
