# The destruction mask on a Vulkan device (label `render`, SPLAT_VALIDATE=1):
# tests/destruction/scene.sg built by splatc, then test_destruction runs a
# scripted series of craters and checks mask, heights and the tile pool.
if(TARGET splatrt AND TARGET splatc_cli)
  set(DESTR_OUT ${CMAKE_BINARY_DIR}/tests/destruction)
  file(MAKE_DIRECTORY ${DESTR_OUT})
  add_executable(test_destruction ${CMAKE_CURRENT_LIST_DIR}/test_destruction.c)
  target_link_libraries(test_destruction splat_testkit)
  add_test(NAME destruction.pack
    COMMAND $<TARGET_FILE:splatc_cli> build ${PROJECT_SOURCE_DIR}/tests/destruction/scene.sg
            -o ${DESTR_OUT}/pack --no-cache)
  set_tests_properties(destruction.pack PROPERTIES LABELS render FIXTURES_SETUP destruction_pack)
  add_test(NAME destruction.craters
    COMMAND test_destruction ${DESTR_OUT}/pack ${DESTR_OUT})
  set_tests_properties(destruction.craters PROPERTIES LABELS "render;asan" TIMEOUT 600
    FIXTURES_REQUIRED destruction_pack ENVIRONMENT "SPLAT_VALIDATE=1")
endif()
# imgcheck comes from tests/render (included after this suite)
if(TARGET splatview AND TARGET splatc_cli)
  add_test(NAME destruction.viewer_click
    COMMAND sh ${CMAKE_CURRENT_LIST_DIR}/viewer_click.sh $<TARGET_FILE:splatview>
            $<TARGET_FILE:imgcheck> ${CMAKE_BINARY_DIR}/tests/destruction/pack
            ${CMAKE_BINARY_DIR}/tests/destruction/viewer)
  set_tests_properties(destruction.viewer_click PROPERTIES LABELS render TIMEOUT 300
    SKIP_RETURN_CODE 77
    FIXTURES_REQUIRED destruction_pack ENVIRONMENT "SPLAT_VALIDATE=1")
endif()
