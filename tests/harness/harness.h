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
    const char *device;    /* device index or name substring (any case) to
                              pick; NULL: $SPLAT_DEVICE, else the first
                              discrete GPU, else integrated, else any
                              (rt_device_desc.select)                     */
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

/* The CPU twin of the device's sampler for `im` (harness_ref.c): Vulkan's
 * texel addressing (u * width - 0.5), its wrap mode, nearest or bilinear,
 * in double.  Usable as an ir_sample_fn over an array of images (`user`
 * points at the first, `texture` indexes it): harness_sample_images. */
void harness_image_sample(const harness_image *im, double u, double v,
                          double rgba[4]);
void harness_sample_images(void *user, int texture, double u, double v,
                           double rgba[4]);

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
 * splat_view_distance(), splat_view_direction(), splat_destruction()) over
 * the per-point record
 * in the input buffer; params and painted values read from the record
 * too.  NULL with *err on failure. */
char *harness_ir_shader(const harness_ir_desc *d, char **err);

/* ---- the reference and its fp32 sensitivity (harness_ref.c) ------------- */

/* Why a value cannot be compared with the device's (harness_refval.flags). */
enum {
    HARNESS_REF_NONFINITE = 1, /* NaN or Inf in the value or on its way     */
    HARNESS_REF_RANGE     = 2, /* a value on the way beyond 1e30 or below
                                  1e-30 in magnitude: fp32 overflows or
                                  flushes where double does not            */
    HARNESS_REF_UNDEFINED = 4, /* GLSL leaves the result undefined
                                  (smoothstep e0 >= e1, clamp lo > hi,
                                  pow of x < 0)                            */
    HARNESS_REF_MISMATCH  = 8, /* the walk disagrees with ir_eval: a bug
                                  of the harness, tests assert none       */
};

typedef struct harness_refval {
    double   value[4];   /* ir_eval's value (double)                        */
    double   spread[4];  /* how far fp32 rounding may move it: the largest
                            deviation over the samples, every node's result
                            perturbed by its op's fp32 error bound (listed
                            in harness_ref.c); INFINITY when flagged      */
    unsigned flags[4];   /* HARNESS_REF_*, per component                    */
} harness_refval;

typedef struct harness_ref_opts {
    int      samples;     /* rounding-perturbation samples (0: 16)          */
    uint64_t seed;        /* their signs                                    */
    double   texel_step;  /* largest difference between neighbouring texels
                             of the textures env->sample reads (0: 1)      */
    int      texels;      /* their largest size in texels (0: 4096)         */
} harness_ref_opts;

/* The reference value of `root` at `env` and its sensitivity to fp32
 * rounding: a Monte-Carlo rounding analysis — each sample perturbs every
 * node by +-its bound (sample 0 all +, sample 1 all -, then random signs).
 * A value whose spread is large is ill-conditioned in fp32 — a
 * discontinuity (floor, step, less, mod) within rounding distance, or
 * cancellation amplified — and no fp32 implementation can be held to it.
 * Nodes that are NaN/Inf, out of range or undefined in GLSL on the way flag
 * a component only when they matter to it: replacing their values with
 * garbage (NaN, +-Inf, 0, 1.2345e7) changes it.  `opts` may be NULL. */
void harness_reference(const ir *ir, ir_ref root, const ir_env *env,
                       const harness_ref_opts *opts, harness_refval *out);

/* Largest difference between neighbouring texels (any channel, across the
 * wrap), for harness_ref_opts.texel_step. */
double harness_image_max_step(const harness_image *im);

#endif
