# The Vulkan compute harness (tests/harness) and its GPU tests, label `gpu`.
# Included by tests/CMakeLists.txt.
set(HARNESS_DIR ${CMAKE_CURRENT_LIST_DIR})

# harness.c: device and dispatch; harness_ir.c: IR through the compiler's
# GLSL emitter; harness_ref.c: the CPU reference with its fp32 sensitivity.
add_library(splat_harness STATIC ${HARNESS_DIR}/harness.c
            ${HARNESS_DIR}/harness_ir.c ${HARNESS_DIR}/harness_ref.c)
target_include_directories(splat_harness PUBLIC ${HARNESS_DIR})
target_link_libraries(splat_harness PUBLIC splatc Vulkan::Vulkan m)

function(splat_gpu_test name)
  add_executable(${name} ${HARNESS_DIR}/${name}.c ${ARGN})
  target_link_libraries(${name} splat_harness PkgConfig::CMOCKA)
  add_test(NAME gpu.${name} COMMAND ${name} WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
  # lavapipe on two shared cores: allow for a slow machine.
  set_tests_properties(gpu.${name} PROPERTIES LABELS gpu TIMEOUT 600)
endfunction()

splat_gpu_test(test_harness)
splat_gpu_test(test_gpu_agree)
# random_ir.h: the IR's random graph generator, shared with the CPU test
target_include_directories(test_gpu_agree PRIVATE ${PROJECT_SOURCE_DIR}/tests/unit)
