# libFuzzer target for the front end (`make fuzz`): only with -DSPLAT_FUZZ=ON
# and clang.  The front-end and IR-builder sources are compiled into the
# target itself, instrumented for coverage, so it needs nothing else.
if(SPLAT_FUZZ)
  if(NOT CMAKE_C_COMPILER_ID MATCHES "Clang")
    message(FATAL_ERROR "SPLAT_FUZZ=ON needs clang (CC=clang cmake ...)")
  endif()
  set(FUZZ_FRONTEND sg_util.c diag.c lex.c parse.c resolve.c lower.c ir.c ir_ops.c)
  list(TRANSFORM FUZZ_FRONTEND PREPEND ${PROJECT_SOURCE_DIR}/compiler/)
  add_executable(fuzz_parse ${CMAKE_CURRENT_LIST_DIR}/fuzz_parse.c ${FUZZ_FRONTEND})
  target_include_directories(fuzz_parse PRIVATE ${PROJECT_SOURCE_DIR}/compiler)
  target_compile_options(fuzz_parse PRIVATE -g -fsanitize=fuzzer,address,undefined
                         -fno-sanitize-recover=undefined)
  target_link_options(fuzz_parse PRIVATE -fsanitize=fuzzer,address,undefined)
  target_link_libraries(fuzz_parse m Threads::Threads)
  set_target_properties(fuzz_parse PROPERTIES LINKER_LANGUAGE C)
  # a short smoke run over the project's graph files
  add_test(NAME fuzz.smoke
           COMMAND sh -c "mkdir -p fuzz_corpus && cp ${PROJECT_SOURCE_DIR}/nodes/*.sg ${PROJECT_SOURCE_DIR}/graphs/*.sg ${PROJECT_SOURCE_DIR}/tests/golden/*.sg fuzz_corpus/ && $<TARGET_FILE:fuzz_parse> -max_total_time=30 -max_len=65536 fuzz_corpus"
           WORKING_DIRECTORY ${CMAKE_CURRENT_BINARY_DIR})
  set_tests_properties(fuzz.smoke PROPERTIES LABELS fuzz TIMEOUT 120)
endif()
