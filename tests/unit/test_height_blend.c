/* test_height_blend.c — the normalised compositor height_softmax
 * (nodes/height_softmax.sg, compiler/DESIGN.md §6.2): the composite equals a
 * double-precision reference written out here at random points; it keeps
 * the soundness contract the analysis relies on (an absent layer adds
 * nothing, an opaque one hides every layer below: the composite equals the
 * one without them, the combinations the analysis builds); the contract
 * check rejects a normalised compositor whose blend is not 0 where m = 0;
 * every GLSL variant passes glslang and spirv-val, with the layer branches
 * and the final division in it. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "compose.h"
#include "glsl_check.h"
#include "spv.h"

/* Four materials: masks and heights are ramps of uv and position with
 * clamped plateaus (so m = 0 and m = 1 both occur over areas), each with
 * its own albedo and roughness. */
static const char GRAPH[] =
    "import \"nodes/height_softmax.sg\"\n"
    "import \"nodes/compositors.sg\"\n"
    "material base {\n"
    "    node h : mul { a = terrain.uv.y, b = 0.6 }\n"
    "    out albedo = vec3(0.4, 0.3, 0.2)\n"
    "    out roughness = 0.9\n"
    "    out height = h.out\n"
    "}\n"
    "material sand {\n"
    "    node k : mul { a = terrain.uv.x, b = 3.0 }\n"
    "    node m : saturate { x = k.out }\n"
    "    node f : fract { x = terrain.position.x }\n"
    "    out mask = m.out\n"
    "    out albedo = vec3(0.8, 0.7, 0.5)\n"
    "    out roughness = 0.7\n"
    "    out height = f.out\n"
    "}\n"
    "material rock {\n"
    "    node k : mul { a = terrain.uv.y, b = 2.5 }\n"
    "    node o : sub { a = k.out, b = 0.7 }\n"
    "    node m : saturate { x = o.out }\n"
    "    node f : fract { x = terrain.position.z }\n"
    "    node g : mul { a = f.out, b = 1.4 }\n"
    "    out mask = m.out\n"
    "    out albedo = vec3(0.5, 0.5, 0.55)\n"
    "    out roughness = 0.5\n"
    "    out height = g.out\n"
    "}\n"
    "material moss {\n"
    "    node s : add { a = terrain.uv.x, b = terrain.uv.y }\n"
    "    node k : mul { a = s.out, b = 2.0 }\n"
    "    node o : sub { a = k.out, b = 2.2 }\n"
    "    node m : saturate { x = o.out }\n"
    "    out mask = m.out\n"
    "    out albedo = vec3(0.2, 0.5, 0.1)\n"
    "    out roughness = 0.6\n"
    "    out height = 0.35\n"
    "}\n"
    /* broken: its blend ignores the mask, so an absent layer would add */
    "shader leaky {\n"
    "    in float T\n"
    "    in float m\n"
    "    in float h = 0.5\n"
    "    node w : mul { a = T, b = m }\n"
    "    node t : sub { a = T, b = w.out }\n"
    "    node b : mul { a = T, b = h }\n"
    "    out float weight = w.out\n"
    "    out float T_next = t.out\n"
    "    out float blend = b.out\n"
    "}\n";

enum { BASE, SAND, ROCK, MOSS, NMAT };
static const char *const names[NMAT] = {"base", "sand", "rock", "moss"};
static const char *const search[] = {".", NULL};

typedef struct fixture {
    sg_program  *p;
    ir           src;
    splat_layout L;
} fixture;

static int setup(void **state)
{
    fixture *f = calloc(1, sizeof *f);
    sg_diags d;
    sg_diags_init(&d);
    f->p = sg_load_string("test.sg", GRAPH, search, &d);
    assert_non_null(f->p);
    ir_init(&f->src);
    for (int i = 0; i < NMAT; i++)
        assert_true(sg_lower_material(f->p, names[i], &f->src, &d));
    sg_diags_print(&d, stderr);
    assert_int_equal(d.nerrors, 0);
    assert_true(splat_layout_init(&f->L, &f->src, f->p, "height_softmax", names, NMAT,
                                  NULL, 0, &d));
    sg_diags_free(&d);
    *state = f;
    return 0;
}

static int teardown(void **state)
{
    fixture *f = *state;
    splat_layout_free(&f->L);
    ir_free(&f->src);
    sg_free(f->p);
    free(f);
    return 0;
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

static void eval_root(const ir *ir, const char *root, const ir_env *e, double out[4])
{
    ir_ref r = ir_find_root(ir, root);
    assert_true(ir_ref_ok(r));
    ir_eval(ir, r, e, out);
}

static double rnd(double lo, double hi)
{
    return lo + (hi - lo) * ((double)rand() / RAND_MAX);
}

static ir_env random_env(void)
{
    ir_env e;
    memset(&e, 0, sizeof e);
    e.normal[1] = 1;
    e.uv[0] = rnd(0, 1);
    e.uv[1] = rnd(0, 1);
    e.position[0] = rnd(-50, 50);
    e.position[1] = rnd(0, 100);
    e.position[2] = rnd(-50, 50);
    e.view_distance = rnd(0, 500);
    return e;
}

/* The reference, from each material's own mask and surface (evaluated on
 * the scene's ir, not the composite's), in double:
 *   w_j = T_j m_j (bottom m = 1), T_j+1 = T_j - w_j,
 *   b_j = w_j 2^((saturate(h_j) - 1) / depth),  S = sum b_j s_j / sum b_j */
static void reference(const fixture *f, const int *mats, int n, const ir_env *e,
                      double depth, int o, double out[4])
{
    double T = 1, sum = 0, acc[4] = {0, 0, 0, 0};
    for (int j = 0; j < n; j++) {
        char root[64];
        double m[4], h[4], s[4];
        snprintf(root, sizeof root, "%s.mask", names[mats[j]]);
        eval_root(&f->src, root, e, m);
        snprintf(root, sizeof root, "%s.height", names[mats[j]]);
        eval_root(&f->src, root, e, h);
        snprintf(root, sizeof root, "%s.%s", names[mats[j]], sg_output_names[o]);
        eval_root(&f->src, root, e, s);
        double mj = j == n - 1 ? 1 : fmin(1, fmax(0, m[0]));
        double w = T * mj;
        T -= w;
        double b = w * exp2((fmin(1, fmax(0, h[0])) - 1) / fmax(depth, 1.0 / 64));
        sum += b;
        for (int k = 0; k < 4; k++)
            acc[k] += b * s[k];
    }
    for (int k = 0; k < 4; k++)
        out[k] = acc[k] / sum;
}

static const int stack[] = {MOSS, ROCK, SAND, BASE};

static void test_equals_reference(void **state)
{
    fixture *f = *state;
    splat_composite c;
    compose(f, stack, 4, &c);
    srand(31);
    int mixed = 0;      /* points where two layers share with unequal heights */
    for (int i = 0; i < 3000; i++) {
        ir_env e = random_env();
        for (int o = SG_OUT_ALBEDO; o < SG_OUT_COUNT; o++) {
            if (o == SG_OUT_NORMAL)
                continue;   /* the terrain normal for all: a sum of equal vectors */
            double want[4], got[4];
            reference(f, stack, 4, &e, 0.05, o, want);
            char root[64];
            snprintf(root, sizeof root, "composite.%s", sg_output_names[o]);
            eval_root(&c.ir, root, &e, got);
            int w = o == SG_OUT_ALBEDO ? 3 : 1;
            for (int k = 0; k < w; k++)
                if (!(fabs(got[k] - want[k]) <= 1e-12 * fmax(1, fabs(want[k]))))
                    fail_msg("point %d %s[%d]: composite %.17g, reference %.17g", i,
                             sg_output_names[o], k, got[k], want[k]);
        }
        /* the normalised share differs from the alpha weight where the
         * heights differ: the reference is not linear_alpha in disguise */
        double a[4], lin[4];
        reference(f, stack, 4, &e, 0.05, SG_OUT_ROUGHNESS, a);
        reference(f, stack, 4, &e, 1e9, SG_OUT_ROUGHNESS, lin);
        mixed += fabs(a[0] - lin[0]) > 0.02;
    }
    assert_true(mixed > 300);
    splat_composite_free(&c);
}

/* depth -> infinity is linear_alpha; depth small selects the highest of the
 * present layers (Billingsley 2009 §2.2), by hand at one point. */
static void test_limits(void **state)
{
    fixture *f = *state;
    ir_env e;
    memset(&e, 0, sizeof e);
    e.normal[1] = 1;
    /* sand m = 0.6, rock m = saturate(2.5 * 0.4 - 0.7) = 0.3, moss m = 0;
     * heights: sand fract(3.9) = 0.9, rock 1.4 * 0.25 = 0.35, base 0.24 */
    e.uv[0] = 0.2;
    e.uv[1] = 0.4;
    e.position[0] = 3.9;
    e.position[2] = 0.25;
    double big[4], small[4];
    reference(f, stack, 4, &e, 1e9, SG_OUT_ROUGHNESS, big);
    /* alpha: rock 0.3, sand 0.7 * 0.6 = 0.42, base 0.28 */
    assert_true(fabs(big[0] - (0.3 * 0.5 + 0.42 * 0.7 + 0.28 * 0.9)) < 1e-6);
    reference(f, stack, 4, &e, 1.0 / 64, SG_OUT_ROUGHNESS, small);
    assert_true(fabs(small[0] - 0.7) < 1e-6);     /* sand, the highest, wins */
    /* and the graph's depth port is what the reference uses */
    splat_composite c;
    compose(f, stack, 4, &c);
    double got[4];
    eval_root(&c.ir, "composite.roughness", &e, got);
    double want[4];
    reference(f, stack, 4, &e, 0.05, SG_OUT_ROUGHNESS, want);
    assert_true(fabs(got[0] - want[0]) < 1e-12);
    assert_true(got[0] > 0.64 && got[0] < 0.7);   /* mostly sand */
    splat_composite_free(&c);
}

/* The soundness contract as the analysis uses it: where a layer's mask is
 * 0 the composite equals the one without that layer; where it is 1, the
 * one that ends at it (the analysis's combination for such a cell). */
static void test_contract(void **state)
{
    fixture *f = *state;
    sg_diags d;
    sg_diags_init(&d);
    assert_true(splat_compositor_check(f->p, "height_softmax", (sg_loc){"t", 1, 1}, &d));
    assert_true(splat_compositor_normalised(f->p, "height_softmax"));
    assert_false(splat_compositor_normalised(f->p, "linear_alpha"));
    assert_false(splat_compositor_normalised(f->p, NULL));
    /* a blend that is not 0 where m = 0 is refused, naming the port */
    assert_false(splat_compositor_check(f->p, "leaky", (sg_loc){"t", 1, 1}, &d));
    assert_int_equal(d.nerrors, 1);
    assert_int_equal(d.items[0].id, SG_E_COMPOSITOR_CONTRACT);
    assert_non_null(strstr(d.items[0].msg, "blend"));
    sg_diags_free(&d);

    splat_composite full, no_moss, rock_down, rock_alone;
    compose(f, stack, 4, &full);
    static const int s1[] = {ROCK, SAND, BASE};
    static const int s2[] = {MOSS, ROCK};
    static const int s3[] = {ROCK};
    compose(f, s1, 3, &no_moss);
    compose(f, s2, 2, &rock_down);
    compose(f, s3, 1, &rock_alone);
    srand(7);
    int absent = 0, opaque = 0, alone = 0;
    for (int i = 0; i < 4000; i++) {
        ir_env e = random_env();
        double mm[4], mr[4];
        eval_root(&f->src, "moss.mask", &e, mm);
        eval_root(&f->src, "rock.mask", &e, mr);
        const splat_composite *other = NULL;
        if (mm[0] <= 0 && mr[0] >= 1) {
            other = &rock_alone;
            alone++;
        } else if (mm[0] <= 0) {
            other = &no_moss;
            absent++;
        } else if (mr[0] >= 1) {
            other = &rock_down;
            opaque++;
        } else {
            continue;
        }
        for (int o = SG_OUT_ALBEDO; o < SG_OUT_COUNT; o++) {
            char root[64];
            snprintf(root, sizeof root, "composite.%s", sg_output_names[o]);
            double a[4], b[4];
            eval_root(&full.ir, root, &e, a);
            eval_root(&other->ir, root, &e, b);
            for (int k = 0; k < 4; k++)
                if (!(fabs(a[k] - b[k]) <= 1e-12 * fmax(1, fabs(a[k]))))
                    fail_msg("point %d %s[%d]: full %.17g, combination %.17g", i,
                             sg_output_names[o], k, a[k], b[k]);
        }
    }
    assert_true(absent > 200 && opaque > 100 && alone > 50);
    splat_composite_free(&full);
    splat_composite_free(&no_moss);
    splat_composite_free(&rock_down);
    splat_composite_free(&rock_alone);
}

static int count(const char *s, const char *what)
{
    int n = 0;
    for (const char *p = s; (p = strstr(p, what)); p += strlen(what))
        n++;
    return n;
}

/* Every variant compiles; each layer keeps its surface branch (the early
 * exit past covered layers stays), every layer adds to s_wsum, and the sums
 * are divided once before splat_finish. */
static void test_glsl(void **state)
{
    fixture *f = *state;
    splat_composite c;
    compose(f, stack, 4, &c);
    int ug_slot[NMAT] = {-1, 0, -1, 1};
    struct { splat_glsl_desc d; spv_stage st; const char *name; } v[] = {
        {{.title = "forward"}, SPV_STAGE_FRAGMENT, "forward"},
        {{.title = "flat", .flat = true}, SPV_STAGE_FRAGMENT, "flat"},
        {{.title = "compute", .compute = true}, SPV_STAGE_COMPUTE, "compute"},
        {{.title = "ug", .compute = true, .ug_slot = ug_slot}, SPV_STAGE_COMPUTE, "ug"},
    };
    for (size_t k = 0; k < sizeof v / sizeof v[0]; k++) {
        ir_buf b = {0};
        splat_composite_glsl(&f->L, &c, &v[k].d, &b);
        const char *body = strstr(b.s, "void main() {\n    ");
        if (!body)
            body = b.s;
        assert_int_equal(count(body, "s_wsum += "), 4);
        assert_int_equal(count(body, "s_albedo *= s_inv;"), 1);
        assert_true(strstr(body, "s_albedo *= s_inv;") < strstr(body, "splat_finish(s_albedo"));
        if (!v[k].d.flat)
            assert_int_equal(count(body, "splat_surface("), 4);
        if (v[k].d.ug_slot)
            assert_int_equal(count(body, "splat_ug_w[1] * s_inv"), 1);
        glsl_check_compiles(b.s, v[k].st, v[k].name);
        ir_buf_free(&b);
    }
    splat_composite_free(&c);

    /* linear_alpha's composite has none of it */
    splat_layout la;
    sg_diags d;
    sg_diags_init(&d);
    assert_true(splat_layout_init(&la, &f->src, f->p, "linear_alpha", names, NMAT, NULL, 0, &d));
    splat_compose_desc desc = {.materials = stack, .nmaterials = 4};
    assert_true(splat_compose(&la, &desc, &c, &d));
    ir_buf b = {0};
    splat_glsl_desc gd = {.title = "alpha"};
    splat_composite_glsl(&la, &c, &gd, &b);
    assert_null(strstr(b.s, "s_wsum"));
    assert_false(ir_ref_ok(ir_find_root(&c.ir, "composite.wsum")));
    ir_buf_free(&b);
    splat_composite_free(&c);
    splat_layout_free(&la);
    sg_diags_free(&d);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(test_equals_reference, setup, teardown),
        cmocka_unit_test_setup_teardown(test_limits, setup, teardown),
        cmocka_unit_test_setup_teardown(test_contract, setup, teardown),
        cmocka_unit_test_setup_teardown(test_glsl, setup, teardown),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
