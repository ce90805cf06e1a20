/* points.h — test helpers for checking the scene analysis at points of the
 * heightfield (points.c; linked into every unit test and test_scene).
 *
 * The analysis promises: at every point of a leaf cell, every material the
 * CPU reference makes visible (front to back: w = cover * mask > 0 until
 * the cover reaches 0) is in the cell's combination.  points_check_sound
 * tests that at random points, with random params and arbitrary texture
 * content; where the painted values come from is the caller's (the raster,
 * or the sparse sampler's CPU twin). */
#ifndef SPLAT_TEST_POINTS_H
#define SPLAT_TEST_POINTS_H

#include <stdbool.h>
#include <stdint.h>

#include "scene.h"

/* xorshift64; the caller keeps the state (each test its own sequence). */
uint32_t points_rnd(uint64_t *state);
double   points_rnd01(uint64_t *state);      /* [0, 1) */

bool points_combo_has(const splat_combo *c, int material);

/* An ir_texture sampler with arbitrary content: a hash of (texture, texel
 * of a 512 x 512 grid) in [0, 1] per channel. */
void points_any_texture(void *user, int texture, double u, double v, double rgba[4]);

/* The bilinear value (clamp to edge, texel centres at i + 0.5) of an 8-bit
 * raster at uv, in [0, 1]. */
double points_raster_bilinear(const uint8_t *px, int w, int h, double u, double v);

/* The terrain inputs at heightfield uv: height, normal, slope (1 - n.y),
 * uv and position; every other field of *env zeroed. */
void points_env(const splat_terrain *t, double u, double v, ir_env *env);

/* The value of painted mask p (the ir's painted p) at uv. */
typedef double (*points_painted_fn)(void *user, int p, double u, double v);

/* `samples` random points in every leaf cell of `a`: fails the test
 * (cmocka) at the first visible material missing from its combination.
 * Returns the number of points checked. */
int points_check_sound(const splat_scene *s, const splat_analysis *a, int samples,
                       uint64_t *rng, points_painted_fn painted, void *user);

#endif
