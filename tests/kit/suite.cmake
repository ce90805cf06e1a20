# The shell half of the test kit (tests/lib.sh, label `unit`): its helpers
# pass and fail what they must, under sh -u and sh -eu.
add_test(NAME kit.shell COMMAND sh ${CMAKE_CURRENT_LIST_DIR}/kit.sh)
set_tests_properties(kit.shell PROPERTIES LABELS unit TIMEOUT 60)
