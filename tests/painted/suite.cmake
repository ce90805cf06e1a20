# Sparse painted masks end to end (label `render`, SPLAT_VALIDATE=1): the
# minimal example built dense, sparse R8 and sparse BC4 and rendered; R8
# equal to dense at every pixel (no seams at tile borders), BC4 within its
# block error.  test_painted (tests/unit) covers sizes and soundness.
# imgcheck comes from tests/render (included after this suite).
if(TARGET splatview AND TARGET splatc_cli)
  add_test(NAME painted.seams
    COMMAND sh ${CMAKE_CURRENT_LIST_DIR}/seams.sh $<TARGET_FILE:splatc_cli>
            $<TARGET_FILE:splatview> $<TARGET_FILE:imgcheck> ${CMAKE_BINARY_DIR}/tests/painted
    WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
  set_tests_properties(painted.seams PROPERTIES LABELS render TIMEOUT 600)
endif()
