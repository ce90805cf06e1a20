/* test_painted.c — the scene's painted masks as the pack stores them
 * (compiler/painted.c over sparse.h):
 *   - the per-mask options of the scene file reach the sparse build
 *     (tests/painted/colorado_levels.sg: colorado with max_level = 1);
 *   - colorado's masks stored sparse (BC4) take at most 15 % of their dense
 *     8-bit bytes, constant cells cost no atlas slot, and the reduced-level
 *     option at most halves that again (the figures and the reduction error
 *     are printed);
 *   - the analysis over the sparse masks is sound for what the GPU samples:
 *     at random points of every leaf cell, every material the CPU reference
 *     shows with the painted values of sparse_sample (BC4 decoded, reduced
 *     levels) is in the cell's combination. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "points.h"
#include "scene.h"

static void load_ok(splat_scene *s, const char *path)
{
    sg_diags d;
    sg_diags_init(&d);
    bool ok = splat_scene_load(s, path, NULL, &d);
    if (!ok)
        sg_diags_print(&d, stderr);
    assert_true(ok);
    sg_diags_free(&d);
}

static void build_ok(const splat_scene *s, splat_painted_format f, sparse_masks *out)
{
    sg_diags d;
    sg_diags_init(&d);
    bool ok = splat_painted_build(s, f, out, &d);
    if (!ok)
        sg_diags_print(&d, stderr);
    assert_true(ok);
    sg_diags_free(&d);
}

static void test_format_names(void **state)
{
    (void)state;
    splat_painted_format f = SPLAT_PAINTED_DENSE;
    assert_true(splat_painted_format_parse("bc4", &f));
    assert_int_equal(f, SPLAT_PAINTED_BC4);
    assert_true(splat_painted_format_parse("r8", &f));
    assert_int_equal(f, SPLAT_PAINTED_R8);
    assert_true(splat_painted_format_parse("dense", &f));
    assert_int_equal(f, SPLAT_PAINTED_DENSE);
    assert_false(splat_painted_format_parse("bc7", &f));
    assert_string_equal(splat_painted_format_name(SPLAT_PAINTED_R8), "r8");
}

/* Colorado: options parsed, fractions and the constant cells. */
static void test_colorado_sizes(void **state)
{
    (void)state;
    splat_scene full, lv;
    load_ok(&full, "examples/colorado/scene.sg");
    load_ok(&lv, "tests/painted/colorado_levels.sg");
    /* the fields' three masks (the road is a spline since issue 31) */
    assert_int_equal(full.desc->npainted, 3);
    assert_int_equal(lv.desc->npainted, 3);
    for (int i = 0; i < 3; i++) {
        assert_int_equal(full.desc->painted[i].max_level, 0);
        assert_true(full.desc->painted[i].max_error == 1.0);
        assert_false(full.desc->painted[i].has_near);
        assert_int_equal(lv.desc->painted[i].max_level, 1);
    }
    sparse_masks a, b, r8;
    build_ok(&full, SPLAT_PAINTED_BC4, &a);
    build_ok(&full, SPLAT_PAINTED_R8, &r8);
    build_ok(&lv, SPLAT_PAINTED_BC4, &b);
    sparse_stats sa, sb, sr;
    sparse_get_stats(&a, &sa);
    sparse_get_stats(&b, &sb);
    sparse_get_stats(&r8, &sr);
    sparse_print_stats(&a, stdout);
    sparse_print_stats(&b, stdout);
    double err = 0;
    for (int m = 0; m < b.nmasks; m++)
        err = fmax(err, b.info[m].reduce_error);
    printf("colorado painted masks: dense %zu B; sparse BC4 %zu B (%.2f %%), R8 %zu B "
           "(%.2f %%), BC4 with levels <= 1 %zu B (%.2f %%, max reduction error %.3f)\n",
           sa.dense_bytes, sa.total_bytes, 100 * sa.fraction, sr.total_bytes,
           100 * sr.fraction, sb.total_bytes, 100 * sb.fraction, err);
    assert_true(sa.fraction <= 0.15);
    assert_true(sb.total_bytes * 2 <= sa.total_bytes);
    assert_true(sb.reduced_cells > 0 && err > 0);
    /* constant cells are index constants, never slots: the atlas holds at
     * most one slot per stored cell */
    size_t ncell = (size_t)a.cells_x * a.cells_z;
    int consts = 0, stored = 0;
    for (int m = 0; m < a.nmasks; m++)
        for (size_t c = 0; c < ncell; c++) {
            uint16_t e = a.index[((size_t)(m / 4) * ncell + c) * 4 + (size_t)(m % 4)];
            consts += e == SPARSE_CONST0 || e == SPARSE_CONST1;
            stored += e != SPARSE_CONST0 && e != SPARSE_CONST1;
        }
    assert_int_equal(consts, sa.const_cells);
    assert_int_equal(stored, sa.stored_cells);
    assert_true(consts > 0 && a.nslots <= stored);
    assert_true(sa.atlas_bytes == (size_t)a.atlas_width * a.atlas_height / 2);
    assert_true((size_t)a.nslots * SPARSE_SLOT * SPARSE_SLOT <=
                (size_t)a.atlas_width * a.atlas_height);
    sparse_free(&a);
    sparse_free(&b);
    sparse_free(&r8);
    splat_scene_free(&full);
    splat_scene_free(&lv);
}

/* ---- soundness at points, painted values as the GPU samples them -------- */

static uint64_t rng = 0x9e3779b97f4a7c15ull;

typedef struct painted_src { const splat_scene *s; const sparse_masks *sp; } painted_src;

/* The scene's painted mask p as the GPU samples it; past them, the ir's
 * vector leaves (vector.NAME, vector.NAME.across) as vector.c draws them. */
static double sparse_painted(void *user, int p, double u, double v)
{
    const painted_src *src = user;
    if (p < src->sp->nmasks)
        return sparse_sample(src->sp, p, u, v);
    bool across;
    int vs = splat_vector_find(src->s->desc, src->s->ir.painted[p].name, &across);
    assert_true(vs >= 0);
    const double *size = src->s->terrain.size;
    double dist = splat_vector_distance_grid(&src->s->vectors, vs, u * size[0], v * size[1]);
    return splat_vector_profile(&src->s->vectors, vs, dist, across);
}

static void test_analysis_sound_over_sparse(void **state)
{
    (void)state;
    splat_scene s;
    load_ok(&s, "tests/painted/colorado_levels.sg");
    sparse_masks sp;
    build_ok(&s, SPLAT_PAINTED_BC4, &sp);
    s.sparse = &sp;
    sg_diags d;
    sg_diags_init(&d);
    splat_analysis a;
    assert_true(splat_analyze(&s, &a, &d));
    sg_diags_free(&d);

    /* the scene's painted mask i is the ir's painted i */
    painted_src src = { &s, &sp };
    int checked = points_check_sound(&s, &a, 12, &rng, sparse_painted, &src);
    printf("%d points in %d cells: every visible material in its cell's combination "
           "(%d combinations)\n", checked, a.cells_x * a.cells_z, a.ncombos);
    splat_analysis_free(&a);
    sparse_free(&sp);
    splat_scene_free(&s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_format_names),
        cmocka_unit_test(test_colorado_sizes),
        cmocka_unit_test(test_analysis_sound_over_sparse),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
