/* harness.h — a small Vulkan compute harness for tests and benchmarks.
 *
 * It runs one compute shader over an input and an output storage buffer
 * (plus optional sampled images) and reads the output back, on whatever
 * Vulkan 1.2 device is there: a GPU, or Mesa's lavapipe on the CPU.  On top
 * of it, harness_eval_ir evaluates IR roots (compiler/ir.h) on the device
 * through the project's own GLSL emitter, so tests and benchmarks can set
 * the GPU's fp32 values beside the CPU reference (ir_eval, double).
 *
 * Validation: with desc.validate, or SPLAT_VALIDATE=1 in the environment,
 * the Khronos validation layer and a debug messenger are enabled; every
 * warning or error message is printed to stderr and counted
 * (harness_validation_count), and a test must fail on any.  Every VkResult
 * is checked; failures come back as messages, never exits.
 *
 * Sections: the device (create, destroy, info), dispatch, IR evaluation.
 */
#ifndef SPLAT_HARNESS_H
#define SPLAT_HARNESS_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "ir.h"

/* ---- the device -------------------------------------------------------- */

typedef struct harness harness;

typedef struct harness_desc {
    bool        validate;  /* validation layer + messenger; also turned on
                              by SPLAT_VALIDATE=1 in the environment       */
    const char *device;    /* substring of the device name to pick; NULL:
                              $SPLAT_DEVICE, else the first discrete GPU,
                              else the first integrated, else any         */
} harness_desc;

/* NULL on failure with *err (malloc'd, caller frees) saying why. */
harness    *harness_create(const harness_desc *desc, char **err);
/* Returns the validation messages of the harness's whole life, teardown
 * included: a test fails when it is not 0. */
int         harness_destroy(harness *h);
const char *harness_device_name(const harness *h);
bool        harness_validating(const harness *h);
/* Validation warnings and errors seen since harness_create. */
int         harness_validation_count(const harness *h);

/* ---- dispatch ----------------------------------------------------------- */

/* Workgroup width every harness shader declares (layout(local_size_x)). */
#define HARNESS_LOCAL_SIZE 64

/* A sampled image: RGBA32F texels, one mip level, with sampler state. */
typedef struct harness_image {
    int          width, height;
    const float *rgba;     /* width * height * 4 floats, row 0 first (v = 0) */
    ir_filter    filter;   /* IR_FILTER_LINEAR (default) or NEAREST         */
    ir_wrap      wrap;     /* IR_WRAP_REPEAT (default), CLAMP, MIRROR       */
} harness_image;

/* Descriptor set 0: binding 0 the input buffer (std430, readonly),
 * binding 1 the output buffer, binding 2 + i image i (sampler2D). */
typedef struct harness_dispatch {
    const uint32_t *spv;            /* compute shader SPIR-V             */
    size_t          nwords;
    const void     *input;          /* copied to binding 0               */
    size_t          input_bytes;    /* > 0                               */
    void           *output;         /* binding 1, read back here         */
    size_t          output_bytes;   /* > 0; the buffer starts zeroed     */
    uint32_t        groups;         /* workgroups along x                */
    const harness_image *images;    /* nimages, may be NULL if 0         */
    int             nimages;
    const void     *push;           /* push constants (compute), or NULL */
    uint32_t        push_bytes;     /* multiple of 4, at most 128        */
} harness_dispatch;

bool harness_run(harness *h, const harness_dispatch *d, char **err);

/* ---- IR evaluation ------------------------------------------------------ */

/* Evaluate IR roots at many points on the device.
 * Each point is an ir_env, exactly what ir_eval takes: terrain inputs,
 * params (4 per param, NULL = defaults) and painted values (NULL = 0); its
 * `sample` hook is ignored — textures come from `images` instead (one per
 * ir texture, bound with that image's sampler state), or, when images is
 * NULL, every texture reads (0.5, 0.5, 0.5, 1), as ir_eval's default.
 * Inputs travel as 32-bit floats: give the reference float-representable
 * values to compare like with like. */
typedef struct harness_ir_desc {
    const ir            *ir;
    const ir_ref        *roots;     /* float or vector values            */
    int                  nroots;
    const ir_env        *points;
    int                  npoints;
    const harness_image *images;    /* ir->ntextures of them, or NULL    */
} harness_ir_desc;

/* out[(p * nroots + r) * 4 + c]: component c of root r at point p
 * (components past the root's width are 0).  With `glsl` non-NULL, *glsl
 * receives the generated compute shader (malloc'd) for inspection. */
bool harness_eval_ir(harness *h, const harness_ir_desc *d, float *out,
                     char **glsl, char **err);

/* The compute shader harness_eval_ir runs (malloc'd).  Its prelude
 * defines the ABI prelude's input functions (splat_height(),
 * splat_slope(), splat_normal(), splat_position(), splat_uv(),
 * splat_view_distance(), splat_destruction()) over the per-point record
 * in the input buffer; params and painted values read from the record
 * too.  NULL with *err on failure. */
char *harness_ir_shader(const harness_ir_desc *d, char **err);

/* ---- the reference and its fp32 sensitivity (harness_ref.c) ------------- */

/* Why a value cannot be compared with the device's (harness_refval.flags). */
enum {
    HARNESS_REF_NONFINITE = 1, /* NaN or Inf in the value or on its way     */
    HARNESS_REF_RANGE     = 2, /* a value on the way beyond 1e18 or below
                                  1e-18 in magnitude: fp32 overflows or
                                  loses precision where double does not    */
    HARNESS_REF_UNDEFINED = 4, /* GLSL leaves the result undefined
                                  (smoothstep e0 >= e1, clamp lo > hi,
                                  pow of x < 0)                            */
    HARNESS_REF_MISMATCH  = 8, /* the walk disagrees with ir_eval: a bug
                                  of the harness, tests assert none       */
};

typedef struct harness_refval {
    double   value[4];   /* ir_eval's value (double)                        */
    double   spread[4];  /* how far fp32 rounding may move it: the largest
                            deviation over `samples` evaluations with every
                            node's result perturbed by its op's fp32 error
                            bound (harness_ref.c lists them)             */
    unsigned flags;      /* HARNESS_REF_*                                   */
} harness_refval;

/* The reference value of `root` at `env` and its sensitivity to fp32
 * rounding (a Monte-Carlo rounding analysis: each sample perturbs every
 * node by +-its bound, signs drawn from `seed`; sample 0 uses all +, sample
 * 1 all -).  A value whose spread is large is ill-conditioned in fp32 —
 * a discontinuity (floor, step, less, mod) within rounding distance, or
 * cancellation amplified — and no fp32 implementation can be held to it. */
void harness_reference(const ir *ir, ir_ref root, const ir_env *env,
                       int samples, uint64_t seed, harness_refval *out);

#endif
