# libFuzzer targets (`make fuzz`, and the fuzz.smoke test of `make test`).
#
# In a build with -DSPLAT_FUZZ=ON (clang; the top CMakeLists instruments
# every target with -fsanitize=fuzzer-no-link,address,undefined):
#   fuzz_parse        the .sg front end (lex, parse, resolve, lower)
#   fuzz_manifest     the pack loader, manifest.json (rt_pack_load)
#   fuzz_combos       combos.bin (rt_combos_parse)
#   fuzz_sparse       painted.sparse (sparse_read)
#   fuzz_heightfield  PNG / raw / GDAL heightfields and painted rasters
#   fuzz_obj          the undergrowth's OBJ reader (scan, parse, triangulate)
#   fuzz_spirv        spirv-val + the SPIRV-Cross interface check
# run.sh runs each for a given time from seeds made of the project's files.
#
# In every other build, fuzz.smoke builds those targets with clang in
# BUILD/fuzz and runs each for a few seconds; it is skipped (exit 77) where
# clang's libFuzzer runtime is missing.
set(FUZZ_TARGETS fuzz_parse fuzz_manifest fuzz_combos fuzz_sparse fuzz_heightfield fuzz_spirv
                 fuzz_obj)
if(SPLAT_FUZZ)
  if(NOT CMAKE_C_COMPILER_ID MATCHES "Clang")
    message(FATAL_ERROR "SPLAT_FUZZ=ON needs clang (CC=clang cmake ...)")
  endif()
  # the front end compiled into its target (as before: no runtime needed)
  set(FUZZ_FRONTEND abi.c sg_util.c diag.c lex.c parse_base.c parse.c parse_undergrowth.c parse_scene.c
                    resolve_names.c resolve_types.c resolve_order.c texture_files.c
                    load.c sg_program.c scene_check.c resolve.c lower.c ir.c ir_ops.c
                    ir_differentiate.c ir_derive_rules.c ir_rebuild.c util.c opt.c opt_fold.c opt_dce.c
                    opt_dedup.c opt_pin.c ir_interval.c ir_validate.c
                    mesh.c mesh_obj.cpp)
  list(TRANSFORM FUZZ_FRONTEND PREPEND ${PROJECT_SOURCE_DIR}/compiler/)
  add_executable(fuzz_parse ${CMAKE_CURRENT_LIST_DIR}/fuzz_parse.c ${FUZZ_FRONTEND})
  target_include_directories(fuzz_parse PRIVATE ${PROJECT_SOURCE_DIR}/compiler)
  # undergrowth blocks load OBJ meshes (tinyobjloader, C++)
  target_link_libraries(fuzz_parse m Threads::Threads PkgConfig::TINYOBJLOADER PkgConfig::XXHASH PkgConfig::STB stdc++)
  foreach(t fuzz_manifest fuzz_combos fuzz_sparse fuzz_heightfield fuzz_spirv)
    add_executable(${t} ${CMAKE_CURRENT_LIST_DIR}/${t}.c)
    target_link_libraries(${t} splatrt)
  endforeach()
  add_executable(fuzz_obj ${CMAKE_CURRENT_LIST_DIR}/fuzz_obj.c)
  target_link_libraries(fuzz_obj splatc)
  foreach(t ${FUZZ_TARGETS})
    target_link_options(${t} PRIVATE -fsanitize=fuzzer)
    set_target_properties(${t} PROPERTIES LINKER_LANGUAGE C)
  endforeach()
  add_custom_target(fuzz_targets DEPENDS ${FUZZ_TARGETS})
else()
  add_test(NAME fuzz.smoke
           COMMAND sh ${CMAKE_CURRENT_LIST_DIR}/smoke.sh ${PROJECT_SOURCE_DIR}
                   ${CMAKE_BINARY_DIR}/fuzz 3)
  set_tests_properties(fuzz.smoke PROPERTIES LABELS fuzz TIMEOUT 1500 SKIP_RETURN_CODE 77)
endif()
