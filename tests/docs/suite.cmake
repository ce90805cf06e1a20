# The documentation (label `unit`): every relative link and image of
# README.md and docs/*.md names a file that exists, and every #anchor a
# heading (check_links.sh says how links are found and what is pending).
add_test(NAME docs.links
  COMMAND sh ${CMAKE_CURRENT_LIST_DIR}/check_links.sh ${PROJECT_SOURCE_DIR}
  WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
set_tests_properties(docs.links PROPERTIES LABELS unit TIMEOUT 60)

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
# docs/language.md is `splatc doc`'s output: an op, input, output, light key
# or node-library shader added without regenerating it fails here
# (regenerate: build/compiler/splatc doc -o docs/language.md).
if(TARGET splatc_cli)
  add_test(NAME docs.language
           COMMAND sh -c "'$<TARGET_FILE:splatc_cli>' doc > '${CMAKE_CURRENT_BINARY_DIR}/language.md' && \
diff -u docs/language.md '${CMAKE_CURRENT_BINARY_DIR}/language.md' || \
{ echo 'FAIL: docs/language.md is out of date: run splatc doc -o docs/language.md'; exit 1; }"
           WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
  set_tests_properties(docs.language PROPERTIES LABELS docs)
endif()

# The runtime's file map (runtime/DESIGN.md, "Files"): one line for every
# file of runtime/, and no line for a file that is gone (file_map.sh; the
# compiler's map, compiler/DESIGN.md, can be checked the same way).
add_test(NAME docs.file_map
  COMMAND sh ${CMAKE_CURRENT_LIST_DIR}/file_map.sh ${PROJECT_SOURCE_DIR} runtime runtime/DESIGN.md)
set_tests_properties(docs.file_map PROPERTIES LABELS unit TIMEOUT 60)

# README.md's option lists are generated from the programs' option tables
# (compiler/args.h): a table row added or changed without regenerating
# them fails here (regenerate: sh tests/docs/options.sh --update README.md
# build/compiler build/runtime).
if(TARGET splatc_cli AND TARGET splatview)
  add_test(NAME docs.options
           COMMAND sh ${CMAKE_CURRENT_LIST_DIR}/options.sh README.md
                   $<TARGET_FILE_DIR:splatc_cli> $<TARGET_FILE_DIR:splatview>
           WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
  set_tests_properties(docs.options PROPERTIES LABELS "docs;unit")
endif()
