/* spv.h — GLSL to SPIR-V in process: compile (glslang's C API), validate
 * and optimise (SPIRV-Tools), write.
 *
 * Target: Vulkan 1.2 / SPIR-V 1.5 (abi.h's shaders and the runtime).
 * Every function is safe to call from several threads at once (`splatc
 * build -j N`): glslang's process state is initialised exactly once, and
 * each call owns its glslang and SPIRV-Tools objects.
 *
 * Logs: where a function takes `char **log`, the pointer may be NULL (no
 * log wanted); otherwise *log is set to NULL or to a malloc'd, NUL-terminated
 * message the caller frees — on failure always a message.
 *
 * Generated GLSL that glslang rejects is a compiler bug, not a user error:
 * spv_compile's log then reads
 *
 *     internal compiler error: generated GLSL for 'cliff' failed to compile:
 *     cliff:42: error: 'foo' : undeclared identifier
 *        42 |     float v3 = foo(v2);
 *
 * one "name:line: error:" entry per glslang error, with the offending line
 * of the generated text (line numbers count from 1 in `glsl`).
 */
#ifndef SPLAT_SPV_H
#define SPLAT_SPV_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef enum spv_stage {
    SPV_STAGE_VERTEX = 0,
    SPV_STAGE_FRAGMENT = 1,
    SPV_STAGE_COMPUTE = 2,
} spv_stage;

/* spv.c */

/* Compile a complete GLSL 450 shader (with its #version line) for `stage`
 * (an spv_stage).  `name` names the shader in messages (a material or
 * combination).  On success *words / *nwords receive a malloc'd SPIR-V
 * module (caller frees); on failure they are NULL / 0 and *log says why.
 * The module is not validated here (glslang's own validation is off):
 * callers that keep it run spv_validate once. */
bool spv_compile(const char *glsl, int stage, const char *name,
                 uint32_t **words, size_t *nwords, char **log);

/* Validate a module with SPIRV-Tools for SPV_ENV_VULKAN_1_2. */
bool spv_validate(const uint32_t *words, size_t nwords, char **log);

/* The module's shape (cache.h splat_spirv_shape_key): a hash of every
 * instruction but the float-valued constants (OpConstant of a float type,
 * OpConstantComposite of such) and debug names and lines, ids numbered in
 * order of first use and a use of such a constant written as its type.
 * Two modules that differ only in those constants' values (and in which
 * of them glslang merged because they became equal) have one shape.  False if `words` do not
 * parse as SPIR-V. */
bool spv_shape(const uint32_t *words, size_t nwords, uint64_t hash[2]);
/* Write a module to `path` atomically: a temporary file beside it, then
 * rename, so a reader never sees half a file.  False (errno set) on error. */
bool spv_write_file(const char *path, const uint32_t *words, size_t nwords);

/* spv_opt.cpp */

/* Run spirv-opt's performance passes (the list `spirv-opt -O` runs) on the
 * module in place, validating before and after.  SPIRV-Tools 2023.1 (Debian
 * 12) has no C entry point that runs the optimiser — its C API only creates
 * option objects — so this one function is written against the C++ API
 * (spvtools::Optimizer) and exported with C linkage.  On failure the module
 * is left unchanged. */
bool spv_optimize(uint32_t **words, size_t *nwords, char **log);

#ifdef __cplusplus
}
#endif

#endif
