/* test_world.c — the analysis's structure (tests/unit/structure.h) on a
 * world with more materials than colorado: gen_world's biomes (issue 29).
 *
 *   test_world WORLDDIR      (WORLDDIR/scene.sg, from gen_world)
 *
 * Unmerged: combinations from leaf cells only, none a coarse node's union,
 * the largest at most the largest leaf-cell overlap; and the world has
 * coarse nodes whose union is no leaf's (what the analysis compiled before
 * issue 29), so the check is not vacuous.  Merged to 4, 16 and half the
 * leaf combinations: every leaf covered by a superset, the count within the
 * bound.  And the analysis stays sound at random points (points.h), merged
 * too.  Prints the figures (no timing is asserted). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>

#include "points.h"
#include "structure.h"

static const char *world;
static uint64_t rng = 0x9e3779b97f4a7c15ull;

static double raster_painted(void *user, int p, double u, double v)
{
    const splat_scene *s = user;
    return points_raster_bilinear(s->painted[p], s->terrain.width, s->terrain.height, u, v);
}

static void analyse(const splat_scene *s, int max, splat_analysis *a)
{
    sg_diags d;
    sg_diags_init(&d);
    bool ok = splat_analyze_merged(s, max, a, &d);
    if (!ok) sg_diags_print(&d, stderr);
    assert_true(ok);
    sg_diags_free(&d);
}

static void test_world_structure(void **state)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/scene.sg", world);
    const char *const search[] = { ".", NULL };
    splat_scene s;
    sg_diags d;
    sg_diags_init(&d);
    bool ok = splat_scene_load(&s, path, search, &d);
    if (!ok) sg_diags_print(&d, stderr);
    assert_true(ok);
    sg_diags_free(&d);
    assert_true(s.nmaterials > 15);                  /* more than colorado */

    splat_analysis ref;
    analyse(&s, 0, &ref);
    structure_counts c = structure_check(&ref, &ref, 0);
    printf("world: %d materials, %d x %d cells; %d leaf combinations (largest %d layers = "
           "the largest leaf overlap %d); %d coarse nodes had a union of their own before "
           "(%d distinct, the largest %d layers); now %d drawn by the uber-shader, %d by a "
           "superset\n", s.nmaterials, ref.cells_x, ref.cells_z, ref.ncombos, ref.largest,
           ref.leaf_largest, c.unions, c.distinct, c.largest, ref.uber_nodes, ref.cover_nodes);
    assert_true(c.distinct > 0);                    /* not vacuous */
    assert_true(c.largest > ref.largest);           /* and those were bigger */
    points_check_sound(&s, &ref, 8, &rng, raster_painted, &s);

    const int bounds[] = { 4, 16, ref.ncombos / 2 };
    for (int k = 0; k < 3; k++) {
        splat_analysis m;
        analyse(&s, bounds[k], &m);
        structure_counts mc = structure_check(&ref, &m, bounds[k]);
        printf("merged to at most %d: %d combinations, largest %d layers, %d coarse nodes "
               "left to the uber-shader\n", bounds[k], m.ncombos, m.largest, mc.uber);
        assert_int_equal(m.nleaf, ref.ncombos);
        points_check_sound(&s, &m, 4, &rng, raster_painted, &s);
        splat_analysis_free(&m);
    }
    splat_analysis_free(&ref);
    splat_scene_free(&s);
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: test_world WORLDDIR (from gen_world)\n");
        return 2;
    }
    world = argv[1];
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_world_structure),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
