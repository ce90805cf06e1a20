# The Vulkan compute harness library (tests/harness/harness.h), defined
# before any suite is included so every suite can link `splat_harness`.
# harness.c: device and dispatch; harness_ir.c: IR through the compiler's
# GLSL emitter; harness_ref.c: the CPU reference with its fp32 sensitivity.
# The device is libsplatrt's (runtime/device.c).
set(HARNESS_DIR ${CMAKE_CURRENT_LIST_DIR})
add_library(splat_harness STATIC ${HARNESS_DIR}/harness.c
            ${HARNESS_DIR}/harness_ir.c ${HARNESS_DIR}/harness_ref.c)
target_include_directories(splat_harness PUBLIC ${HARNESS_DIR})
target_link_libraries(splat_harness PUBLIC splatrt m)
# A new fp32 error class without a bound in harness_ref.c's switch must not
# build (the switch has no default on purpose).
set_source_files_properties(${HARNESS_DIR}/harness_ref.c PROPERTIES
                            COMPILE_OPTIONS -Werror=switch)
