/* test_scene.c — loading scenes (compiler/scene.c) and analysing real scene
 * files.  Run from the repository root (CTest does).
 *
 * Error fixtures: every tests/scene/bad_*.sg opens with
 *     # error: LINE:COL ID TEXT
 * and loading it must fail with its first error of id SG_E_<ID> at that
 * line and column of the fixture itself (scene errors carry the scene
 * file's locations), its message containing TEXT, and the scene freed. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <stb_image.h>

#include "points.h"
#include "scene.h"

static const char *const error_names[] = {
#define X(id, fmt) #id,
    SG_ERRORS(X)
#undef X
};

static int cmp_str(const void *a, const void *b)
{
    return strcmp(*(const char *const *)a, *(const char *const *)b);
}

static void check_error_fixture(const char *path)
{
    FILE *f = fopen(path, "r");
    assert_non_null(f);
    char first[256] = "";
    assert_non_null(fgets(first, sizeof first, f));
    fclose(f);
    int line = 0, col = 0, used = 0;
    char id[64] = "";
    if (sscanf(first, "# error: %d:%d %63s %n", &line, &col, id, &used) != 3) {
        print_error("%s: first line must be '# error: LINE:COL ID TEXT'\n", path);
        fail();
    }
    char *text = first + used;
    text[strcspn(text, "\n")] = 0;

    sg_diags d;
    sg_diags_init(&d);
    splat_scene s;
    bool ok = splat_scene_load(&s, path, NULL, &d);
    if (ok || d.nerrors == 0) {
        print_error("%s: loaded without errors\n", path);
        fail();
    }
    const sg_diag *e = NULL;
    for (int i = 0; i < d.n && !e; i++)
        if (d.items[i].severity == SG_ERROR) e = &d.items[i];
    assert_non_null(e);
    if (strcmp(e->loc.file, path) != 0 || e->loc.line != line || e->loc.col != col ||
        strcmp(error_names[e->id], id) != 0 || !strstr(e->msg, text)) {
        print_error("%s: want %d:%d %s '%s'\n", path, line, col, id, text);
        sg_diags_print(&d, stderr);
        fail();
    }
    /* Left freed. */
    assert_null(s.prog);
    assert_null(s.terrain.texels);
    assert_int_equal(s.ir.nnodes, 0);
    sg_diags_free(&d);
}

static void test_error_fixtures(void **state)
{
    DIR *dir = opendir("tests/scene");
    assert_non_null(dir);
    char *names[64];
    int n = 0;
    struct dirent *ent;
    while ((ent = readdir(dir)) != NULL) {
        size_t len = strlen(ent->d_name);
        if (strncmp(ent->d_name, "bad_", 4) == 0 && len > 3 &&
            strcmp(ent->d_name + len - 3, ".sg") == 0) {
            assert_true(n < 64);
            names[n] = malloc(len + 16);
            snprintf(names[n], len + 16, "tests/scene/%s", ent->d_name);
            n++;
        }
    }
    closedir(dir);
    qsort(names, (size_t)n, sizeof *names, cmp_str);
    assert_true(n >= 10);
    for (int i = 0; i < n; i++) {
        check_error_fixture(names[i]);
        free(names[i]);
    }
}

/* Every compositor of the node library keeps the contract
 * (splat_compositor_check); the broken ones of bad_compositor_*.sg are
 * errors (test_error_fixtures). */
static void test_shipped_compositors(void **state)
{
    static const char *const files[] = {"nodes/compositors.sg", "nodes/compositors_extra.sg",
                                        "nodes/stochastic.sg", "nodes/height_softmax.sg"};
    static const char *const names[] = {"linear_alpha", "height_blend", "stochastic_select",
                                        "height_softmax"};
    const char *search[] = {".", NULL};
    for (int i = 0; i < 4; i++) {
        sg_diags d;
        sg_diags_init(&d);
        sg_program *p = sg_load(files[i], search, &d);
        assert_non_null(p);
        bool ok = splat_compositor_check(p, names[i], (sg_loc){files[i], 1, 1}, &d);
        if (!ok)
            sg_diags_print(&d, stderr);
        assert_true(ok);
        assert_int_equal(d.nerrors, 0);
        sg_free(p);
        sg_diags_free(&d);
    }
}

/* ---- soundness at points ------------------------------------------------- */

static uint64_t rng = 0x853c49e6748fea9bull;

static double raster_painted(void *user, int p, double u, double v)
{
    const splat_scene *s = user;
    bool across;
    int vs = p >= s->desc->npainted
                 ? splat_vector_find(s->desc, s->ir.painted[p].name, &across) : -1;
    if (vs >= 0) {   /* a spline or polygon (vector.c): as the shader reads it */
        double d = splat_vector_distance_grid(&s->vectors, vs, u * s->terrain.size[0],
                                              v * s->terrain.size[1]);
        return splat_vector_profile(&s->vectors, vs, d, across);
    }
    return points_raster_bilinear(s->painted[p], s->terrain.width, s->terrain.height, u, v);
}

/* At random points of every leaf cell (and random params and texture
 * content), every material the CPU reference makes visible (front to back:
 * w = T * mask > 0 until T reaches 0) is in the cell's combination; painted
 * values bilinear in the scene's rasters, vector shapes (colorado's roads)
 * from their grid as the shader reads them. */
static void check_points_sound(const splat_scene *s, const splat_analysis *a,
                               int samples)
{
    points_check_sound(s, a, samples, &rng, raster_painted, (void *)s);
}

static void load_ok(splat_scene *s, const char *path, const char *const *search)
{
    sg_diags d;
    sg_diags_init(&d);
    bool ok = splat_scene_load(s, path, search, &d);
    if (!ok) sg_diags_print(&d, stderr);
    assert_true(ok);
    assert_int_equal(d.nerrors, 0);
    sg_diags_free(&d);
}

/* ok.sg: the fields, rasters and lowered materials; then its analysis.
 * hf16.png rises 1000 per texel east with a jump of 30000 at x = 8;
 * mask.png is 255 on x < 8.  Cells are 4 texels wide. */
static void test_ok_scene(void **state)
{
    splat_scene s;
    const char *const search[] = { ".", NULL };
    load_ok(&s, "tests/scene/ok.sg", search);
    assert_int_equal(s.nmaterials, 3);
    assert_string_equal(s.desc->materials[2], "steep");
    assert_int_equal(s.terrain.width, 16);
    assert_int_equal(s.terrain.height, 16);
    assert_true(s.terrain.size[0] == 64 && s.terrain.size[1] == 32);
    assert_true(s.terrain.max_height == 50 && s.terrain.height_offset == -10);
    assert_int_equal(s.terrain.texels[3 * 16 + 9], 9 * 1000 + 3 * 10 + 30000);
    /* Painted: the scene's mask 0 is the IR's painted 0. */
    assert_int_equal(s.ir.npainted, 1);
    assert_string_equal(s.ir.painted[0].name, "west");
    assert_int_equal(s.painted[0][5 * 16 + 7], 255);
    assert_int_equal(s.painted[0][5 * 16 + 8], 0);
    /* Every material has all five outputs. */
    for (int m = 0; m < 3; m++)
        for (int o = 0; o < SG_OUT_COUNT; o++) {
            char root[128];
            snprintf(root, sizeof root, "%s.%s", s.desc->materials[m], sg_output_names[o]);
            assert_true(ir_ref_ok(ir_find_root(&s.ir, root)));
        }

    sg_diags d;
    sg_diags_init(&d);
    splat_analysis a;
    assert_true(splat_analyze(&s, &a, &d));
    assert_int_equal(a.cells_x, 4);
    assert_int_equal(a.cells_z, 4);
    /* Columns: 0 all painted (west_paint opaque, base dropped); 1 and 2
     * see the cliff and the mask's edge; 3 is bare ramp. */
    check_points_sound(&s, &a, 400);
    const int col_sizes[4] = { 1, 3, 3, 1 };
    const int col_top[4] = { 1, 2, 2, 0 };
    for (int z = 0; z < 4; z++)
        for (int x = 0; x < 4; x++) {
            const splat_combo *c = &a.combos[a.levels[0].ids[z * 4 + x]];
            assert_int_equal(c->nmaterials, col_sizes[x]);
            assert_int_equal(c->materials[0], col_top[x]);
        }
    splat_analysis_free(&a);
    sg_diags_free(&d);
    splat_scene_free(&s);
    assert_null(s.prog);
}

/* The raw R16 copy loads to the same texels as the PNG. */
static void test_raw_matches_png(void **state)
{
    splat_scene s;
    load_ok(&s, "tests/scene/ok_raw.sg", NULL);
    int w, h, c;
    stbi_us *png = stbi_load_16("tests/scene/hf16.png", &w, &h, &c, 1);
    assert_non_null(png);
    assert_int_equal(s.terrain.width, w);
    assert_int_equal(s.terrain.height, h);
    assert_memory_equal(s.terrain.texels, png, sizeof(uint16_t) * w * h);
    stbi_image_free(png);
    splat_scene_free(&s);
}

/* The quickstart: found from the repository root without search paths
 * (imports of graphs/ and nodes/ resolve through the project root). */
static void test_minimal_example(void **state)
{
    splat_scene s;
    load_ok(&s, "examples/minimal/scene.sg", NULL);
    assert_int_equal(s.nmaterials, 3);
    assert_int_equal(s.terrain.width, 257);
    assert_int_equal(s.terrain.height, 257);
    assert_int_equal(s.desc->npainted, 1);
    sg_diags d;
    sg_diags_init(&d);
    splat_analysis a, b;
    assert_true(splat_analyze(&s, &a, &d));
    assert_true(splat_analyze(&s, &b, &d));
    assert_int_equal(a.cells_x, 9);
    assert_int_equal(a.nlevels, 5);
    /* Not every cell needs every material, and the same scene gives the
     * same ids. */
    assert_true(a.ncombos >= 2);
    int smallest = 3;
    for (int i = 0; i < a.ncombos; i++)
        if (a.combos[i].nmaterials < smallest) smallest = a.combos[i].nmaterials;
    assert_true(smallest < 3);
    check_points_sound(&s, &a, 300);
    assert_int_equal(a.ncombos, b.ncombos);
    for (int L = 0; L < a.nlevels; L++)
        assert_memory_equal(a.levels[L].ids, b.levels[L].ids,
                            sizeof(uint16_t) * a.levels[L].width * a.levels[L].height);
    splat_analysis_free(&a);
    splat_analysis_free(&b);
    sg_diags_free(&d);
    splat_scene_free(&s);
}

/* The 15-material example on the real DEM: sound at sample points. */
/* `materials =` twice: the second list replaces the first (fuzz_parse
 * found the locations' array written past its end here). */
static void test_materials_twice(void **state)
{
    (void)state;
    static const char text[] =
        "material a { out albedo = vec3(0.5) }\n"
        "material b { out albedo = vec3(0.25) }\n"
        "material c { out albedo = vec3(0.75) }\n"
        "scene s {\n"
        "    heightfield = \"hf16.png\"\n"
        "    materials = [a, b, c, a, b]\n"
        "    materials = [c, a]\n"
        "}\n";
    sg_diags d;
    sg_diags_init(&d);
    sg_program *p = sg_load_string("twice.sg", text, NULL, &d);
    assert_non_null(p);
    const sg_scene *sc = sg_program_scene(p);
    assert_non_null(sc);
    assert_int_equal(sc->nmaterials, 2);
    assert_string_equal(sc->materials[0], "c");
    assert_string_equal(sc->materials[1], "a");
    assert_int_equal(sc->material_locs[1].line, 7);
    sg_free(p);
    sg_diags_free(&d);
}

static void test_colorado_sound(void **state)
{
    splat_scene s;
    load_ok(&s, "examples/colorado/scene.sg", NULL);
    sg_diags d;
    sg_diags_init(&d);
    splat_analysis a;
    assert_true(splat_analyze(&s, &a, &d));
    assert_true(a.ncombos > 10);
    check_points_sound(&s, &a, 10);
    splat_analysis_free(&a);
    sg_diags_free(&d);
    splat_scene_free(&s);
}

/* colorado's roads are splines: at random points within 12 m of them
 * (the falloff's edge is 9 m), the material stack evaluated front to back
 * as in check_points_sound; every visible material, the road most of all,
 * must be in the point's leaf-cell combination. */
static void test_colorado_roads_sound(void **state)
{
    (void)state;
    splat_scene s;
    load_ok(&s, "examples/colorado/scene.sg", NULL);
    sg_diags d;
    sg_diags_init(&d);
    splat_analysis a;
    assert_true(splat_analyze(&s, &a, &d));
    const splat_vectors *vs = &s.vectors;
    assert_non_null(vs->words);
    int n = s.nmaterials, road = -1, seen = 0;
    ir_ref *masks = calloc((size_t)n, sizeof *masks);
    double *painted = calloc((size_t)s.ir.npainted + 1, sizeof *painted);
    assert_true(masks && painted);
    for (int m = 0; m < n; m++) {
        char root[256];
        snprintf(root, sizeof root, "%s.mask", s.desc->materials[m]);
        masks[m] = ir_find_root(&s.ir, root);
        if (!strcmp(s.desc->materials[m], "road")) road = m;
    }
    assert_true(road > 0);
    uint32_t nseg = vs->shape_first[s.desc->nvectors];
    const double W = s.terrain.size[0], H = s.terrain.size[1];
    for (int k = 0; k < 4000; k++) {
        /* a point of a random segment, pushed sideways */
        uint32_t seg = points_rnd(&rng) % nseg;
        size_t at = vs->nwords - (size_t)SPLAT_VEC_SEG * (nseg - seg);
        float f[4];
        memcpy(f, &vs->words[at], sizeof f);
        double t = points_rnd01(&rng);
        double x = f[0] + t * (f[2] - f[0]) + (points_rnd01(&rng) - 0.5) * 24;
        double z = f[1] + t * (f[3] - f[1]) + (points_rnd01(&rng) - 0.5) * 24;
        double u = x / W, v = z / H;
        if (!(u >= 0 && u < 1 && v >= 0 && v < 1)) continue;
        int T = a.cell_texels, cx = (int)(u * s.terrain.width) / T;
        int cz = (int)(v * s.terrain.height) / T;
        const splat_combo *c = &a.combos[a.levels[0].ids[cz * a.cells_x + cx]];
        ir_env env;
        points_env(&s.terrain, u, v, &env);
        env.view_distance = points_rnd01(&rng) * 2000;
        for (int p = 0; p < s.ir.npainted; p++)
            painted[p] = raster_painted(&s, p, u, v);
        env.painted = painted;
        env.sample = points_any_texture;
        double cover = 1;
        for (int m = n - 1; m >= 0 && cover > 0; m--) {
            double mask[4] = { 1 };
            if (m > 0) ir_eval(&s.ir, masks[m], &env, mask);
            double w = cover * mask[0];
            if (w > 0 && !points_combo_has(c, m)) {
                print_error("cell (%d, %d): '%s' visible (w = %g) at x %.2f z %.2f but not "
                            "in the combination\n", cx, cz, s.desc->materials[m], w, x, z);
                fail();
            }
            seen += m == road && w > 0;
            cover -= w;
        }
    }
    assert_true(seen > 1000);   /* the points did land on the roads */
    free(masks);
    free(painted);
    splat_analysis_free(&a);
    sg_diags_free(&d);
    splat_scene_free(&s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_error_fixtures),
        cmocka_unit_test(test_shipped_compositors),
        cmocka_unit_test(test_ok_scene),
        cmocka_unit_test(test_raw_matches_png),
        cmocka_unit_test(test_minimal_example),
        cmocka_unit_test(test_colorado_sound),
        cmocka_unit_test(test_colorado_roads_sound),
        cmocka_unit_test(test_materials_twice),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
