/* test_vector.c — the vector shapes (compiler/vector.c) on the CPU:
 *   - a straight spline's and a square polygon's grid distance (what the
 *     shader computes) equal their analytic distance at random points,
 *     and the mask the closed-form profile;
 *   - a curved spline's and a concave polygon's grid distance equal the
 *     distance over all their segments wherever it is within reach;
 *   - splat_vector_range bounds the distance at random points of random
 *     rectangles (the analysis's soundness), and is tight where it must
 *     be: 0 far away, 1 wholly inside;
 *   - a polygon's second ring is a hole, a spline's curves are apart;
 *   - too many segments in a grid cell is a located OVER_LIMIT error.
 * The GPU side is tests/vector/probe.sh. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scene_load.h"

static uint64_t rng = 0x9E3779B97F4A7C15ull;
static double rnd(double lo, double hi)   /* xorshift64*, deterministic */
{
    rng ^= rng >> 12, rng ^= rng << 25, rng ^= rng >> 27;
    return lo + (hi - lo) * (double)((rng * 2685821657736338717ull) >> 11) / 9007199254740992.0;
}

/* one curve of all its points, for a shape given without curves */
static void one_curve(sg_scene_vector *v, int n)
{
    static int ends[16];
    for (int i = 0; i < n && i < 16; i++)
        if (v[i].ncurves == 0) {
            ends[i] = v[i].npoints;
            v[i].curve_end = &ends[i];
            v[i].ncurves = 1;
        }
}

static void build(sg_scene *sc, sg_scene_vector *v, int n, splat_vectors *out)
{
    one_curve(v, n);
    memset(sc, 0, sizeof *sc);
    sc->name = "t";
    sc->vectors = v;
    sc->nvectors = n;
    sg_diags d;
    sg_diags_init(&d);
    bool ok = splat_vectors_build(sc, out, &d);
    if (!ok) sg_diags_print(&d, stderr);
    sg_diags_free(&d);
    assert_true(ok);
    assert_non_null(out->words);
}

static double seg_dist(double px, double pz, double ax, double az, double bx, double bz)
{
    double ux = bx - ax, uz = bz - az, t = ((px - ax) * ux + (pz - az) * uz) / (ux * ux + uz * uz);
    t = t < 0 ? 0 : t > 1 ? 1 : t;
    return hypot(px - ax - t * ux, pz - az - t * uz);
}

static double smooth_mask(double d, double hw, double f)
{
    double t = fmin(fmax((d - hw) / f, 0), 1);
    return 1 - t * t * (3 - 2 * t);
}

static void test_straight_spline(void **state)
{
    (void)state;
    double pts[] = { 120.5, 80.25, 870.0, 610.75 };
    sg_scene_vector v = { .name = "road", .kind = SPLAT_VEC_SPLINE, .points = pts,
                          .npoints = 2, .width = 8, .falloff = 5,
                          .profile = SPLAT_VEC_SMOOTHSTEP };
    sg_scene sc;
    splat_vectors vs;
    build(&sc, &v, 1, &vs);
    int inside = 0, falloff = 0;
    for (int i = 0; i < 20000; i++) {
        double x = rnd(0, 1000), z = rnd(0, 800);
        if (i % 2) {   /* half of them near the road */
            double t = rnd(-0.05, 1.05);
            x = pts[0] + t * (pts[2] - pts[0]) + rnd(-12, 12);
            z = pts[1] + t * (pts[3] - pts[1]) + rnd(-12, 12);
        }
        double want = seg_dist(x, z, pts[0], pts[1], pts[2], pts[3]);
        double got = splat_vector_distance_grid(&vs, 0, x, z);
        if (want < 9) {
            assert_true(fabs(got - want) < 1e-3);
            double m = splat_vector_profile(&vs, 0, got, false);
            assert_true(fabs(m - smooth_mask(want, 4, 5)) < 1e-3);
            double a = splat_vector_profile(&vs, 0, got, true);
            assert_true(fabs(a - fmin(want / 9, 1)) < 1e-3);
            inside += want < 4, falloff += want > 4;
        } else {
            assert_true(got >= 9 - 1e-3);   /* beyond reach: mask 0, across 1 */
            assert_true(splat_vector_profile(&vs, 0, got, false) < 1e-6);
        }
    }
    assert_true(inside > 500 && falloff > 500);
    splat_vectors_free(&vs);
}

static double box_dist(double x, double z, double x0, double z0, double x1, double z1)
{
    double dx = fmax(fmax(x0 - x, 0), x - x1), dz = fmax(fmax(z0 - z, 0), z - z1);
    return hypot(dx, dz);
}

static void test_square_polygon(void **state)
{
    (void)state;
    double pts[] = { 200, 300, 500, 300, 500, 650, 200, 650 };
    sg_scene_vector v = { .name = "yard", .kind = SPLAT_VEC_POLYGON, .points = pts,
                          .npoints = 4, .falloff = 20, .profile = SPLAT_VEC_LINEAR };
    sg_scene sc;
    splat_vectors vs;
    build(&sc, &v, 1, &vs);
    int in = 0, ring = 0;
    for (int i = 0; i < 20000; i++) {
        double x = rnd(100, 600), z = rnd(200, 750);
        double want = box_dist(x, z, 200, 300, 500, 650);
        double got = splat_vector_distance_grid(&vs, 0, x, z);
        if (want < 20) {
            assert_true(fabs(got - want) < 1e-3);
            assert_true(fabs(splat_vector_profile(&vs, 0, got, false) -
                             (1 - want / 20)) < 1e-3);
            in += want == 0, ring += want > 0;
        } else
            assert_true(got >= 20 - 1e-3);
    }
    assert_true(in > 1000 && ring > 1000);
    splat_vectors_free(&vs);
}

/* the grid against all segments: a winding road and a concave polygon
 * (the notch makes the inside parity matter) sharing a grid */
static void test_grid_equals_all_segments(void **state)
{
    (void)state;
    double road[] = { 50, 60, 200, 400, 330, 380, 420, 700, 700, 720, 900, 300, 760, 120 };
    double yard[] = { 300, 200, 700, 180, 720, 600, 520, 330, 320, 620 };
    sg_scene_vector v[2] = {
        { .name = "road", .kind = SPLAT_VEC_SPLINE, .points = road, .npoints = 7, .width = 6,
          .falloff = 3, .profile = SPLAT_VEC_SMOOTHSTEP },
        { .name = "yard", .kind = SPLAT_VEC_POLYGON, .points = yard, .npoints = 5,
          .falloff = 15, .profile = SPLAT_VEC_LINEAR },
    };
    sg_scene sc;
    splat_vectors vs;
    build(&sc, v, 2, &vs);
    int near[2] = { 0, 0 }, zero = 0;
    for (int i = 0; i < 40000; i++) {
        double x = rnd(0, 1000), z = rnd(0, 800);
        for (int s = 0; s < 2; s++) {
            double reach = s ? 15 : 6;
            double all = splat_vector_distance(&vs, s, x, z);
            double got = splat_vector_distance_grid(&vs, s, x, z);
            if (all <= reach) {
                assert_true(fabs(got - all) < 1e-9);
                near[s]++;
                zero += s == 1 && all == 0;
            } else
                assert_true(got > reach);
        }
    }
    assert_true(near[0] > 300 && near[1] > 3000 && zero > 3000);
    splat_vectors_free(&vs);
}

static void test_range_sound(void **state)
{
    (void)state;
    double road[] = { 50, 60, 200, 400, 330, 380, 420, 700, 700, 720 };
    double yard[] = { 300, 200, 700, 180, 720, 600, 520, 330, 320, 620 };
    sg_scene_vector v[2] = {
        { .name = "road", .kind = SPLAT_VEC_SPLINE, .points = road, .npoints = 5, .width = 10,
          .falloff = 6, .profile = SPLAT_VEC_SMOOTHSTEP },
        { .name = "yard", .kind = SPLAT_VEC_POLYGON, .points = yard, .npoints = 5,
          .falloff = 10, .profile = SPLAT_VEC_LINEAR },
    };
    sg_scene sc;
    splat_vectors vs;
    build(&sc, v, 2, &vs);
    int zero_cells = 0, one_cells = 0;
    for (int i = 0; i < 3000; i++) {
        double w = rnd(1, 120), h = rnd(1, 120), x0 = rnd(-100, 900), z0 = rnd(-100, 800);
        double r[4] = { x0, z0, x0 + w, z0 + h };
        for (int s = 0; s < 2; s++) {
            double lo, hi;
            splat_vector_range(&vs, s, r, &lo, &hi);
            assert_true(lo <= hi);
            double reach = s ? 10 : 11;
            for (int k = 0; k < 50; k++) {
                /* what the shader computes there lies within the bounds
                 * (past the reach only the profiles matter: 0 and 1) */
                double x = rnd(r[0], r[2]), z = rnd(r[1], r[3]);
                double d = splat_vector_distance_grid(&vs, s, x, z);
                assert_true(d >= lo);
                assert_true(d <= hi || d > reach);
                for (int a = 0; a < 2; a++) {
                    double p = splat_vector_profile(&vs, s, d, a);
                    double plo = splat_vector_profile(&vs, s, a ? lo : hi, a);
                    double phi = splat_vector_profile(&vs, s, a ? hi : lo, a);
                    assert_true(p >= plo && p <= phi);
                }
            }
            zero_cells += lo > reach;
            one_cells += s == 1 && hi == 0;
        }
    }
    /* the bounds decide: many rectangles are proven outside (mask 0) and
     * some wholly inside the polygon (mask 1) */
    printf("range: %d of 6000 proven 0, %d wholly inside\n", zero_cells, one_cells);
    assert_true(zero_cells > 1000 && one_cells > 20);
    splat_vectors_free(&vs);
}

/* Curves: a polygon of two rings (the inner one a hole, even-odd) and a
 * spline of two curves (nothing joins them): the analytic distances. */
static void test_curves(void **state)
{
    (void)state;
    double ring[] = { 100, 100, 500, 100, 500, 500, 100, 500,      /* outer */
                      250, 250, 350, 250, 350, 350, 250, 350 };    /* hole  */
    int ring_end[] = { 4, 8 };
    double two[] = { 100, 700, 400, 700, 600, 700, 900, 700 };
    int two_end[] = { 2, 4 };
    sg_scene_vector v[2] = {
        { .name = "yard", .kind = SPLAT_VEC_POLYGON, .points = ring, .npoints = 8,
          .curve_end = ring_end, .ncurves = 2, .falloff = 10, .profile = SPLAT_VEC_LINEAR },
        { .name = "roads", .kind = SPLAT_VEC_SPLINE, .points = two, .npoints = 4,
          .curve_end = two_end, .ncurves = 2, .width = 6, .falloff = 2,
          .profile = SPLAT_VEC_LINEAR },
    };
    sg_scene sc;
    splat_vectors vs;
    build(&sc, v, 2, &vs);
    int hole = 0, gap = 0;
    for (int i = 0; i < 20000; i++) {
        double x = rnd(0, 1000), z = rnd(0, 800);
        double out = box_dist(x, z, 100, 100, 500, 500);
        double in_hole = x > 250 && x < 350 && z > 250 && z < 350;
        double to_hole = -fmax(fmax(250 - x, x - 350), fmax(250 - z, z - 350));
        double want = in_hole ? to_hole : out;   /* 0 inside the ring's area */
        double got = splat_vector_distance_grid(&vs, 0, x, z);
        if (want <= 10) assert_true(fabs(got - want) < 1e-3);
        else assert_true(got > 10);
        hole += in_hole && want > 10;
        /* the road: two pieces along z = 700, none between x 400 and 600 */
        double r = fmin(seg_dist(x, z, 100, 700, 400, 700), seg_dist(x, z, 600, 700, 900, 700));
        double gr = splat_vector_distance_grid(&vs, 1, x, z);
        if (r <= 5) assert_true(fabs(gr - r) < 1e-3);
        else assert_true(gr > 5);
        gap += x > 420 && x < 580 && fabs(z - 700) < 3;
    }
    assert_true(hole > 50 && gap > 10);
    splat_vectors_free(&vs);
}

static void test_cell_limit(void **state)
{
    (void)state;
    enum { N = 400 };
    static double pts[2 * N];
    for (int i = 0; i < N; i++) {   /* a zigzag folded into a few metres */
        pts[2 * i] = 100 + (i % 2) * 3;
        pts[2 * i + 1] = 100 + i * 0.01;
    }
    sg_scene_vector v = { .name = "knot", .kind = SPLAT_VEC_SPLINE, .points = pts,
                          .npoints = N, .width = 2, .falloff = 1, .profile = 0,
                          .loc = { "scene.sg", 7, 12 } };
    one_curve(&v, 1);
    sg_scene sc = { .name = "t", .vectors = &v, .nvectors = 1 };
    splat_vectors vs;
    sg_diags d;
    sg_diags_init(&d);
    assert_false(splat_vectors_build(&sc, &vs, &d));
    assert_int_equal(d.nerrors, 1);
    assert_int_equal(d.items[0].id, SG_E_OVER_LIMIT);
    assert_int_equal(d.items[0].loc.line, 7);
    assert_int_equal(d.items[0].loc.col, 12);
    assert_null(vs.words);
    sg_diags_free(&d);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_straight_spline),
        cmocka_unit_test(test_square_polygon),
        cmocka_unit_test(test_grid_equals_all_segments),
        cmocka_unit_test(test_range_sound),
        cmocka_unit_test(test_curves),
        cmocka_unit_test(test_cell_limit),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
