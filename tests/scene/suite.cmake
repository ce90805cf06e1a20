# Scene tests: loading and analysing scene files (fixtures in tests/scene/),
# and the deterministic generators of the committed rasters (the minimal
# example's heightfield and mask, the fixtures' small rasters), with a test
# that a fresh run reproduces the committed bytes.

add_executable(test_scene ${CMAKE_CURRENT_LIST_DIR}/test_scene.c)
target_link_libraries(test_scene splatc splat_unit_helpers PkgConfig::CMOCKA)
add_test(NAME scene.test_scene COMMAND test_scene WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
set_tests_properties(scene.test_scene PROPERTIES LABELS unit)

add_executable(minimal_gen_heightfield ${PROJECT_SOURCE_DIR}/examples/minimal/gen_heightfield.c)
target_link_libraries(minimal_gen_heightfield splatc)
add_executable(scene_gen_fixtures ${CMAKE_CURRENT_LIST_DIR}/gen_fixtures.c)
target_link_libraries(scene_gen_fixtures splatc)

# Rewrite the committed rasters in the source tree:
#   cmake --build BUILD --target scene_rasters
add_custom_target(scene_rasters
  COMMAND minimal_gen_heightfield ${PROJECT_SOURCE_DIR}/examples/minimal
  COMMAND scene_gen_fixtures ${CMAKE_CURRENT_LIST_DIR}
  COMMENT "regenerating the minimal example's and the scene fixtures' rasters")

set(SCENE_OUT ${CMAKE_CURRENT_BINARY_DIR}/scene_reproduce)
add_test(NAME scene.rasters_reproducible
  COMMAND sh -c "rm -rf '${SCENE_OUT}' && mkdir -p '${SCENE_OUT}/minimal' '${SCENE_OUT}/fixtures' && \
'$<TARGET_FILE:minimal_gen_heightfield>' '${SCENE_OUT}/minimal' >/dev/null && \
'$<TARGET_FILE:scene_gen_fixtures>' '${SCENE_OUT}/fixtures' && \
cmp '${SCENE_OUT}/minimal/heightfield.png' examples/minimal/heightfield.png && \
cmp '${SCENE_OUT}/minimal/fields.png' examples/minimal/fields.png && \
for f in hf16.png hf.r16 hf_rgb.png mask.png mask8x8.png hf_truncated.png mask_truncated.png; do \
  cmp '${SCENE_OUT}/fixtures/'$f tests/scene/$f || exit 1; done"
  WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
set_tests_properties(scene.rasters_reproducible PROPERTIES LABELS unit)
