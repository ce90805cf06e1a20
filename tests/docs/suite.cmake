# Documentation tests: docs/getting-started.md followed verbatim (its ```sh
# blocks, in an empty folder outside the repository, with the built tools
# on PATH); fails if any step fails.
if(TARGET splatc_cli AND TARGET splatview)
  add_test(NAME docs.getting_started
           COMMAND sh ${CMAKE_CURRENT_LIST_DIR}/getting_started.sh
                   ${PROJECT_SOURCE_DIR}/docs/getting-started.md
                   $<TARGET_FILE_DIR:splatview> $<TARGET_FILE_DIR:splatc_cli>)
  set_tests_properties(docs.getting_started PROPERTIES LABELS "docs;render" TIMEOUT 600
                       ENVIRONMENT "SPLAT_VALIDATE=1")
endif()
