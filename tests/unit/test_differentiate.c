/* test_differentiate.c — the compiler's texture derivatives
 * (ir_differentiate.c, the op table's derivative rules) against central
 * finite differences of the double reference (ir_eval).
 *
 * The screen step: every input that moves (position, height, uv, view
 * distance and direction) moves along a random direction `dir` by s; the
 * others (normal, slope, destruction, params, painted masks) stay, as the
 * pass takes them.  The DINPUT leaves read eps * dir, so the IR's
 * derivative divided by eps is the derivative along s — up to SAMPLE's
 * rule, a finite difference over the eps step itself (error O(eps)).
 * Against it: (f(s + h) - f(s - h)) / 2h, with h and h / 2 combined by
 * Richardson extrapolation.  Where f is not smooth within h (floor, step,
 * select, hash noise) these and the quotient with h / 3 disagree, and where some value f
 * depends on exceeds 1e6 double rounding swamps them: those points are
 * skipped, the others must match (TOL_ALU, TOL_SAMPLE below), and the
 * tests assert that most points were compared and that many of those had
 * a derivative that is not zero.
 *
 * Graphs: random ones over every op (random_ir.h), and every shader of
 * nodes/ lowered with its vector and undefaulted inputs bound to moving
 * inputs.  Last, the pass itself: every SAMPLE becomes a SAMPLE_GRAD whose
 * gradients are ir_derivative's of its uv, values unchanged, and the
 * compute variant of random graphs and its counting variant compile
 * (glslang + spirv-val).
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <glob.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ir.h"
#include "random_ir.h"
#include "sg.h"
#include "shader.h"
#include "spv.h"

enum { GRAPHS = 1000, POINTS = 12 };
static const double EPS = 1e-7;   /* the DINPUT step                         */
static const double H = 1e-4;     /* the finite-difference step along dir    */
/* Relative error allowed where smooth (against the larger of the two
 * derivatives and 1e-4 max(1, |value|)).  Without samples the rules are
 * exact up to rounding; SAMPLE's rule is itself a finite difference over
 * the eps step: truncation eps |f''| and the rounding of uv + eps * dir
 * (uv up to 1000 in metres: 1e-13 / eps), compounded through nested
 * samples, stay below 1e-3. */
static const double TOL_ALU = 1e-6, TOL_SAMPLE = 1e-3;

/* What a run of checks found, for the assertions and the report. */
typedef struct tally {
    long   values;     /* components looked at                            */
    long   compared;   /* smooth there: compared                          */
    long   moving;     /* compared with a derivative that is not ~0       */
    double worst;      /* largest relative error, graphs without samples  */
    double worst_sample; /* the same, graphs with samples                 */
} tally;

/* The moving inputs at s along dir; the rest as in `base`. */
static ir_env at(const ir_env *base, const ir_env *dir, double s)
{
    ir_env e = *base;
    e.height += s * dir->height;
    e.view_distance += s * dir->view_distance;
    for (int c = 0; c < 3; c++) {
        e.position[c] += s * dir->position[c];
        e.view_direction[c] += s * dir->view_direction[c];
    }
    for (int c = 0; c < 2; c++)
        e.uv[c] += s * dir->uv[c];
    return e;
}

/* DINPUT values eps * dir, on both axes (the test moves along one line). */
static void seed(ir_env *e, const ir_env *dir)
{
    memset(e->d_input, 0, sizeof e->d_input);
    for (int a = 0; a < 2; a++) {
        e->d_input[a][IR_IN_HEIGHT][0] = EPS * dir->height;
        e->d_input[a][IR_IN_VIEW_DISTANCE][0] = EPS * dir->view_distance;
        for (int c = 0; c < 3; c++) {
            e->d_input[a][IR_IN_POSITION][c] = EPS * dir->position[c];
            e->d_input[a][IR_IN_VIEW_DIRECTION][c] = EPS * dir->view_direction[c];
        }
        for (int c = 0; c < 2; c++)
            e->d_input[a][IR_IN_UV][c] = EPS * dir->uv[c];
    }
}

static double fd(const ir *ir, ir_ref r, const ir_env *base, const ir_env *dir, double h,
                 int c)
{
    double p[4], m[4];
    ir_env ep = at(base, dir, h), em = at(base, dir, -h);
    ir_eval(ir, r, &ep, p);
    ir_eval(ir, r, &em, m);
    return (p[c] - m[c]) / (2 * h);
}

/* Compare r's derivative node dr (built beforehand) with finite
 * differences at `base` along `dir`. */
/* Some value r depends on is beyond 1e6 or not finite: double rounding
 * there (mod of 1e150, sin of 1e9) swamps any finite difference. */
static bool wild(const ir *ir, ir_ref r, const ir_env *e)
{
    double (*vals)[4] = calloc(r.id + 1, sizeof *vals);
    uint8_t *need = calloc(r.id + 1, 1);
    need[r.id] = 1;
    for (uint32_t id = r.id; id > 0; id--)
        if (need[id])
            for (int i = 0; i < ir->nodes[id].nargs; i++)
                need[ir->nodes[id].arg[i].id] = 1;
    bool w = false;
    for (uint32_t id = 1; id <= r.id; id++) {
        if (!need[id])
            continue;
        ir_eval_node(ir, id, e, vals);
        for (int c = 0; c < ir_type_width(ir_typeof(ir, (ir_ref){id})); c++)
            w = w || !(fabs(vals[id][c]) <= 1e6);
    }
    free(vals);
    free(need);
    return w;
}

static void check_point(const ir *ir, ir_ref r, ir_ref dr, const ir_env *base,
                        const ir_env *dir, tally *t, const char *what)
{
    ir_env e = *base;
    seed(&e, dir);
    double f0[4], d[4];
    ir_eval(ir, r, &e, f0);
    ir_eval(ir, dr, &e, d);
    bool skip = wild(ir, r, base);
    bool sampled = false, wraps = false;
    for (uint32_t id = 1; id <= r.id; id++) {
        sampled = sampled || ir->nodes[id].op == IR_OP_SAMPLE;
        wraps = wraps || ir->nodes[id].op == IR_OP_FRACT || ir->nodes[id].op == IR_OP_MOD;
    }
    double tol = sampled ? TOL_SAMPLE : TOL_ALU;
    for (int c = 0; c < ir_type_width(ir_typeof(ir, r)); c++) {
        t->values++;
        double a1 = fd(ir, r, base, dir, H, c), b = fd(ir, r, base, dir, H / 2, c);
        double a = (4 * b - a1) / 3;   /* Richardson: error O(h^4) */
        /* h / 3 too: a fract that wraps 2k times within h and k times
         * within h / 2 fools the first two alike */
        double a3 = fd(ir, r, base, dir, H / 3, c);
        double floor_ = 1e-4 * fmax(1.0, fabs(f0[c]));
        double scale = fmax(fmax(fabs(a1), fabs(b)), floor_);
        double got = d[c] / EPS;
        if (skip || !isfinite(a) || fabs(a1 - b) > 1e-2 * scale || fabs(b - a3) > 1e-2 * scale)
            continue;   /* not smooth within h here */
        /* a fract or mod of a value that moves by more than half a period
         * within h wraps inside every difference, whose steps can then agree
         * by aliasing (hash_sin's sin * 43758) */
        if (wraps && fabs(got) * H > 0.5)
            continue;
        t->compared++;
        double err = fabs(got - a) / fmax(fmax(fabs(a), fabs(got)), floor_);
        if (!(err <= tol)) {
            fprintf(stderr, "%s: component %d: derivative %.9g, finite difference %.9g "
                    "(h/2: %.9g), value %.9g\n", what, c, got, a, b, f0[c]);
            ir_set_root((struct ir *)ir, "value", r);   /* for the dump only */
            ir_set_root((struct ir *)ir, "derivative", dr);
            ir_dump(ir, stderr);
            fail();
        }
        if (fabs(a) > floor_)
            t->moving++;
        if (sampled)
            t->worst_sample = fmax(t->worst_sample, err);
        else
            t->worst = fmax(t->worst, err);
    }
}

/* A random point: inputs in their usual ranges, a random direction. */
static void random_point(random_ir_rng *rng, ir_env *base, ir_env *dir)
{
    memset(base, 0, sizeof *base);
    memset(dir, 0, sizeof *dir);
    base->height = random_ir_range(rng, -50, 500);
    base->slope = random_ir_range(rng, 0, 1);
    base->view_distance = random_ir_range(rng, 1, 2000);
    base->destruction = random_ir_range(rng, 0, 1);
    double n = 0;
    for (int c = 0; c < 3; c++) {
        base->normal[c] = random_ir_range(rng, -1, 1);
        base->position[c] = random_ir_range(rng, -100, 1000);
        base->view_direction[c] = random_ir_range(rng, -1, 1);
        n += base->view_direction[c] * base->view_direction[c];
    }
    for (int c = 0; c < 3; c++)
        base->view_direction[c] /= sqrt(n);
    for (int c = 0; c < 2; c++)
        base->uv[c] = random_ir_range(rng, 0.05, 0.95);
    base->sample = random_ir_sample;
    dir->height = random_ir_range(rng, -1, 1);
    dir->view_distance = random_ir_range(rng, -1, 1);
    for (int c = 0; c < 3; c++) {
        dir->position[c] = random_ir_range(rng, -1, 1);
        dir->view_direction[c] = random_ir_range(rng, -1e-3, 1e-3);
    }
    for (int c = 0; c < 2; c++)
        dir->uv[c] = random_ir_range(rng, -1e-2, 1e-2);
}

static void report(const char *what, const tally *t)
{
    printf("%s: %ld values, %ld compared (smooth), %ld with a derivative != 0; "
           "worst relative error %.3g without samples (tolerance %.0e), %.3g with "
           "(tolerance %.0e)\n", what, t->values, t->compared, t->moving, t->worst, TOL_ALU,
           t->worst_sample, TOL_SAMPLE);
}

/* ---- random graphs ----------------------------------------------------- */

static void test_random_graphs(void **state)
{
    random_ir_rng rng = {777};
    tally t = {0};
    double params[4 * RANDOM_IR_NPARAMS] = {0}, painted[RANDOM_IR_NPAINTED] = {0};
    for (int g = 0; g < GRAPHS; g++) {
        ir ir;
        ir_init(&ir);
        random_ir_setup(&ir);
        ir_type ty = ir_type_vec(1 + random_ir_int(&rng, 4));
        ir_ref r = random_ir_expr(&ir, &rng, ty, 5, NULL);
        ir_ref dr = ir_derivative(&ir, r, g & 1);
        assert_int_equal(ir_typeof(&ir, dr), ty);
        assert_true(ir_validate(&ir, stderr));
        for (int p = 0; p < POINTS; p++) {
            ir_env base, dir;
            random_point(&rng, &base, &dir);
            for (int i = 0; i < RANDOM_IR_NPARAMS; i++)
                for (int c = 0; c < 4; c++)
                    params[4 * i + c] = ir.params[i].def[c];
            painted[0] = random_ir_unit(&rng);
            base.params = params;
            base.painted = painted;
            char what[64];
            snprintf(what, sizeof what, "random graph %d, point %d", g, p);
            check_point(&ir, r, dr, &base, &dir, &t, what);
        }
        ir_free(&ir);
    }
    report("random graphs", &t);
    /* not vacuous: most values are compared, and many of those move
     * (random graphs often read only constants, params, normal, slope) */
    assert_true(t.compared >= t.values / 2);
    assert_true(t.moving >= 500 && t.moving >= t.compared / 10);
}

/* ---- every shader of nodes/ ------------------------------------------- */

typedef struct port { char type[16], name[64]; bool has_default; } port;

/* `in TYPE NAME [= …]` / `out TYPE NAME = …` lines of shader `name`'s block
 * in `text`, from `at` (its "shader" line) to the closing brace. */
static int ports_of(const char *at, const char *kw, port *ports, int max)
{
    int n = 0;
    const char *end = strstr(at, "\n}");
    for (const char *l = strchr(at, '\n'); l && l < end && n < max; l = strchr(l + 1, '\n')) {
        char k[8], type[16], name[64];
        if (sscanf(l + 1, " %7s %15s %63[A-Za-z0-9_]", k, type, name) != 3 || strcmp(k, kw))
            continue;
        port *p = &ports[n++];
        snprintf(p->type, sizeof p->type, "%s", type);
        snprintf(p->name, sizeof p->name, "%s", name);
        const char *eol = strchr(l + 1, '\n');
        const char *eq = strchr(l + 1, '=');
        p->has_default = eq && (!eol || eq < eol);
    }
    return n;
}

static char *slurp(const char *path)
{
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *s = malloc((size_t)n + 1);
    assert_int_equal(fread(s, 1, (size_t)n, f), (size_t)n);
    s[n] = 0;
    fclose(f);
    return s;
}

static void test_nodes(void **state)
{
    static const char *const search[] = {".", NULL};
    glob_t g;
    assert_int_equal(glob("nodes/*.sg", 0, NULL, &g), 0);
    /* one program importing every file */
    size_t cap = 64 * (g.gl_pathc + 1);
    char *imports = calloc(cap, 1);
    for (size_t i = 0; i < g.gl_pathc; i++)
        snprintf(imports + strlen(imports), cap - strlen(imports), "import \"%s\"\n",
                 g.gl_pathv[i]);
    sg_diags d;
    sg_diags_init(&d);
    sg_program *prog = sg_load_string("nodes.sg", imports, search, &d);
    if (!prog || d.nerrors)
        sg_diags_print(&d, stderr);
    assert_non_null(prog);
    random_ir_rng rng = {4242};
    tally t = {0};
    int nshaders = 0;
    for (size_t f = 0; f < g.gl_pathc; f++) {
        char *text = slurp(g.gl_pathv[f]);
        for (const char *s = strstr(text, "\nshader "); s; s = strstr(s + 1, "\nshader ")) {
            char name[64];
            assert_int_equal(sscanf(s, "\nshader %63[A-Za-z0-9_]", name), 1);
            /* each shader's points from its name: a new node file leaves
             * the other shaders' points alone */
            uint64_t h = 4242;
            for (const char *c = name; *c; c++)
                h = h * 131 + (unsigned char)*c;
            rng = (random_ir_rng){h};
            port in[16], out[16];
            int nin = ports_of(s, "in", in, 16), nout = ports_of(s, "out", out, 16);
            ir ir;
            ir_init(&ir);
            ir_texture tex = {.file = "random.png", .lo = 0, .hi = 1};
            ir_add_texture(&ir, &tex);
            /* moving values: vectors always, floats without a default */
            const char *in_names[16];
            ir_ref in_vals[16];
            int nb = 0;
            ir_ref uv = ir_input(&ir, IR_IN_UV), pos = ir_input(&ir, IR_IN_POSITION);
            for (int i = 0; i < nin; i++) {
                ir_ref v = IR_NONE;
                if (!strcmp(in[i].type, "texture"))
                    v = ir_texture_ref(&ir, 0);
                else if (!strcmp(in[i].type, "vec2"))
                    v = ir_op2(&ir, IR_OP_MUL, uv, ir_const(&ir, IR_T_VEC2,
                                                              (double[]){5, 7, 0, 0}));
                else if (!strcmp(in[i].type, "vec3"))
                    v = ir_op1(&ir, IR_OP_NORMALIZE, pos);
                else if (!in[i].has_default)
                    v = ir_op2(&ir, IR_OP_MUL, ir_input(&ir, IR_IN_HEIGHT),
                               ir_constf(&ir, 1e-3));
                if (ir_ref_ok(v)) {
                    in_names[nb] = in[i].name;
                    in_vals[nb++] = v;
                }
            }
            const char *out_names[16];
            ir_ref out_vals[16];
            for (int o = 0; o < nout; o++)
                out_names[o] = out[o].name;
            if (!sg_lower_shader(prog, name, &ir, in_names, in_vals, nb, out_names, out_vals,
                                 nout, &d)) {
                sg_diags_print(&d, stderr);
                fail_msg("cannot lower %s", name);
            }
            nshaders++;
            for (int o = 0; o < nout; o++) {
                ir_ref dr = ir_derivative(&ir, out_vals[o], 0);
                for (int p = 0; p < POINTS; p++) {
                    ir_env base, dir;
                    random_point(&rng, &base, &dir);
                    base.height = random_ir_range(&rng, 0, 1000);
                    char what[160];
                    snprintf(what, sizeof what, "%s.%s, point %d", name, out_names[o], p);
                    check_point(&ir, out_vals[o], dr, &base, &dir, &t, what);
                }
            }
            ir_free(&ir);
        }
        free(text);
    }
    report("nodes/", &t);
    printf("nodes/: %d shaders\n", nshaders);
    assert_true(nshaders >= 60);
    assert_true(t.compared >= t.values / 2);
    assert_true(t.moving >= t.compared / 2);
    sg_free(prog);
    sg_diags_free(&d);
    free(imports);
    globfree(&g);
}

/* ---- the pass ---------------------------------------------------------- */

static void test_pass(void **state)
{
    random_ir_rng rng = {99};
    int samples = 0;
    for (int g = 0; g < 60; g++) {
        ir ir;
        ir_init(&ir);
        random_ir_setup(&ir);
        ir_ref r = random_ir_expr(&ir, &rng, IR_T_VEC4, 5, NULL);
        /* a sample of a warped uv, so there is one to rewrite */
        ir_ref uv = ir_op2(&ir, IR_OP_ADD, ir_input(&ir, IR_IN_UV),
                           ir_swizzle(&ir, r, "xy"));
        ir_ref s = ir_op2(&ir, IR_OP_SAMPLE, ir_texture_ref(&ir, 0), uv);
        ir_set_root(&ir, "out", ir_op2(&ir, IR_OP_ADD, r, s));
        ir_env base, dir;
        random_point(&rng, &base, &dir);
        seed(&base, &dir);
        double before[4], after[4];
        ir_eval(&ir, ir_find_root(&ir, "out"), &base, before);

        int nsample = 0;
        for (uint32_t i = 1; i < ir.nnodes; i++)
            nsample += ir.nodes[i].op == IR_OP_SAMPLE;
        assert_true(ir_differentiate(&ir));
        assert_true(ir_validate(&ir, stderr));
        ir_eval(&ir, ir_find_root(&ir, "out"), &base, after);
        for (int c = 0; c < 4; c++)
            assert_true(before[c] == after[c] || (isnan(before[c]) && isnan(after[c])));
        /* No SAMPLE left.  Each sample became a SAMPLE_GRAD whose
         * gradients are the derivatives of its uv (built again here:
         * hash-consing gives the very same nodes).  The others are SAMPLE's
         * rule's finite differences: uv + g beside sample(uv) with g, the
         * outer sample's gradients. */
        uint32_t n = ir.nnodes;
        int primary = 0;
        for (uint32_t i = 1; i < n; i++) {
            assert_int_not_equal(ir.nodes[i].op, IR_OP_SAMPLE);
            if (ir.nodes[i].op != IR_OP_SAMPLE_GRAD)
                continue;
            ir_node sg = ir.nodes[i];
            const ir_node *u = ir_get(&ir, sg.arg[1]);
            int k = u->op != IR_OP_ADD ? -1
                    : ir_ref_eq(u->arg[1], sg.arg[2]) || ir_ref_eq(u->arg[1], sg.arg[3]) ? 0
                    : ir_ref_eq(u->arg[0], sg.arg[2]) || ir_ref_eq(u->arg[0], sg.arg[3]) ? 1
                                                                                     : -1;
            if (k >= 0) {
                ir_node base_sample = sg;
                base_sample.arg[1] = u->arg[k];
                assert_true(ir_ref_ok(ir_lookup(&ir, &base_sample)));
                continue;
            }
            for (int a = 0; a < 2; a++)
                assert_int_equal(ir_derivative(&ir, sg.arg[1], a).id, sg.arg[2 + a].id);
            primary++;
        }
        assert_int_equal(primary, nsample);
        samples += primary;
        ir_optimize(&ir, NULL);
        assert_true(ir_validate(&ir, stderr));
        ir_free(&ir);
    }
    assert_true(samples >= 60);
}

/* The compute variant of random graphs over every op compiles. */
static void test_compute_compiles(void **state)
{
    random_ir_rng rng = {2024};
    static const struct { const char *name; ir_type type; } outs[] = {
        {"rnd.mask", IR_T_FLOAT}, {"rnd.albedo", IR_T_VEC3}, {"rnd.normal", IR_T_VEC3},
        {"rnd.roughness", IR_T_FLOAT}, {"rnd.height", IR_T_FLOAT}};
    int grads = 0, dinputs = 0;
    for (int g = 0; g < 8; g++) {
        ir ir;
        ir_init(&ir);
        random_ir_setup(&ir);
        for (int i = 0; i < 5; i++)
            ir_set_root(&ir, outs[i].name, random_ir_expr(&ir, &rng, outs[i].type, 5, NULL));
        ir_buf a = {0};
        glsl_material_shader_stage(&ir, "rnd", true, &a);
        assert_null(strstr(a.s, "texture(t_"));
        /* call sites: every occurrence but the prelude's definition */
        for (const char *p = a.s; (p = strstr(p, "splat_texture_grad(")); p++)
            grads += strncmp(p, "splat_texture_grad(sampler2D", 28) != 0;
        for (const char *p = a.s; (p = strstr(p, "splat_d_uv(")); p++)
            dinputs++;
        /* the shader, and its counting variant as the runtime makes it
         * (abi.h: #define SPLAT_COUNT after the #version line) */
        const char *nl = strchr(a.s, '\n');
        ir_buf counting = {0};
        ir_buf_printf(&counting, "%.*s#define SPLAT_COUNT 1\n%s", (int)(nl + 1 - a.s), a.s,
                      nl + 1);
        const char *texts[] = {a.s, counting.s};
        for (int k = 0; k < 2; k++) {
            uint32_t *words = NULL;
            size_t nwords = 0;
            char *log = NULL;
            if (!spv_compile(texts[k], SPV_STAGE_COMPUTE, "rnd", &words, &nwords, &log) ||
                !spv_validate(words, nwords, &log))
                fail_msg("%s\n%s", log ? log : "", texts[k]);
            free(words);
            free(log);
        }
        assert_non_null(strstr(counting.s, "splat_count_samples("));
        ir_buf_free(&counting);
        ir_buf_free(&a);
        ir_free(&ir);
    }
    assert_true(grads >= 8);
    assert_true(dinputs >= 8);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_random_graphs),
        cmocka_unit_test(test_nodes),
        cmocka_unit_test(test_pass),
        cmocka_unit_test(test_compute_compiles),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
