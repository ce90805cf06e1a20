# House checks on the code's shape (issue 32).
#
# house.cycles: no call cycle between source files (cycles.sh: an object
# calls another when it uses a symbol the other defines).  The objects come
# from CMake itself, so a file added to or removed from a target is
# followed.  To check another target, add it to SPLAT_ACYCLIC_TARGETS.
set(SPLAT_ACYCLIC_TARGETS splatc splatc_cli)
if(TARGET splatrt)
  list(APPEND SPLAT_ACYCLIC_TARGETS splatrt)
endif()
set(SPLAT_ACYCLIC_OBJECTS)
foreach(t ${SPLAT_ACYCLIC_TARGETS})
  list(APPEND SPLAT_ACYCLIC_OBJECTS $<TARGET_OBJECTS:${t}>)
endforeach()
add_test(NAME house.cycles
         COMMAND sh ${CMAKE_CURRENT_LIST_DIR}/cycles.sh ${SPLAT_ACYCLIC_OBJECTS}
         COMMAND_EXPAND_LISTS)
set_tests_properties(house.cycles PROPERTIES LABELS "unit;house")
