/* glsl_check.h — unit-test assertions (glsl_check.c; linked into every
 * unit test): GLSL the compiler emitted compiles with glslang and its
 * SPIR-V passes spirv-val, or the test fails with the source and the log. */
#ifndef SPLAT_TEST_GLSL_CHECK_H
#define SPLAT_TEST_GLSL_CHECK_H

#include "compose.h"
#include "spv.h"

void glsl_check_compiles(const char *glsl, spv_stage stage, const char *name);

/* Composite c in each of its emitted forms (forward, flat, compute, and
 * undergrowth mask with ug_slot): each holds every string of `needles`
 * (NULL-terminated) and compiles (glsl_check_compiles). */
void glsl_check_every_stage(const splat_layout *L, const splat_composite *c, const int *ug_slot,
                            const char *const *needles);

#endif
