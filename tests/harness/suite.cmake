# The harness's own tests, label `gpu` (the library: harness.cmake).
# Included by tests/CMakeLists.txt.
function(splat_gpu_test name)
  add_executable(${name} ${HARNESS_DIR}/${name}.c ${ARGN})
  target_link_libraries(${name} splat_harness PkgConfig::CMOCKA)
  add_test(NAME gpu.${name} COMMAND ${name} WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
  # lavapipe on two shared cores: allow for a slow machine.  Validation on
  # whoever runs the test (ctest alone, not only make test).
  set_tests_properties(gpu.${name} PROPERTIES LABELS gpu TIMEOUT 600
    ENVIRONMENT "SPLAT_VALIDATE=1")
endfunction()

splat_gpu_test(test_harness)
splat_gpu_test(test_gpu_agree)
# the B-spline height and normal (abi.c) against terrain.c's twins
splat_gpu_test(test_terrain_gpu)
# random_ir.h: the IR's random graph generator, shared with the CPU test
target_include_directories(test_gpu_agree PRIVATE ${PROJECT_SOURCE_DIR}/tests/unit)
# the look nodes of issue 31 (nodes/detile.sg ...) against their reference
splat_gpu_test(test_look_gpu)
