/* test_lazy.c — lazy branches (compiler/compose.c "lazy branches",
 * compiler/DESIGN.md §6.1): a mix/select/mul operand side worth more than
 * SPLAT_LAZY_MIN_COST becomes a quad-uniform branch where its weight can
 * vanish over a plateau.
 *
 * - the rule's cases: which sides get a branch and which do not (no
 *   plateau, too cheap, --no-lazy), asserted on the emitted GLSL;
 * - random composites over mix/select/mul/add of texture taps and clamped
 *   weights: the GLSL passes glslang and spirv-val, holds one `lz` value
 *   per lazy side, and the double reference evaluated the lazy way (a side
 *   whose guard fails reads 0, as the branch leaves it) equals the eager
 *   evaluation at random points wherever the eager value is finite (to
 *   the reference mix's own rounding, 1e-14). */
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
#include "abi.h"
#include "scene.h"
#include "spv.h"

static ir_texture tex(const char *file)
{
    return (ir_texture){.file = (char *)file, .filter = IR_FILTER_LINEAR,
                        .mip = IR_FILTER_LINEAR, .wrap = IR_WRAP_REPEAT,
                        .srgb = false, .lo = 0, .hi = 1};
}

static void set_outputs(ir *ir, const char *name, ir_ref mask, ir_ref albedo,
                        ir_ref rough)
{
    ir_ref v[SG_OUT_COUNT] = {mask, albedo, ir_input(ir, IR_IN_NORMAL), rough,
                              ir_constf(ir, 0.5)};
    for (int o = 0; o < SG_OUT_COUNT; o++) {
        char root[64];
        snprintf(root, sizeof root, "%s.%s", name, sg_output_names[o]);
        ir_set_root(ir, root, v[o]);
    }
}

static unsigned rng_state;
static double rnd(double lo, double hi)
{
    rng_state = rng_state * 1103515245u + 12345u;
    return lo + (hi - lo) * ((rng_state >> 8) & 0xffffff) / (double)0xffffff;
}

/* A texture tap at uv * s (its uv arithmetic and the sample: cost > 16). */
static ir_ref tap(ir *s, int k, double scale)
{
    static const char *const files[] = {"a.png", "b.png", "c.png", "d.png"};
    ir_texture t = tex(files[k & 3]);
    ir_ref uv = ir_input(s, IR_IN_UV);
    ir_ref st = ir_op2(s, IR_OP_MUL, uv, ir_splat(s, ir_constf(s, scale), IR_T_VEC2));
    st = ir_op2(s, IR_OP_ADD, st, ir_splat(s, ir_constf(s, 0.25 * k), IR_T_VEC2));
    return ir_op2(s, IR_OP_SAMPLE, ir_texture_ref(s, ir_add_texture(s, &t)), st);
}

/* A weight with plateaus at 0 and 1: saturate(input * a + b). */
static ir_ref weight(ir *s)
{
    static const ir_input_kind ins[] = {IR_IN_HEIGHT, IR_IN_SLOPE};
    ir_ref x = ir_input(s, ins[(int)rnd(0, 1.999)]);
    if (ir_typeof(s, x) != IR_T_FLOAT)
        x = ir_swizzle(s, x, "y");
    return ir_op1(s, IR_OP_SATURATE,
                  ir_op2(s, IR_OP_ADD, ir_op2(s, IR_OP_MUL, x, ir_constf(s, rnd(-4, 4))),
                         ir_constf(s, rnd(-1, 1))));
}

/* A random vec4 expression over taps and weights. */
static ir_ref random_expr(ir *s, int depth)
{
    int pick = depth <= 0 ? 0 : (int)rnd(0, 5.999);
    switch (pick) {
    case 0:
    case 1:
        return tap(s, (int)rnd(0, 3.999), rnd(1, 20));
    case 2:
        return ir_op3(s, IR_OP_MIX, random_expr(s, depth - 1), random_expr(s, depth - 1),
                      ir_splat(s, weight(s), IR_T_VEC4));
    case 3:
        return ir_op3(s, IR_OP_SELECT,
                      ir_splat(s, ir_op2(s, IR_OP_LESS, weight(s), ir_constf(s, 0.5)),
                               IR_T_VEC4),
                      random_expr(s, depth - 1), random_expr(s, depth - 1));
    case 4:
        return ir_op2(s, IR_OP_MUL, ir_splat(s, weight(s), IR_T_VEC4),
                      random_expr(s, depth - 1));
    default:
        return ir_op2(s, IR_OP_ADD, random_expr(s, depth - 1), random_expr(s, depth - 1));
    }
}

typedef struct fixture {
    ir           src;
    splat_layout L;
} fixture;

static const char *const mat_names[] = {"base", "top"};

static void layout(fixture *f)
{
    sg_diags d;
    sg_diags_init(&d);
    bool ok = splat_layout_init(&f->L, &f->src, NULL, NULL, mat_names, 2, NULL, 0, &d);
    sg_diags_print(&d, stderr);
    sg_diags_free(&d);
    assert_true(ok);
}

static void fixture_free(fixture *f)
{
    splat_layout_free(&f->L);
    ir_free(&f->src);
}

static void compose2(fixture *f, splat_composite *c)
{
    static const int mats[] = {1, 0};
    sg_diags d;
    sg_diags_init(&d);
    splat_compose_desc desc = {.materials = mats, .nmaterials = 2};
    bool ok = splat_compose(&f->L, &desc, c, &d);
    sg_diags_print(&d, stderr);
    sg_diags_free(&d);
    assert_true(ok);
}

static char *glsl(fixture *f, const splat_composite *c, bool lazy, bool compute,
                  uint8_t *sides, int *nlazy)
{
    ir_buf b = {0};
    splat_glsl_desc gd = {.title = "lazy test", .no_lazy = !lazy, .compute = compute,
                          .lazy_sides = sides, .lazy_branches = nlazy, .no_mask_view = true};
    splat_composite_glsl(&f->L, c, &gd, &b);
    return b.s;
}

static void compiles(const char *g, bool compute)
{
    glsl_check_compiles(g, compute ? SPV_STAGE_COMPUTE : SPV_STAGE_FRAGMENT, "lazy");
}

static int count(const char *s, const char *what)
{
    int n = 0;
    for (const char *p = s; (p = strstr(p, what)); p += strlen(what))
        n++;
    return n;
}

/* The samples the counting variant adds up over the whole shader. */
static int samples_counted(const char *g)
{
    int n = 0;
    for (const char *p = g; (p = strstr(p, "splat_count_samples(")); p++)
        n += atoi(p + strlen("splat_count_samples("));
    return n;
}

/* ---- the cases ----------------------------------------------------------- */

static void test_cases(void **state)
{
    (void)state;
    fixture f;
    rng_state = 7;
    ir *s = &f.src;
    ir_init(s);
    ir_ref slope = ir_input(s, IR_IN_SLOPE);
    ir_ref w = ir_op1(s, IR_OP_SATURATE,
                      ir_op2(s, IR_OP_SUB, ir_op2(s, IR_OP_MUL, slope, ir_constf(s, 4.0)),
                             ir_constf(s, 1.0)));
    /* mix of two taps under a clamped weight: both sides lazy */
    ir_ref m = ir_op3(s, IR_OP_MIX, tap(s, 0, 3), tap(s, 1, 5), ir_splat(s, w, IR_T_VEC4));
    /* mix under a sine: no plateau, no branch */
    ir_ref sn = ir_op1(s, IR_OP_SIN, ir_input(s, IR_IN_HEIGHT));
    ir_ref m2 = ir_op3(s, IR_OP_MIX, tap(s, 2, 7), tap(s, 3, 9), ir_splat(s, sn, IR_T_VEC4));
    ir_ref alb = ir_swizzle(s, ir_op2(s, IR_OP_ADD, m, m2), "rgb");
    /* a cheap side (height * 2 under the weight): under the threshold */
    ir_ref rough = ir_op2(s, IR_OP_MUL, w,
                          ir_op2(s, IR_OP_MUL, ir_input(s, IR_IN_HEIGHT), ir_constf(s, 2)));
    set_outputs(s, "top", ir_op1(s, IR_OP_SATURATE, ir_input(s, IR_IN_HEIGHT)), alb, rough);
    set_outputs(s, "base", ir_constf(s, 1), ir_swizzle(s, tap(s, 0, 1), "rgb"),
                ir_constf(s, 0.5));
    layout(&f);
    splat_composite c;
    compose2(&f, &c);

    uint8_t *sides = calloc(c.ir.nnodes, 1);
    int nlazy = 0;
    char *g = glsl(&f, &c, true, false, sides, &nlazy);
    compiles(g, false);
    assert_int_equal(nlazy, 2);
    /* + the layers' guards: the coverage guard and the top's surface */
    assert_int_equal(count(g, "if (splat_quad_any(v"), 2 + 1);
    assert_int_equal(count(g, "if (splat_surface(0u, v"), 1);   /* layer 0: the top */
    /* the two guards of the mix: t < 1 for a, t > 0 for b */
    assert_int_equal(count(g, " < 1.0)) {"), 1);
    assert_int_equal(count(g, " > 0.0)) {"), 1 + 2);
    int mixes = 0;
    for (uint32_t id = 1; id < c.ir.nnodes; id++)
        if (sides[id]) {   /* the clamped mix, both sides */
            assert_int_equal(c.ir.nodes[id].op, IR_OP_MIX);
            assert_int_equal(sides[id], 3);
            mixes++;
        }
    assert_int_equal(mixes, 1);
    free(g);
    /* the compute variant: the same branches, with explicit gradients */
    nlazy = 0;
    g = glsl(&f, &c, true, true, NULL, &nlazy);
    compiles(g, true);
    assert_int_equal(nlazy, 2);
    assert_true(count(g, "splat_texture_grad(u_tex") >= 4);
    free(g);
    /* --no-lazy: no lz values at all; each sample counted once either way */
    char *lz = glsl(&f, &c, true, false, NULL, NULL);
    nlazy = 0;
    g = glsl(&f, &c, false, false, NULL, &nlazy);
    compiles(g, false);
    assert_int_equal(nlazy, 0);
    assert_int_equal(count(g, "lz"), 0);
    assert_int_equal(samples_counted(g), 5);
    assert_int_equal(samples_counted(lz), 5);
    free(lz);
    free(g);
    free(sides);
    splat_composite_free(&c);
    fixture_free(&f);
}

/* ---- random composites: lazy equals eager ---------------------------------- */

static void sample_fn(void *user, int texture, double u, double v, double rgba[4])
{
    (void)user;
    for (int c = 0; c < 4; c++)
        rgba[c] = 0.5 + 0.5 * sin(5.0 * u + 3.0 * v + c + texture);
}

static bool any(const double *v, int w, int (*pred)(double))
{
    for (int c = 0; c < w; c++)
        if (pred(v[c]))
            return true;
    return false;
}
static int below1(double x) { return x < 1.0; }
static int above0(double x) { return x > 0.0; }
static int nonzero(double x) { return x != 0.0; }
static int zero(double x) { return x == 0.0; }

/* Whether operand a of node n counts at this point (the branch's guard). */
static bool guard(const ir *ir, const ir_node *n, int a, double (*vals)[4])
{
    ir_ref g = n->op == IR_OP_MIX ? n->arg[2] : n->op == IR_OP_SELECT ? n->arg[0]
                                                                     : n->arg[1 - a];
    int w = ir_type_width(ir_typeof(ir, g));
    if (n->op == IR_OP_MIX)
        return any(vals[g.id], w, a == 0 ? below1 : above0);
    if (n->op == IR_OP_SELECT)
        return any(vals[g.id], w, a == 1 ? nonzero : zero);
    return any(vals[g.id], w, nonzero);
}

static void test_random_equal_eager(void **state)
{
    (void)state;
    int graphs = 0, branches = 0, skipped = 0, compared = 0;
    for (unsigned seed = 1; seed <= 24; seed++) {
        rng_state = seed;
        fixture f;
        ir *s = &f.src;
        ir_init(s);
        ir_ref e = random_expr(s, 4);
        set_outputs(s, "top", weight(s), ir_swizzle(s, e, "rgb"), ir_swizzle(s, e, "w"));
        set_outputs(s, "base", ir_constf(s, 1), ir_swizzle(s, tap(s, 0, 1), "rgb"),
                    ir_constf(s, 0.5));
        layout(&f);
        splat_composite c;
        compose2(&f, &c);
        const ir *ir = &c.ir;
        uint8_t *sides = calloc(ir->nnodes, 1);
        int nlazy = 0;
        char *g = glsl(&f, &c, true, false, sides, &nlazy);
        compiles(g, false);
        int nsides = 0;
        for (uint32_t id = 1; id < ir->nnodes; id++)
            nsides += __builtin_popcount(sides[id]);
        assert_int_equal(nsides, nlazy);
        /* one `T lz<id>_<k> = T(0.0);` per lazy side */
        char *eager_g = glsl(&f, &c, false, false, NULL, NULL);
        assert_int_equal(count(g, "(0.0);\n") - count(eager_g, "(0.0);\n"), nlazy);
        assert_int_equal(count(g, "if (") - count(eager_g, "if ("), nlazy);
        free(eager_g);
        free(g);
        graphs++;
        branches += nlazy;

        double (*eager)[4] = calloc(ir->nnodes, sizeof *eager);
        double (*lazy)[4] = calloc(ir->nnodes, sizeof *lazy);
        for (int k = 0; k < 64; k++) {
            ir_env env = {0};
            env.height = rnd(-0.5, 1.5);
            env.normal[1] = rnd(0, 1);
            env.normal[0] = sqrt(1 - env.normal[1] * env.normal[1]);
            env.slope = 1 - env.normal[1];
            env.uv[0] = rnd(0, 1);
            env.uv[1] = rnd(0, 1);
            env.sample = sample_fn;
            for (uint32_t id = 1; id < ir->nnodes; id++)
                ir_eval_node(ir, id, &env, eager);
            for (uint32_t id = 1; id < ir->nnodes; id++) {
                const ir_node *n = &ir->nodes[id];
                for (int a = 0; a < n->nargs; a++)
                    if ((sides[id] >> a & 1) && !guard(ir, n, a, lazy)) {
                        memset(lazy[n->arg[a].id], 0, sizeof lazy[0]);   /* skipped */
                        skipped++;
                    }
                ir_eval_node(ir, id, &env, lazy);
            }
            for (int o = 1; o < SG_OUT_COUNT; o++) {
                char name[64];
                snprintf(name, sizeof name, "composite.%s", sg_output_names[o]);
                ir_ref r = ir_find_root(ir, name);
                for (int ch = 0; ch < ir_type_width(ir_typeof(ir, r)); ch++) {
                    if (!isfinite(eager[r.id][ch]))
                        continue;
                    /* the reference's mix is a + t (b - a), which at t = 1
                     * rounds a + (b - a) where the skipped form gives b
                     * exactly: a few ulps of the operands (values <= 4) */
                    if (fabs(lazy[r.id][ch] - eager[r.id][ch]) > 1e-14)
                        fail_msg("seed %u %s[%d]: lazy %.17g, eager %.17g", seed, name, ch,
                                 lazy[r.id][ch], eager[r.id][ch]);
                    compared++;
                }
            }
        }
        free(eager);
        free(lazy);
        free(sides);
        splat_composite_free(&c);
        fixture_free(&f);
    }
    fprintf(stderr, "lazy: %d graphs, %d branches, %d sides skipped, %d values equal\n",
            graphs, branches, skipped, compared);
    /* the test exercised the rule: branches made and taken both ways */
    assert_true(branches >= graphs);
    assert_true(skipped > 100);
    assert_true(compared > 1000);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_cases),
        cmocka_unit_test(test_random_equal_eager),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
