# Hostile inputs to `splatc build` (issue 34, tests/hostile/hostile.sh):
# special files, values at their ends, lying headers, meshes, memory and
# the depfile's atomicity.  Label `unit`: they run again under ASan + UBSan.
if(TARGET splatc_cli)
  foreach(case special limits mesh)
    add_test(NAME hostile.${case}
             COMMAND sh ${CMAKE_CURRENT_LIST_DIR}/hostile.sh $<TARGET_FILE:splatc_cli> ${case}
             WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
    set_tests_properties(hostile.${case} PROPERTIES LABELS unit TIMEOUT 600)
  endforeach()
endif()
