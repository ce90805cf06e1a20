# Hostile inputs to `splatc build` (issue 34, tests/hostile/hostile.sh):
# special files, values at their ends, lying headers, meshes, memory and
# the depfile's atomicity.  Label `unit`: they run again under ASan + UBSan.
if(TARGET splatc_cli)
  set(hostile_cases special limits mesh depfile)
  set(hostile_big_png "")
  find_package(ZLIB)
  if(ZLIB_FOUND)
    # the masks case's "small PNG" of 16384^2 texels (big_png.c)
    add_executable(hostile_big_png ${CMAKE_CURRENT_LIST_DIR}/big_png.c)
    target_link_libraries(hostile_big_png ZLIB::ZLIB)
    list(APPEND hostile_cases masks)
    set(hostile_big_png $<TARGET_FILE:hostile_big_png>)
  endif()
  if(SPLAT_SANITIZE)
    set(hostile_asan ON)
  else()
    set(hostile_asan OFF)
  endif()
  foreach(case ${hostile_cases})
    add_test(NAME hostile.${case}
             COMMAND sh ${CMAKE_CURRENT_LIST_DIR}/hostile.sh $<TARGET_FILE:splatc_cli> ${case}
                     "${hostile_big_png}" ${hostile_asan}
             WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
    set_tests_properties(hostile.${case} PROPERTIES LABELS unit TIMEOUT 600)
  endforeach()
endif()
