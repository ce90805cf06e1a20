# splat_testkit: the C test kit (kit.h) the device test programs link:
# checks, a device, a pack, a frame, picture comparisons, file reading,
# through the public splatrt.h.
if(TARGET splatrt)
  add_library(splat_testkit STATIC ${CMAKE_CURRENT_LIST_DIR}/kit.c)
  target_include_directories(splat_testkit PUBLIC ${CMAKE_CURRENT_LIST_DIR})
  target_link_libraries(splat_testkit PUBLIC splatrt splatc m)
endif()
# The kit's checks fail when they should (test_kit.c).
if(TARGET splat_testkit)
  add_executable(test_kit ${CMAKE_CURRENT_LIST_DIR}/test_kit.c)
  target_link_libraries(test_kit splat_testkit)
  file(MAKE_DIRECTORY ${CMAKE_CURRENT_BINARY_DIR}/kit)
  add_test(NAME unit.kit COMMAND test_kit ${CMAKE_CURRENT_BINARY_DIR}/kit)
  set_tests_properties(unit.kit PROPERTIES LABELS unit)
endif()
