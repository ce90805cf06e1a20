# Command-line tests of splatc (tests/cli/cli.sh): every graph through
# glsl/spirv and the validators, exit codes, eval, tools, malformed input.
if(TARGET splatc_cli)
  foreach(case graphs status eval tools depfile preview malformed teach texgen)
    add_test(NAME cli.${case}
             COMMAND sh ${CMAKE_CURRENT_LIST_DIR}/cli.sh $<TARGET_FILE:splatc_cli> ${case}
             WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
    set_tests_properties(cli.${case} PROPERTIES LABELS cli TIMEOUT 600)
  endforeach()
endif()
if(TARGET splatc_cli AND TARGET splatview)
  add_test(NAME cli.teach_param
           COMMAND sh ${CMAKE_CURRENT_LIST_DIR}/cli.sh $<TARGET_FILE:splatc_cli> teach_param
           WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
  set_tests_properties(cli.teach_param PROPERTIES LABELS "cli;render" TIMEOUT 600
                       ENVIRONMENT "SPLATVIEW=$<TARGET_FILE:splatview>;SPLAT_VALIDATE=1")
endif()
# imgcheck comes from tests/render (included after this suite)
if(TARGET splatc_cli AND TARGET splatview AND TARGET splatrt)
  add_test(NAME cli.init
           COMMAND sh ${CMAKE_CURRENT_LIST_DIR}/cli.sh $<TARGET_FILE:splatc_cli> init
           WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
  set_tests_properties(cli.init PROPERTIES LABELS "cli;render" TIMEOUT 600
    ENVIRONMENT "SPLATVIEW=$<TARGET_FILE:splatview>;IMGCHECK=$<TARGET_FILE:imgcheck>;SPLAT_VALIDATE=1")
endif()
