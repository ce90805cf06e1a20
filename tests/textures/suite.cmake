# Many textures (issue 29): a scene sampling 100 textures of three sizes,
# half of them sRGB, built into six texture arrays and rendered on both
# paths under the validation layer; each pixel must be their mean.  Label
# `render`.  Included by tests/CMakeLists.txt.
if(TARGET splatview AND TARGET splatc_cli AND TARGET imgcheck)
  add_executable(gen_many ${CMAKE_CURRENT_LIST_DIR}/gen_many.c)
  target_link_libraries(gen_many PkgConfig::STB m)
  add_test(NAME render.many_textures
    COMMAND sh ${CMAKE_CURRENT_LIST_DIR}/many.sh $<TARGET_FILE:gen_many>
            $<TARGET_FILE:splatc_cli> $<TARGET_FILE:splatview> $<TARGET_FILE:imgcheck>
            ${CMAKE_BINARY_DIR}/tests/many_textures 100
    WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
  set_tests_properties(render.many_textures PROPERTIES LABELS render TIMEOUT 600
                       ENVIRONMENT SPLAT_VALIDATE=1)
endif()
