# The runtime's library boundary (label `unit`): who outside libsplatrt's
# own files may include rt_internal.h, each with why (rt_internal.sh).
add_test(NAME house.rt_internal
  COMMAND sh ${CMAKE_CURRENT_LIST_DIR}/rt_internal.sh ${PROJECT_SOURCE_DIR})
set_tests_properties(house.rt_internal PROPERTIES LABELS unit)
