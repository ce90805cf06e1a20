/* test_analysis.c — the scene analysis (compiler/analysis.c): soundness on
 * thin slivers (a narrow slope band, a single painted texel), opaque upper
 * materials dropping lower ones, combinations from leaf cells only (a
 * coarse node gets the smallest compiled cover of its union or the
 * über-shader, never a composite of its own), merging into at most P
 * supersets, the destructible area, deterministic ids, and a randomised
 * check that every sample point's true combination is inside its cell's.
 *
 * Scenes are built by hand: a heightfield in memory, an sg_scene filled in
 * directly and material masks built with the IR builder, so each test
 * controls exactly what the analysis sees. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "abi.h"
#include "points.h"
#include "structure.h"
#include "scene.h"

/* ---- fixtures ------------------------------------------------------------ */

typedef struct fixture {
    splat_scene      s;
    sg_scene         desc;
    char            *names[8];
    sg_scene_painted painted[4];
    uint8_t         *rasters[4];
} fixture;

/* A flat heightfield of w x h texels, 1 m texels, 100 m max height, and
 * the material names bottom first; masks are set by the test. */
static fixture *fixture_new(int w, int h, int cell, int nmat, const char *const *names)
{
    fixture *f = calloc(1, sizeof *f);
    assert_non_null(f);
    f->desc.name = "test";
    f->desc.loc = (sg_loc){ "test.sg", 1, 1 };
    f->desc.size[0] = w;
    f->desc.size[1] = h;
    f->desc.max_height = 100;
    f->desc.cell_texels = cell;
    for (int i = 0; i < nmat; i++) f->names[i] = (char *)names[i];
    f->desc.materials = f->names;
    f->desc.nmaterials = nmat;
    f->s.desc = &f->desc;
    f->s.nmaterials = nmat;
    splat_terrain *t = &f->s.terrain;
    t->width = w;
    t->height = h;
    t->size[0] = w;
    t->size[1] = h;
    t->max_height = 100;
    t->texels = calloc((size_t)w * h, sizeof *t->texels);
    assert_non_null(t->texels);
    ir_init(&f->s.ir);
    /* The bottom material's mask is never read, but lowering sets it. */
    char root[64];
    snprintf(root, sizeof root, "%s.mask", names[0]);
    ir_set_root(&f->s.ir, root, ir_constf(&f->s.ir, 1.0));
    return f;
}

/* A painted mask raster (all 0) registered in the scene and the IR. */
static uint8_t *fixture_painted(fixture *f, const char *name)
{
    int k = f->desc.npainted++;
    f->painted[k].name = (char *)name;
    f->painted[k].loc = (sg_loc){ "test.sg", 2, 1 };
    f->desc.painted = f->painted;
    size_t n = (size_t)f->s.terrain.width * f->s.terrain.height;
    f->rasters[k] = calloc(n, 1);
    assert_non_null(f->rasters[k]);
    f->s.painted = f->rasters;
    assert_int_equal(ir_add_painted(&f->s.ir, name), k);
    return f->rasters[k];
}

static void fixture_free(fixture *f)
{
    for (int k = 0; k < f->desc.npainted; k++) free(f->rasters[k]);
    splat_terrain_free(&f->s.terrain);
    ir_free(&f->s.ir);
    free(f);
}

static void set_mask(fixture *f, const char *material, ir_ref r)
{
    char root[64];
    snprintf(root, sizeof root, "%s.mask", material);
    ir_set_root(&f->s.ir, root, r);
}

static void set_texel(fixture *f, int x, int z, uint16_t v)
{
    f->s.terrain.texels[(size_t)z * f->s.terrain.width + x] = v;
}

/* saturate((x - lo) / (hi - lo)): the linear ramp of Andersson 2007. */
static ir_ref ramp(ir *ir, ir_ref x, double lo, double hi)
{
    ir_ref d = ir_op2(ir, IR_OP_SUB, x, ir_constf(ir, lo));
    return ir_op1(ir, IR_OP_SATURATE, ir_op2(ir, IR_OP_DIV, d, ir_constf(ir, hi - lo)));
}

static void analyze(fixture *f, splat_analysis *a)
{
    sg_diags d;
    sg_diags_init(&d);
    bool ok = splat_analyze(&f->s, a, &d);
    if (!ok) sg_diags_print(&d, stderr);
    assert_true(ok);
    assert_int_equal(d.nerrors, 0);
    sg_diags_free(&d);
}

static const splat_combo *combo_at(const splat_analysis *a, int level, int x, int z)
{
    const splat_level *lv = &a->levels[level];
    assert_true(x < lv->width && z < lv->height);
    int id = lv->ids[(size_t)z * lv->width + x];
    assert_true(id < a->ncombos);
    return &a->combos[id];
}

/* Whether combination c is exactly `want` (material indices, top first,
 * terminated by -1). */
static bool combo_is(const splat_combo *c, const int *want)
{
    int n = 0;
    while (want[n] >= 0) n++;
    if (c->nmaterials != n) return false;
    for (int i = 0; i < n; i++)
        if (c->materials[i] != want[i]) return false;
    return true;
}

static bool combo_has(const splat_combo *c, int m)
{
    for (int i = 0; i < c->nmaterials; i++)
        if (c->materials[i] == m) return true;
    return false;
}

static void analyze_merged(fixture *f, int max, splat_analysis *a)
{
    sg_diags d;
    sg_diags_init(&d);
    bool ok = splat_analyze_merged(&f->s, max, a, &d);
    if (!ok) sg_diags_print(&d, stderr);
    assert_true(ok);
    assert_int_equal(d.nerrors, 0);
    sg_diags_free(&d);
}

/* check_structure of f unmerged and merged to 1, 2, ... nleaf - 1 (at most
 * `steps` bounds): every leaf covered, the count within the bound.
 * Returns the unmerged analysis's über nodes. */
static int check_all_bounds(fixture *f, int steps)
{
    splat_analysis ref;
    analyze(f, &ref);
    int uber = structure_check(&ref, &ref, 0).uber;
    int n = ref.ncombos, stride = n / steps > 1 ? n / steps : 1;
    for (int max = 1; max < n; max += stride) {
        splat_analysis m;
        analyze_merged(f, max, &m);
        structure_check(&ref, &m, max);
        assert_true(m.largest >= ref.largest);
        splat_analysis_free(&m);
    }
    splat_analysis m;                               /* a bound above the count */
    analyze_merged(f, n + 5, &m);
    assert_int_equal(m.ncombos, n);
    structure_check(&ref, &m, 0);
    splat_analysis_free(&m);
    splat_analysis_free(&ref);
    return uber;
}

/* ---- slivers ------------------------------------------------------------- */

/* A narrow slope band: flat ground with one 1-texel step in one cell.  A
 * cliff material that needs slope > 0.3 covers a sliver of that cell only,
 * and must be kept there (and only where the step's footprint reaches). */
static void test_thin_slope_band_kept(void **state)
{
    const char *names[] = { "grass", "cliff" };
    fixture *f = fixture_new(32, 32, 8, 2, names);
    /* Texel x = 12, z = 12 raised 20 m: the cross filter sees it from
     * texels 11..13 of row 12 and 11..13 of column 12 (slope ~0.9 there),
     * all inside cell (1, 1) = texels 8..15; everything else is flat. */
    set_texel(f, 12, 12, 13107);
    ir *ir = &f->s.ir;
    set_mask(f, "cliff", ramp(ir, ir_input(ir, IR_IN_SLOPE), 0.3, 0.31));
    splat_analysis a;
    analyze(f, &a);
    assert_int_equal(a.cells_x, 4);
    assert_int_equal(a.cells_z, 4);
    assert_true(combo_has(combo_at(&a, 0, 1, 1), 1));
    /* Every other cell's footprint (cell + one texel) misses texels 11..13:
     * grass only. */
    const int grass[] = { 0, -1 }, both[] = { 1, 0, -1 };
    for (int z = 0; z < 4; z++)
        for (int x = 0; x < 4; x++)
            assert_true(combo_is(combo_at(&a, 0, x, z),
                                 x == 1 && z == 1 ? both : grass));
    /* The cliff's sliver is real: the CPU twin sees a slope over 0.3 at
     * the step, so dropping it would be wrong. */
    double n[3];
    splat_terrain_normal(&f->s.terrain, 11.5 / 32, 12.5 / 32, n);
    assert_true(1 - n[1] > 0.3);
    splat_analysis_free(&a);
    fixture_free(f);
}

/* A single painted texel keeps its material in the cells whose bilinear
 * footprint holds it: only its own cell when inside, the two cells on
 * either side when it sits on a cell border. */
static void test_single_painted_texel_kept(void **state)
{
    const char *names[] = { "grass", "field" };
    fixture *f = fixture_new(32, 32, 8, 2, names);
    uint8_t *px = fixture_painted(f, "fields");
    ir *ir = &f->s.ir;
    set_mask(f, "field", ir_painted_ref(ir, 0));
    px[20 * 32 + 19] = 1;                  /* 1/255, inside cell (2, 2) */
    splat_analysis a;
    analyze(f, &a);
    for (int z = 0; z < 4; z++)
        for (int x = 0; x < 4; x++)
            assert_int_equal(combo_has(combo_at(&a, 0, x, z), 1),
                             x == 2 && z == 2);
    splat_analysis_free(&a);

    /* Texel x = 8 is the first of cell 1; cell 0's footprint ring reads it. */
    px[20 * 32 + 19] = 0;
    px[4 * 32 + 8] = 255;
    analyze(f, &a);
    for (int z = 0; z < 4; z++)
        for (int x = 0; x < 4; x++)
            assert_int_equal(combo_has(combo_at(&a, 0, x, z), 1),
                             z == 0 && (x == 0 || x == 1));
    splat_analysis_free(&a);
    fixture_free(f);
}

/* ---- opaque materials ---------------------------------------------------- */

/* Heights: left half 0 m, right half 80 m.  Stack: grass (base), dirt
 * (mask 0.5 everywhere: present, never opaque), snow (opaque above 50 m).
 * High cells show snow alone; low cells dirt over grass; the cells at the
 * step see both and keep all three. */
static fixture *snow_scene(void)
{
    const char *names[] = { "grass", "dirt", "snow" };
    fixture *f = fixture_new(40, 24, 8, 3, names);
    for (int z = 0; z < 24; z++)
        for (int x = 20; x < 40; x++)
            set_texel(f, x, z, 52428);         /* 0.8 * 100 m */
    ir *ir = &f->s.ir;
    set_mask(f, "dirt", ir_constf(ir, 0.5));
    set_mask(f, "snow", ramp(ir, ir_input(ir, IR_IN_HEIGHT), 40, 50));
    return f;
}

static void test_opaque_upper_drops_lower(void **state)
{
    fixture *f = snow_scene();
    splat_analysis a;
    analyze(f, &a);
    assert_int_equal(a.cells_x, 5);
    assert_int_equal(a.cells_z, 3);
    const int snow[] = { 2, -1 }, low[] = { 1, 0, -1 }, all[] = { 2, 1, 0, -1 };
    for (int z = 0; z < 3; z++) {
        assert_true(combo_is(combo_at(&a, 0, 0, z), low));
        assert_true(combo_is(combo_at(&a, 0, 1, z), low));
        /* Cells 2 (texels 16..23) and 3 (24..31): the step at x = 20 is
         * inside cell 2; cell 3's ring starts at texel 23, all high. */
        assert_true(combo_is(combo_at(&a, 0, 2, z), all));
        assert_true(combo_is(combo_at(&a, 0, 3, z), snow));
        assert_true(combo_is(combo_at(&a, 0, 4, z), snow));
    }
    /* Counts add up; the naive approach would need every subset. */
    int cells = 0, nodes = 0, total = 0;
    for (int i = 0; i < a.ncombos; i++) {
        cells += a.combos[i].ncells;
        nodes += a.combos[i].nnodes;
    }
    for (int L = 0; L < a.nlevels; L++)
        total += a.levels[L].width * a.levels[L].height;
    assert_int_equal(cells, 15);
    assert_int_equal(nodes, total);
    assert_true(a.naive_subsets == 4.0);
    assert_int_equal(a.largest, 3);
    splat_analysis_free(&a);
    fixture_free(f);
}

/* ---- quadtree ------------------------------------------------------------ */

static void test_quadtree_union(void **state)
{
    fixture *f = snow_scene();
    splat_analysis a;
    analyze(f, &a);
    /* 5 x 3 cells -> 3 x 2 -> 2 x 1 -> 1 x 1. */
    assert_int_equal(a.nlevels, 4);
    const int w[] = { 5, 3, 2, 1 }, h[] = { 3, 2, 1, 1 };
    for (int L = 0; L < 4; L++) {
        assert_int_equal(a.levels[L].width, w[L]);
        assert_int_equal(a.levels[L].height, h[L]);
    }
    const int snow[] = { 2, -1 }, low[] = { 1, 0, -1 }, all[] = { 2, 1, 0, -1 };
    /* Level 1 node (0, 0) = low cells only; (2, 0) = cell 4: snow only;
     * (1, 0) = cells 2, 3: the union of {snow, dirt, grass} and {snow},
     * which is cell 2's own combination, so no node needs one of its own. */
    assert_true(combo_is(combo_at(&a, 1, 0, 0), low));
    assert_true(combo_is(combo_at(&a, 1, 2, 0), snow));
    assert_true(combo_is(combo_at(&a, 1, 1, 0), all));
    assert_true(combo_is(combo_at(&a, 3, 0, 0), all));
    assert_int_equal(a.ncombos, 3);
    assert_int_equal(structure_check(&a, &a, 0).uber, 0);
    splat_analysis_free(&a);
    fixture_free(f);
}

/* Four cells in a row, painted: rock opaque in cell 0, rock over grass in
 * cell 1 (its footprint ring reads cell 0's rock), grass alone in cell 2,
 * field over grass in cell 3.  Each level-1 node's union is a leaf's
 * combination, but the root's, {rock, field, grass}, is no leaf's: it is
 * not compiled, the root gets SPLAT_COMBO_UBER.  Merged to two, every
 * leaf's set is inside its superset; merged to one, that superset covers
 * the root as well. */
static fixture *strip_scene(void)
{
    const char *names[] = { "grass", "field", "rock" };
    fixture *f = fixture_new(32, 8, 8, 3, names);
    uint8_t *fields = fixture_painted(f, "fields");
    uint8_t *rocks = fixture_painted(f, "rocks");
    for (int z = 0; z < 8; z++) {
        for (int x = 0; x <= 8; x++) rocks[z * 32 + x] = 255;
        for (int x = 26; x < 32; x++) fields[z * 32 + x] = 128;
    }
    ir *ir = &f->s.ir;
    set_mask(f, "field", ir_painted_ref(ir, 0));
    set_mask(f, "rock", ir_painted_ref(ir, 1));
    return f;
}

static void test_coarse_union_not_compiled(void **state)
{
    fixture *f = strip_scene();
    splat_analysis a;
    analyze(f, &a);
    const int rock[] = { 2, -1 }, rock_grass[] = { 2, 0, -1 }, grass[] = { 0, -1 },
              field[] = { 1, 0, -1 };
    assert_true(combo_is(combo_at(&a, 0, 0, 0), rock));
    assert_true(combo_is(combo_at(&a, 0, 1, 0), rock_grass));
    assert_true(combo_is(combo_at(&a, 0, 2, 0), grass));
    assert_true(combo_is(combo_at(&a, 0, 3, 0), field));
    assert_int_equal(a.nlevels, 3);
    assert_true(combo_is(combo_at(&a, 1, 0, 0), rock_grass));
    assert_true(combo_is(combo_at(&a, 1, 1, 0), field));
    assert_int_equal(a.levels[2].ids[0], SPLAT_COMBO_UBER);
    assert_int_equal(a.ncombos, 4);
    assert_int_equal(a.largest, 2);               /* not the root's 3 */
    assert_int_equal(a.uber_nodes, 1);
    structure_counts sc = structure_check(&a, &a, 0);
    assert_int_equal(sc.uber, 1);
    assert_int_equal(sc.unions, 1);           /* the root: compiled before issue 29 */
    assert_int_equal(sc.largest, 3);

    /* Merged to two: the cheapest merges first ({rock} into {rock, grass}
     * costs one layer on one cell), never more than two pipelines. */
    splat_analysis m;
    analyze_merged(f, 2, &m);
    assert_int_equal(m.nleaf, 4);
    assert_int_equal(m.ncombos, 2);
    assert_true(combo_is(combo_at(&m, 0, 0, 0), rock_grass));
    assert_true(combo_is(combo_at(&m, 0, 3, 0), field));
    assert_int_equal(structure_check(&a, &m, 2).uber, 1);
    splat_analysis_free(&m);
    /* Merged to one: {rock, field, grass} everywhere, the root covered. */
    analyze_merged(f, 1, &m);
    assert_int_equal(m.ncombos, 1);
    assert_int_equal(m.levels[2].ids[0], 0);
    assert_int_equal(structure_check(&a, &m, 1).uber, 0);
    splat_analysis_free(&m);

    char *text = NULL;
    size_t len = 0;
    FILE *out = open_memstream(&text, &len);
    assert_non_null(out);
    splat_analysis_report(&f->s, &a, out);
    fclose(out);
    assert_non_null(strstr(text, "combinations: 4 in leaf cells, 4 compiled"));
    assert_non_null(strstr(text, "largest combination: 2 materials (largest leaf-cell overlap: 2)"));
    assert_non_null(strstr(text, "0 drawn by a compiled superset of their union, 1 by the uber-shader"));
    free(text);
    splat_analysis_free(&a);
    fixture_free(f);
}

/* ---- destruction --------------------------------------------------------- */

static void test_destruction_area(void **state)
{
    const char *names[] = { "grass", "cliff", "burnt" };
    fixture *f = fixture_new(64, 32, 16, 3, names);
    f->desc.has_destruction = true;
    f->desc.destruction_origin[0] = 40;    /* metres: texels are 1 m */
    f->desc.destruction_origin[1] = 0;
    f->desc.destruction_size[0] = 6;       /* x 40..46, z 0..6 */
    f->desc.destruction_size[1] = 6;
    f->desc.destruction_cell = 2;
    ir *ir = &f->s.ir;
    set_mask(f, "cliff", ramp(ir, ir_input(ir, IR_IN_SLOPE), 0.5, 0.6));
    set_mask(f, "burnt", ir_input(ir, IR_IN_DESTRUCTION));
    splat_analysis a;
    analyze(f, &a);
    /* Cell (2, 0) covers x 32..48 m and z 0..16 m: the area is inside.
     * Craters may make cliffs there, so cliff is kept on flat ground. */
    const int flat[] = { 0, -1 }, reached[] = { 2, 1, 0, -1 }, near[] = { 1, 0, -1 };
    assert_true(combo_is(combo_at(&a, 0, 2, 0), reached));
    /* Cell (3, 0) starts at x = 48, two texels from the area: no
     * destruction mask there, but its filters read texels craters lower. */
    assert_true(combo_is(combo_at(&a, 0, 3, 0), near));
    assert_true(combo_is(combo_at(&a, 0, 0, 0), flat));
    assert_true(combo_is(combo_at(&a, 0, 1, 0), flat));
    assert_true(combo_is(combo_at(&a, 0, 2, 1), flat));
    assert_true(combo_is(combo_at(&a, 0, 3, 1), flat));
    splat_analysis_free(&a);

    /* Three texels away is out of the filters' reach. */
    f->desc.destruction_size[0] = f->desc.destruction_size[1] = 5;
    f->desc.destruction_cell = 5;          /* x 40..45 */
    analyze(f, &a);
    assert_true(combo_is(combo_at(&a, 0, 3, 0), flat));
    assert_true(combo_is(combo_at(&a, 0, 2, 0), reached));
    splat_analysis_free(&a);
    fixture_free(f);
}

/* ---- determinism and ids ------------------------------------------------- */

static void test_deterministic_first_occurrence_ids(void **state)
{
    fixture *f = snow_scene();
    splat_analysis a, b;
    analyze(f, &a);
    analyze(f, &b);
    assert_int_equal(a.ncombos, b.ncombos);
    assert_int_equal(a.nlevels, b.nlevels);
    for (int L = 0; L < a.nlevels; L++)
        assert_memory_equal(a.levels[L].ids, b.levels[L].ids,
                            sizeof(uint16_t) * a.levels[L].width * a.levels[L].height);
    for (int i = 0; i < a.ncombos; i++) {
        assert_int_equal(a.combos[i].nmaterials, b.combos[i].nmaterials);
        assert_memory_equal(a.combos[i].materials, b.combos[i].materials,
                            sizeof(int) * a.combos[i].nmaterials);
    }
    /* Ids appear in order of first occurrence in level 0, row-major; the
     * coarse levels name only those (or no combination). */
    int next = 0;
    const splat_level *l0 = &a.levels[0];
    for (int i = 0; i < l0->width * l0->height; i++) {
        assert_true(l0->ids[i] <= next);
        if (l0->ids[i] == next) next++;
    }
    assert_int_equal(next, a.ncombos);
    for (int L = 1; L < a.nlevels; L++)
        for (int i = 0; i < a.levels[L].width * a.levels[L].height; i++)
            assert_true(a.levels[L].ids[i] < a.ncombos ||
                        a.levels[L].ids[i] == SPLAT_COMBO_UBER);
    /* All distinct. */
    for (int i = 0; i < a.ncombos; i++)
        for (int j = 0; j < i; j++)
            assert_false(a.combos[i].nmaterials == a.combos[j].nmaterials &&
                         memcmp(a.combos[i].materials, a.combos[j].materials,
                                sizeof(int) * a.combos[i].nmaterials) == 0);

    char *text = NULL;
    size_t len = 0;
    FILE *out = open_memstream(&text, &len);
    assert_non_null(out);
    splat_analysis_report(&f->s, &a, out);
    fclose(out);
    assert_non_null(strstr(text, "combinations: 3 in leaf cells"));
    assert_non_null(strstr(text, "naive all subsets: 4"));
    assert_non_null(strstr(text, "largest combination: 3 materials"));
    free(text);
    splat_analysis_free(&a);
    splat_analysis_free(&b);
    fixture_free(f);
}

/* ---- randomised soundness ------------------------------------------------ */

static uint64_t rng = 0x2545f4914f6cdd1dull;
static uint32_t rnd(void) { return points_rnd(&rng); }
static double rnd01(void) { return points_rnd01(&rng); }

/* At random points of every cell, the materials whose CPU-reference mask
 * makes them visible (top down: w > 0 until the first mask of 1) are all
 * in the cell's combination. */
static void test_random_points_inside_cell_combination(void **state)
{
    const char *names[] = { "grass", "dirt", "field", "rock", "snow" };
    fixture *f = fixture_new(96, 64, 8, 5, names);
    splat_terrain *t = &f->s.terrain;
    t->size[0] = 192;                      /* non-square texels: 2 m x 1 m */
    f->desc.size[0] = 192;
    for (int z = 0; z < 64; z++)
        for (int x = 0; x < 96; x++) {
            double v = 0.35 + 0.25 * sin(x * 0.11) * cos(z * 0.13) + 0.04 * rnd01();
            if (x > 60 && x < 64) v += 0.3;            /* cliffs */
            set_texel(f, x, z, (uint16_t)(fmin(fmax(v, 0), 1) * 65535));
        }
    uint8_t *px = fixture_painted(f, "fields");
    for (int i = 0; i < 30; i++) {                     /* painted blobs */
        int cx = (int)(rnd() % 96), cz = (int)(rnd() % 64);
        for (int dz = -2; dz <= 2; dz++)
            for (int dx = -2; dx <= 2; dx++)
                if (cx + dx >= 0 && cx + dx < 96 && cz + dz >= 0 && cz + dz < 64)
                    px[(cz + dz) * 96 + cx + dx] = (uint8_t)(255 - 40 * (abs(dx) + abs(dz)));
    }
    ir *ir = &f->s.ir;
    ir_ref slope = ir_input(ir, IR_IN_SLOPE), height = ir_input(ir, IR_IN_HEIGHT);
    set_mask(f, "dirt", ramp(ir, slope, 0.02, 0.05));
    set_mask(f, "field", ir_op2(ir, IR_OP_MUL, ir_painted_ref(ir, 0),
                                ramp(ir, height, 50, 20)));   /* falls with height */
    ir_ref nx = ir_swizzle(ir, ir_input(ir, IR_IN_NORMAL), "x");
    set_mask(f, "rock", ir_op2(ir, IR_OP_STEP, ir_constf(ir, 0.2), nx));
    set_mask(f, "snow", ramp(ir, height, 55, 60));
    ir_ref masks[5];
    for (int m = 1; m < 5; m++) {
        char root[64];
        snprintf(root, sizeof root, "%s.mask", names[m]);
        masks[m] = ir_find_root(ir, root);
    }
    splat_analysis a;
    analyze(f, &a);
    assert_true(a.ncombos > 3);                /* the scene is not trivial */
    int dropped = 0;                           /* materials a cell left out */
    for (int cz = 0; cz < a.cells_z; cz++)
        for (int cx = 0; cx < a.cells_x; cx++) {
            const splat_combo *c = combo_at(&a, 0, cx, cz);
            dropped += 5 - c->nmaterials;
            for (int s = 0; s < 60; s++) {
                double u = (cx * 8 + rnd01() * 8) / 96, v = (cz * 8 + rnd01() * 8) / 64;
                ir_env env;
                points_env(t, u, v, &env);
                double p = points_raster_bilinear(px, 96, 64, u, v);
                env.painted = &p;
                double T = 1;
                for (int m = 4; m >= 0 && T > 0; m--) {
                    double mask[4] = { 1 };
                    if (m > 0) ir_eval(ir, masks[m], &env, mask);
                    double w = T * mask[0];
                    if (w > 0) assert_true(combo_has(c, m));
                    T -= w;
                }
            }
        }
    assert_true(dropped > 0);                  /* and the analysis prunes */
    splat_analysis_free(&a);
    /* leaf-only combinations and every merge bound, on a scene with some */
    check_all_bounds(f, 6);
    fixture_free(f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_thin_slope_band_kept),
        cmocka_unit_test(test_single_painted_texel_kept),
        cmocka_unit_test(test_opaque_upper_drops_lower),
        cmocka_unit_test(test_quadtree_union),
        cmocka_unit_test(test_coarse_union_not_compiled),
        cmocka_unit_test(test_destruction_area),
        cmocka_unit_test(test_deterministic_first_occurrence_ids),
        cmocka_unit_test(test_random_points_inside_cell_combination),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
