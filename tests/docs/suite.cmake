# The documentation (label `unit`): every relative link and image of
# README.md and docs/*.md names a file that exists, and every #anchor a
# heading (check_links.sh says how links are found and what is pending).
add_test(NAME docs.links
  COMMAND sh ${CMAKE_CURRENT_LIST_DIR}/check_links.sh ${PROJECT_SOURCE_DIR}
  WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
set_tests_properties(docs.links PROPERTIES LABELS unit TIMEOUT 60)

# The runtime's library boundary: who may include rt_internal.h.
add_test(NAME docs.internal_includes
  COMMAND sh ${CMAKE_CURRENT_LIST_DIR}/internal_includes.sh ${PROJECT_SOURCE_DIR})
set_tests_properties(docs.internal_includes PROPERTIES LABELS unit)
