/* test_distance.c — distance classes (compiler/distance.c) and the pass
 * they run (compiler/opt_pin.c).
 *
 * opt_pin on a hand-built fade: pinned to 0 beyond the fade distance, kept
 * where the distance is not bounded.  On colorado's real graphs (rock's
 * parallax fades out at 300 m, graphs/rock.sg): the classes found for a
 * combination holding rock and for the über-shader, each cheaper than its
 * composite; soundness like the combination analysis' — at random points
 * whose view.distance lies in the class's interval (its ends included),
 * with random terrain inputs, view directions, params, painted values and
 * arbitrary texture content, every root of the class equals the same root
 * of the full composite in the double reference (ir_eval); and the check
 * can fail: nearer than the class's interval the two differ somewhere.
 * Every class variant's GLSL (fragment and compute) passes glslang and
 * spirv-val.  A mid class ([a, b], both ends finite) on a scene whose
 * detail fades in as well as out (tests/scene/distance_mid.sg).
 *
 * Runs from the repository root (CTest's working directory). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "glsl_check.h"
#include "points.h"
#include "scene.h"
#include "spv.h"

/* ---- opt_pin ------------------------------------------------------------- */

/* depth * saturate(1 - d / fade) * view.direction.x: parallax_offset's
 * shape (nodes/parallax.sg). */
static ir_ref fade(ir *ir)
{
    ir_ref d = ir_input(ir, IR_IN_VIEW_DISTANCE);
    ir_ref fr = ir_op2(ir, IR_OP_DIV, d, ir_constf(ir, 300.0));
    ir_ref fk = ir_op1(ir, IR_OP_SATURATE, ir_op2(ir, IR_OP_SUB, ir_constf(ir, 1.0), fr));
    ir_ref vx = ir_swizzle(ir, ir_input(ir, IR_IN_VIEW_DIRECTION), "x");
    return ir_op2(ir, IR_OP_MUL, ir_op2(ir, IR_OP_MUL, fk, ir_constf(ir, 0.5)), vx);
}

static void pin_region(ir *ir, double lo, double hi)
{
    ir_ienv env;
    memset(&env, 0, sizeof env);
    ir_ienv_domain(&env);
    env.view_distance = (ir_iv){lo, hi};
    opt_pin(ir, &env);
    ir_optimize(ir, NULL);
    assert_true(ir_validate(ir, stderr));
}

static void test_pin_fade(void **state)
{
    (void)state;
    ir ir;
    ir_init(&ir);
    ir_set_root(&ir, "r", fade(&ir));
    uint32_t before = ir.nnodes;
    pin_region(&ir, 301.0, INFINITY);   /* beyond the fade: 0 */
    ir_ref r = ir_find_root(&ir, "r");
    assert_int_equal(ir_get(&ir, r)->op, IR_OP_CONST);
    assert_true(ir_get(&ir, r)->val[0] == 0.0);
    assert_true(ir.nnodes < before);
    ir_free(&ir);

    ir_init(&ir);
    ir_set_root(&ir, "r", fade(&ir));
    before = ir.nnodes;
    ir_ienv any;
    memset(&any, 0, sizeof any);
    ir_ienv_domain(&any);
    assert_false(opt_pin(&ir, &any));       /* any distance: nothing */
    pin_region(&ir, 0.0, 299.0);            /* nearer: still varies */
    assert_int_not_equal(ir_get(&ir, ir_find_root(&ir, "r"))->op, IR_OP_CONST);
    assert_int_equal(ir.nnodes, before);
    ir_free(&ir);
}

/* ---- colorado's classes -------------------------------------------------- */

static const char *const search[] = {".", NULL};

typedef struct fixture {
    splat_scene  s;
    splat_layout L;
} fixture;

static int load(void **state, const char *scene)
{
    fixture *f = calloc(1, sizeof *f);
    sg_diags d;
    sg_diags_init(&d);
    bool ok = splat_scene_load(&f->s, scene, search, &d) &&
              splat_layout_from_scene(&f->L, &f->s, &d);
    sg_diags_print(&d, stderr);
    sg_diags_free(&d);
    assert_true(ok);
    *state = f;
    return 0;
}

static int setup(void **state) { return load(state, "examples/colorado/scene.sg"); }

static int setup_mid(void **state) { return load(state, "tests/scene/distance_mid.sg"); }

static int teardown(void **state)
{
    fixture *f = *state;
    splat_layout_free(&f->L);
    splat_scene_free(&f->s);
    free(f);
    return 0;
}

static int material(const fixture *f, const char *name)
{
    for (int k = 0; k < f->L.nmaterials; k++)
        if (strcmp(f->L.materials[k], name) == 0)
            return k;
    fail_msg("no material %s", name);
    return -1;
}

static void compose(fixture *f, const int *mats, int n, splat_composite *c)
{
    sg_diags d;
    sg_diags_init(&d);
    splat_compose_desc desc = {.materials = mats, .nmaterials = n};
    bool ok = splat_compose(&f->L, &desc, c, &d);
    sg_diags_print(&d, stderr);
    sg_diags_free(&d);
    assert_true(ok);
}

static void unit3(uint64_t *rng, double v[3], double ymin)
{
    double l;
    do {
        for (int k = 0; k < 3; k++)
            v[k] = 2 * points_rnd01(rng) - 1;
        l = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    } while (l < 0.1 || l > 1 || v[1] / l < ymin);
    for (int k = 0; k < 3; k++)
        v[k] /= l;
}

/* A random point of colorado's inputs with view.distance `dist`; params
 * and painted values (one per entry) random in their ranges. */
static void random_env(const fixture *f, const ir *ir, uint64_t *rng, double dist, ir_env *env,
                       double *params, double *painted)
{
    double u = points_rnd01(rng), v = points_rnd01(rng);
    points_env(&f->s.terrain, u, v, env);
    env->height += (points_rnd01(rng) - 0.5) * 200;   /* any shape (craters) */
    unit3(rng, env->normal, 0.05);
    env->slope = 1 - env->normal[1];
    unit3(rng, env->view_direction, -1);
    env->view_distance = dist;
    env->destruction = points_rnd01(rng) < 0.5 ? 0 : points_rnd01(rng);
    for (int i = 0; i < ir->nparams; i++)
        for (int c = 0; c < 4; c++) {
            const ir_param *p = &ir->params[i];
            params[4 * i + c] = p->lo == p->hi ? p->def[c]
                                               : p->lo + (p->hi - p->lo) * points_rnd01(rng);
        }
    for (int i = 0; i < ir->npainted; i++)
        painted[i] = points_rnd01(rng);
    env->params = params;
    env->painted = painted;
    env->sample = points_any_texture;
}

/* Params and painted masks of `cls` by name in `full` (DCE may have
 * dropped some of the class's), so both see the same point. */
static void remap(const ir *full, const ir *cls, const double *fp, const double *fpa,
                  double *cp, double *cpa)
{
    for (int i = 0; i < cls->nparams; i++)
        for (int j = 0; j < full->nparams; j++)
            if (strcmp(cls->params[i].name, full->params[j].name) == 0)
                memcpy(&cp[4 * i], &fp[4 * j], 4 * sizeof *cp);
    for (int i = 0; i < cls->npainted; i++)
        for (int j = 0; j < full->npainted; j++)
            if (strcmp(cls->painted[i].name, full->painted[j].name) == 0)
                cpa[i] = fpa[j];
}

/* Textures by file in points_any_texture: the class's texture indices
 * must name the same content as the full composite's. */
typedef struct tex_map { const ir *from, *to; } tex_map;
static void sample_mapped(void *user, int t, double u, double v, double rgba[4])
{
    const tex_map *m = user;
    int k = t;
    for (int j = 0; j < m->to->ntextures; j++)
        if (ir_texture_same(&m->from->textures[t], &m->to->textures[j])) {
            k = j;
            break;
        }
    points_any_texture(NULL, k, u, v, rgba);
}

/* Every root of `cls` against `full` at `n` points with view.distance in
 * [lo, hi] (its ends first); returns how many root values differed
 * (`report`: the first one on stderr). */
static int compare(const fixture *f, const splat_composite *full, const splat_composite *cls,
                   double lo, double hi, int n, bool report, uint64_t *rng)
{
    const ir *a = &full->ir, *b = &cls->ir;
    double *fp = calloc(4 * (size_t)a->nparams + 4, sizeof *fp);
    double *fpa = calloc((size_t)a->npainted + 1, sizeof *fpa);
    double *cp = calloc(4 * (size_t)b->nparams + 4, sizeof *cp);
    double *cpa = calloc((size_t)b->npainted + 1, sizeof *cpa);
    tex_map tm = {b, a};
    int differ = 0;
    for (int i = 0; i < n; i++) {
        /* the ends, then log-uniform over [lo, min(hi, 100 lo)] */
        double top = fmin(hi, 100 * fmax(lo, 1));
        double dist = i == 0 ? lo : i == 1 && isfinite(hi) ? hi
                    : lo > 0 ? lo * pow(top / lo, points_rnd01(rng))
                             : top * points_rnd01(rng);
        ir_env ea, eb;
        random_env(f, a, rng, dist, &ea, fp, fpa);
        eb = ea;
        remap(a, b, fp, fpa, cp, cpa);
        eb.params = cp;
        eb.painted = cpa;
        eb.sample = sample_mapped;
        eb.sample_user = &tm;
        for (int r = 0; r < b->nroots; r++) {
            ir_ref ra = ir_find_root(a, b->roots[r].name);
            assert_true(ir_ref_ok(ra));
            double va[4], vb[4];
            ir_eval(a, ra, &ea, va);
            ir_eval(b, b->roots[r].ref, &eb, vb);
            for (int c = 0; c < ir_type_width(ir_typeof(b, b->roots[r].ref)); c++)
                if (!(va[c] == vb[c] || (isnan(va[c]) && isnan(vb[c])))) {
                    if (report && differ == 0)
                        fprintf(stderr, "%s[%d] at distance %.17g: full %.17g, class %.17g\n",
                                b->roots[r].name, c, dist, va[c], vb[c]);
                    differ++;
                }
        }
    }
    free(fp);
    free(fpa);
    free(cp);
    free(cpa);
    return differ;
}

static void compiles(const splat_layout *L, const splat_composite *c, bool compute)
{
    ir_buf glsl = {0};
    splat_glsl_desc gd = {.title = "distance class", .no_mask_view = true, .compute = compute};
    splat_composite_glsl(L, c, &gd, &glsl);
    glsl_check_compiles(glsl.s, compute ? SPV_STAGE_COMPUTE : SPV_STAGE_FRAGMENT, "class");
    ir_buf_free(&glsl);
}

/* The composite of `mats` into *full and its classes into *v; how many. */
static int classes_of(fixture *f, const int *mats, int n, splat_composite *full,
                      splat_dclass **v)
{
    compose(f, mats, n, full);
    sg_diags d;
    sg_diags_init(&d);
    int nc = splat_distance_classes(&f->L, full, v, &d);
    assert_int_equal(d.nerrors, 0);
    sg_diags_free(&d);
    return nc;
}

static void check_classes(fixture *f, const int *mats, int n, uint64_t seed, bool glsl)
{
    splat_composite full;
    splat_dclass *v;
    int nc = classes_of(f, mats, n, &full, &v);
    assert_true(nc >= 1);
    double cost = splat_composite_cost(&full);
    bool fade_class = false;
    uint64_t rng = seed;
    for (int k = 0; k < nc; k++) {
        assert_true(v[k].cost < cost);
        assert_true(v[k].lo <= v[k].hi);
        assert_true(ir_validate(&v[k].comp.ir, stderr));
        assert_int_equal(v[k].comp.nlayers, full.nlayers);
        /* rock's fade (graphs/rock.sg: 300 m), found to 1e-4 */
        fade_class |= v[k].lo >= 300.0 && v[k].lo <= 300.0 * 1.001 && isinf(v[k].hi);
        assert_int_equal(compare(f, &full, &v[k].comp, v[k].lo, v[k].hi, 400, true, &rng), 0);
        if (v[k].lo > 0)   /* the check can fail: nearer, parallax shifts the uv */
            assert_true(compare(f, &full, &v[k].comp, 0.05 * v[k].lo, 0.5 * v[k].lo, 200,
                                false, &rng) > 0);
        if (glsl) {
            compiles(&f->L, &v[k].comp, false);
            compiles(&f->L, &v[k].comp, true);
        }
    }
    assert_true(fade_class);
    splat_dclasses_free(v, nc);
    splat_composite_free(&full);
}

static void test_colorado_rock(void **state)
{
    fixture *f = *state;
    int mats[] = {material(f, "rock"), material(f, "mountain"), material(f, "grassland")};
    check_classes(f, mats, 3, 0x9e3779b97f4a7c15ull, true);
}

/* The über-shader's stack without grassland: since its far tiling is
 * hex-tiled and faded by distance (issue 31), no class of the full
 * 15-layer stack saves SPLAT_DCLASS_MIN_SAVING of it (measured: none is
 * kept; the combinations keep theirs, 57 on colorado); the other 14
 * layers keep the classes this checks. */
static void test_colorado_uber(void **state)
{
    fixture *f = *state;
    static const char *const filtered[] = { "grassland" };
    int n = f->L.nmaterials, m = 0;
    int *all = calloc((size_t)n, sizeof *all);
    for (int k = n - 1; k >= 0; k--) {
        bool skip = false;
        for (size_t j = 0; j < sizeof filtered / sizeof *filtered; j++)
            skip |= strcmp(f->L.materials[k], filtered[j]) == 0;
        if (!skip)
            all[m++] = k;
    }
    assert_true(m == n - 1);
    check_classes(f, all, m, 0x2545f4914f6cdd1dull, false);
    free(all);
}

/* near / mid / far (tests/scene/distance_mid.sg): detail fading out by
 * 300 m and detail fading in from 1 km give a mid class [300, 1000] with
 * both pinned, cheaper than every other class holding its interval,
 * equal to the composite inside it and not outside it on either side. */
static void test_mid_class(void **state)
{
    fixture *f = *state;
    int mats[] = {material(f, "fades")};
    splat_composite full;
    splat_dclass *v;
    int nc = classes_of(f, mats, 1, &full, &v);
    int mid = -1;
    for (int k = 0; k < nc; k++)
        if (fabs(v[k].lo - 300.0) < 0.1 && fabs(v[k].hi - 1000.0) < 0.1)
            mid = k;
    assert_true(mid >= 0);
    for (int k = 0; k < nc; k++)
        if (k != mid && v[k].lo <= v[mid].lo && v[mid].hi <= v[k].hi)
            assert_true(v[mid].cost < v[k].cost);
    assert_true(v[mid].cost < splat_composite_cost(&full));
    uint64_t rng = 0x6a09e667f3bcc909ull;
    assert_int_equal(compare(f, &full, &v[mid].comp, v[mid].lo, v[mid].hi, 400, true, &rng), 0);
    assert_true(compare(f, &full, &v[mid].comp, 0.05 * v[mid].lo, 0.5 * v[mid].lo, 200, false,
                        &rng) > 0);
    assert_true(compare(f, &full, &v[mid].comp, 1.5 * v[mid].hi, 3.0 * v[mid].hi, 200, false,
                        &rng) > 0);
    compiles(&f->L, &v[mid].comp, false);
    compiles(&f->L, &v[mid].comp, true);
    splat_dclasses_free(v, nc);
    splat_composite_free(&full);
}

/* A composite that never reads view.distance has no classes. */
static void test_no_distance(void **state)
{
    fixture *f = *state;
    int mats[] = {material(f, "grassland")};
    splat_composite c;
    compose(f, mats, 1, &c);
    splat_dclass *v = (splat_dclass *)&c;   /* overwritten with NULL */
    sg_diags d;
    sg_diags_init(&d);
    assert_int_equal(splat_distance_classes(&f->L, &c, &v, &d), 0);
    assert_null(v);
    sg_diags_free(&d);
    splat_composite_free(&c);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_pin_fade),
        cmocka_unit_test_setup_teardown(test_colorado_rock, setup, teardown),
        cmocka_unit_test_setup_teardown(test_colorado_uber, setup, teardown),
        cmocka_unit_test_setup_teardown(test_no_distance, setup, teardown),
        cmocka_unit_test_setup_teardown(test_mid_class, setup_mid, teardown),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
