/* glsl_check.h — a unit-test assertion (glsl_check.c; linked into every
 * unit test): GLSL the compiler emitted compiles with glslang and its
 * SPIR-V passes spirv-val, or the test fails with the source and the log. */
#ifndef SPLAT_TEST_GLSL_CHECK_H
#define SPLAT_TEST_GLSL_CHECK_H

#include "spv.h"

void glsl_check_compiles(const char *glsl, spv_stage stage, const char *name);

#endif
