# The language server (`splatc lsp`, compiler/lsp*.c), driven over pipes by
# scripted clients (tests/lsp/client.h): an editing session (diagnostics,
# completion, hover, definition, an unsaved import, UTF-16 columns,
# shutdown and exit) and bad input (framing, JSON, requests, random bodies
# and documents).  Label `unit`, so they also run under ASan + UBSan.
if(TARGET splatc_cli)
  foreach(prog lsp_session lsp_garbage)
    add_executable(${prog} ${CMAKE_CURRENT_LIST_DIR}/${prog}.c)
    target_link_libraries(${prog} PkgConfig::JANSSON)
    add_test(NAME lsp.${prog}
             COMMAND ${prog} $<TARGET_FILE:splatc_cli> ${CMAKE_CURRENT_LIST_DIR}
             WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
    set_tests_properties(lsp.${prog} PROPERTIES LABELS "unit;lsp" TIMEOUT 300)
  endforeach()
endif()

# The TextMate grammar for editors (editors/sg.tmLanguage.json) is valid
# JSON and names every keyword the parser (parse*.c) recognises and every word of the
# compiler's tables (settings keys, light keys, filters, inputs, meshes).
add_executable(grammar_check ${CMAKE_CURRENT_LIST_DIR}/grammar_check.c)
target_link_libraries(grammar_check splatc PkgConfig::JANSSON)
add_test(NAME lsp.grammar
         COMMAND grammar_check ${PROJECT_SOURCE_DIR}/editors/sg.tmLanguage.json
                 ${PROJECT_SOURCE_DIR}/compiler/parse.c ${PROJECT_SOURCE_DIR}/compiler/parse_base.c
                 ${PROJECT_SOURCE_DIR}/compiler/parse_undergrowth.c
                 ${PROJECT_SOURCE_DIR}/compiler/parse_scene.c)
set_tests_properties(lsp.grammar PROPERTIES LABELS "unit;lsp")
