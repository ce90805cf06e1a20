/* test_shading_lod.c — the CPU shading LOD's side of the node library
 * (view.shading_lod, 1 under the LOD, 0 on GPUs; runtime/DESIGN.md "CPU
 * shading LOD"), against references written out here, with ir_eval at
 * random points:
 *   nodes/detile.sg      hex_tile reads only the vertex of the largest
 *                        weight (the full three-read blend at 0);
 *   nodes/projection.sg  triplanar reads only the axis of the largest
 *                        weight;
 *   nodes/parallax.sg    parallax4/8/16 give back the uv (no steps);
 * and the optimiser's fold of mix(x, x, view.shading_lod) to x (opt_fold.c),
 * which keeps the distance classes of a parallax material as they were.
 * Textures read a smooth procedural function of the raw uv, so a wrong
 * offset or axis shows.  Runs from the repository root. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ir.h"
#include "lowered.h"

static double rnd(double lo, double hi)
{
    return lo + (hi - lo) * ((double)rand() / RAND_MAX);
}

static ir_env env_at(double x, double y, double z, int lod)
{
    ir_env e = lowered_env(x, y, z);
    e.shading_lod = lod;
    return e;
}

/* ---- hex tiling ------------------------------------------------------------ */

/* The copy of the vertex of the largest barycentric weight (Mikkelsen
 * 2022's triangle grid; ties to the first, then the second), and in *full
 * the three-copy blend with weights w^4, renormalised. */
static void hex_lod_ref(double u, double v, double out[4], double full[4])
{
    const double grid = 3.4641016;
    double gx = u * grid, gy = v * grid;
    double skx = gx, sky = -0.57735027 * gx + 1.15470054 * gy;
    double bx = floor(skx), by = floor(sky);
    double fx = skx - bx, fy = sky - by, z = 1.0 - fx - fy;
    double s = -z >= 0 ? 1 : 0, s2 = 2 * s - 1;
    double w[3] = {fabs(-z * s2), fabs(s - fy * s2), fabs(s - fx * s2)};
    double vx[3] = {bx + s, bx + s, bx + 1 - s}, vy[3] = {by + s, by + 1 - s, by + s};
    int k = w[0] >= w[1] && w[0] >= w[2] ? 0 : w[1] >= w[2] ? 1 : 2;
    double sum = 0;
    for (int c = 0; c < 4; c++)
        full[c] = 0;
    for (int j = 0; j < 3; j++) {
        double h1 = lowered_hash_perm(vx[j], vy[j]);
        double k1 = floor(289 * h1 + 0.5);
        double h2 = lowered_hash_perm(vy[j] + k1, vx[j] + k1);
        double c[4];
        lowered_texture(u + h1, v + h2, c);
        if (j == k)
            memcpy(out, c, sizeof c);
        double p = pow(w[j], 4.0);
        sum += p;
        for (int i = 0; i < 4; i++)
            full[i] += p * c[i];
    }
    for (int c = 0; c < 4; c++)
        full[c] /= sum;
}

static void test_hex_tile_lod(void **state)
{
    (void)state;
    srand(33);
    int apart = 0, near = 0;
    for (int i = 0; i < 400; i++) {
        double u = rnd(-40, 40), v = rnd(-40, 40);
        char node[256];
        snprintf(node, sizeof node, "hex_tile { tex = tx, uv = vec2(%.17g, %.17g) }", u, v);
        double got[4], got_full[4], want[4], full[4];
        ir_env on = env_at(0, 0, 0, 1), off = env_at(0, 0, 0, 0);
        lowered_eval_node("detile.sg", &on, "albedo", "n.out.rgb", node, got);
        lowered_eval_node("detile.sg", &off, "albedo", "n.out.rgb", node, got_full);
        hex_lod_ref(u, v, want, full);
        for (int c = 0; c < 3; c++) {
            CLOSE(got[c], want[c], 1e-9);
            CLOSE(got_full[c], full[c], 1e-9);
        }
        double d = fabs(got[0] - got_full[0]);
        apart += d > 0.01;   /* near the hexagons' edges */
        near += d < 0.01;    /* inside a hexagon: the same copy */
    }
    /* the LOD changes the picture only at the edges: most points agree */
    assert_true(apart > 10);
    assert_true(near > 200);
}

/* ---- triplanar --------------------------------------------------------------- */

static void test_triplanar_lod(void **state)
{
    (void)state;
    srand(34);
    int picked[3] = {0};
    for (int i = 0; i < 300; i++) {
        double n[3] = {rnd(-1, 1), rnd(0.05, 1), rnd(-1, 1)};
        double l = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        ir_env e = env_at(rnd(-500, 500), rnd(0, 300), rnd(-500, 500), 1);
        for (int c = 0; c < 3; c++)
            e.normal[c] = n[c] / l;
        double got[4], want[4];
        lowered_eval_node("projection.sg", &e, "albedo", "n.out.rgb",
                  "triplanar { tex = tx, scale = 8.0, sharpness = 4.0 }", got);
        /* the axis of the largest |n| (its weight |n|^4 / sum is the largest) */
        double a[3] = {fabs(e.normal[0]), fabs(e.normal[1]), fabs(e.normal[2])};
        int k = a[0] >= a[1] && a[0] >= a[2] ? 0 : a[1] >= a[2] ? 1 : 2;
        const double *p = e.position;
        double uv[3][2] = {{p[2], p[1]}, {p[0], p[2]}, {p[0], p[1]}};
        lowered_texture(uv[k][0] / 8.0, uv[k][1] / 8.0, want);
        for (int c = 0; c < 3; c++)
            CLOSE(got[c], want[c], 1e-9);
        picked[k]++;
    }
    for (int k = 0; k < 3; k++)
        assert_true(picked[k] > 10);
}

/* ---- parallax ---------------------------------------------------------------- */

static void test_parallax_lod(void **state)
{
    (void)state;
    static const char *const steps[] = {"parallax4", "parallax8", "parallax16"};
    srand(35);
    for (int s = 0; s < 3; s++) {
        int moved = 0;
        for (int i = 0; i < 50; i++) {
            double u = rnd(-10, 10), v = rnd(-10, 10);
            char node[256];
            snprintf(node, sizeof node,
                     "%s { tex = tx, uv = vec2(%.17g, %.17g), offset = vec2(0.3, -0.2) }",
                     steps[s], u, v);
            double got[4], full[4];
            ir_env on = env_at(0, 0, 0, 1), off = env_at(0, 0, 0, 0);
            lowered_eval_node("parallax.sg", &on, "albedo", "n.out.xyy", node, got);
            lowered_eval_node("parallax.sg", &off, "albedo", "n.out.xyy", node, full);
            CLOSE(got[0], u, 0);
            CLOSE(got[1], v, 0);
            moved += fabs(full[0] - u) > 1e-6;
        }
        assert_true(moved > 10);   /* at 0 the steps move the uv */
    }
}

/* ---- mix(x, x, view.shading_lod) folds to x ------------------------------------ */

static int count_op(const ir *ir, ir_op op)
{
    int n = 0;
    for (uint32_t id = 1; id < ir->nnodes; id++)
        n += ir->nodes[id].op == op;
    return n;
}

static void test_fold_lod_mix(void **state)
{
    (void)state;
    lowered l;
    lowered_load(&l, "material t {\n"
                     "    node u : div { a = terrain.position.xz, b = 3.0 }\n"
                     "    node m : mix { a = u.out, b = u.out, t = view.shading_lod }\n"
                     "    node k : mix { a = u.out, b = terrain.position.zx, t = view.shading_lod }\n"
                     "    node s : add { a = m.out, b = k.out }\n"
                     "    out albedo = s.out.xyy\n"
                     "}\n");
    assert_int_equal(count_op(&l.ir, IR_OP_MIX), 2);
    ir_optimize(&l.ir, NULL);
    /* the mix of two equal sides went, the other stays (its sides differ) */
    assert_int_equal(count_op(&l.ir, IR_OP_MIX), 1);
    ir_env e = env_at(6, 0, 9, 1);
    double out[4];
    ir_eval(&l.ir, ir_find_root(&l.ir, "t.albedo"), &e, out);
    CLOSE(out[0], 2.0 + 9.0, 1e-12);   /* u.x + position.z */
    CLOSE(out[1], 3.0 + 6.0, 1e-12);
    lowered_free(&l);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_hex_tile_lod),
        cmocka_unit_test(test_triplanar_lod),
        cmocka_unit_test(test_parallax_lod),
        cmocka_unit_test(test_fold_lod_mix),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
