/* bench.h — splatbench (tests/bench), split by job: the render command
 * and its variants and camera paths (splatbench.c), the device benchmarks
 * far-bake and shadow (bench_device.c), the file tools upscale,
 * analytic-hf and compare (bench_tools.c), the lane assignments' predicted
 * layer efficiency (bench_lanes.c), and the helpers they share
 * (bench_util.c). */
#ifndef SPLAT_BENCH_H
#define SPLAT_BENCH_H

#include "rt_internal.h"
#include "args.h"
#include "util.h"

#include <stdbool.h>
#include <stddef.h>
#include <stdio.h>
#include <stdint.h>

/* ---- bench_util.c ---------------------------------------------------------- */

char  *read_text(const char *path);    /* NULL if unreadable; NUL-terminated */
bool   read_words(const char *path, uint32_t **words, size_t *n);   /* SPIR-V */
/* median, 10th and 90th percentile of n samples (sorted in place) */
void   percentiles(double *v, int n, double *med, double *p10, double *p90);
double rss_mb(void);                   /* resident set size now, MB */
double process_cpu_ms(void);           /* CPU time of every thread so far, ms
                                          (llvmpipe's too: the work, which a
                                          loaded machine does not inflate) */

/* The error of an image against a reference (RGB). */
typedef struct err_acc {
    double max_abs, sum_abs, sum_sq;
    long   n, nonfinite;
} err_acc;
/* RGB of `img` against `ref` (npx RGBA floats).  A NaN/Inf in img counts
 * as nonfinite and as an error of 1 (so it cannot hide in the mean). */
void   err_add(err_acc *a, const float *img, const float *ref, size_t npx);
double err_psnr(const err_acc *a);     /* peak 1; 999 when equal */

/* The analytic heightfield: normalised height at heightfield uv (u, v),
 * within 0.1 .. 0.9 (the reference of the normal-filter knob). */
double analytic_height(double u, double v);

/* ---- bench_lanes.c --------------------------------------------------------- */

/* Layer efficiency predicted for subgroups of 8, 32 and 64 lanes and
 * several pixel-to-lane assignments, from a w x h RGBA float image of the
 * layers view (abi.h SPLAT_VIEW_LAYERS); prev: the frame before, or NULL.
 * Lines "lanes LABEL: ..." on out. */
void   lanes_predict(FILE *out, const char *label, const float *rgba, const float *prev,
                     int w, int h);

/* ---- the commands: argv[1] is the command's name; exit status ------------- */

int bench_far_bake(int argc, char **argv);      /* bench_device.c */
int bench_shadow(int argc, char **argv);        /* bench_device.c */
int bench_upscale(int argc, char **argv);       /* bench_tools.c  */
int bench_analytic_hf(int argc, char **argv);   /* bench_tools.c  */
int bench_compare(int argc, char **argv);       /* bench_tools.c  */

#endif
