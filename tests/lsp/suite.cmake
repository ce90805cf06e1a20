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
