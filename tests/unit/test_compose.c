/* test_compose.c — the compositor (compiler/compose.c): composite IR exact
 * against the multi-pass alpha reference, resource dedup, the terrain
 * normal computed once, values placed in the region that needs them, and
 * every GLSL variant accepted by glslang and spirv-val. */
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
#include "scene.h"
#include "glsl_check.h"
#include "spv.h"

/* ---- a small scene built with the IR builder ------------------------------
 *   0 base:  mask 1; albedo = sample(rock.png, uv * 4).rgb; normal = terrain
 *   1 cliff: mask = smoothstep(0.2, 0.6, 1 - normal.y); albedo = mix(the same
 *            rock sample (its own texture entry: dedup must merge it),
 *            0.4, normal.x)
 *   2 snow:  mask = saturate((height - snow.level) * 0.01) * normal.y;
 *            albedo = sample(snow_detail.png, uv * 13).rgb (surface only) */

enum { BASE, CLIFF, SNOW, NMAT };
static const char *const mat_names[NMAT] = {"base", "cliff", "snow"};

static ir_texture tex(const char *file)
{
    return (ir_texture){.file = (char *)file, .filter = IR_FILTER_LINEAR,
                        .mip = IR_FILTER_LINEAR, .wrap = IR_WRAP_REPEAT,
                        .srgb = true, .lo = 0, .hi = 1};
}

static ir_ref vec3c(ir *ir, double x, double y, double z)
{
    double v[4] = {x, y, z, 0};
    return ir_const(ir, IR_T_VEC3, v);
}

static void set_outputs(ir *ir, const char *name, ir_ref mask, ir_ref albedo,
                        ir_ref normal, ir_ref rough, ir_ref height)
{
    ir_ref v[SG_OUT_COUNT] = {mask, albedo, normal, rough, height};
    for (int o = 0; o < SG_OUT_COUNT; o++) {
        char root[64];
        snprintf(root, sizeof root, "%s.%s", name, sg_output_names[o]);
        ir_set_root(ir, root, v[o]);
    }
}

static void build_scene(ir *s)
{
    ir_init(s);
    ir_ref uv = ir_input(s, IR_IN_UV);
    ir_ref n = ir_input(s, IR_IN_NORMAL);
    ir_ref ny = ir_swizzle(s, n, "y");
    ir_ref h = ir_input(s, IR_IN_HEIGHT);
    ir_ref uv4 = ir_op2(s, IR_OP_MUL, uv, ir_splat(s, ir_constf(s, 4.0), IR_T_VEC2));

    ir_texture rock = tex("textures/rock.png");
    ir_ref base_alb = ir_swizzle(
        s, ir_op2(s, IR_OP_SAMPLE, ir_texture_ref(s, ir_add_texture(s, &rock)), uv4), "rgb");
    set_outputs(s, "base", ir_constf(s, 1.0), base_alb, n, ir_constf(s, 0.9),
                ir_op2(s, IR_OP_MUL, h, ir_constf(s, 0.01)));

    ir_ref slope = ir_op2(s, IR_OP_SUB, ir_constf(s, 1.0), ny);
    ir_ref cliff_mask = ir_op3(s, IR_OP_SMOOTHSTEP, ir_constf(s, 0.2), ir_constf(s, 0.6), slope);
    ir_ref rock2 = ir_swizzle(
        s, ir_op2(s, IR_OP_SAMPLE, ir_texture_ref(s, ir_add_texture(s, &rock)), uv4), "rgb");
    ir_ref cliff_alb = ir_op3(s, IR_OP_MIX, rock2, vec3c(s, 0.4, 0.4, 0.4),
                              ir_splat(s, ir_swizzle(s, n, "x"), IR_T_VEC3));
    ir_ref cliff_n = ir_op1(s, IR_OP_NORMALIZE, ir_op2(s, IR_OP_ADD, n, vec3c(s, 0.1, 0, 0)));
    set_outputs(s, "cliff", cliff_mask, cliff_alb, cliff_n, ir_constf(s, 0.7),
                ir_constf(s, 0.3));

    ir_param level = {.name = "snow.level", .type = IR_T_FLOAT, .def = {120.0},
                      .lo = 0, .hi = 1000};
    ir_ref lv = ir_param_ref(s, ir_add_param(s, &level));
    ir_ref snow_mask = ir_op2(
        s, IR_OP_MUL,
        ir_op1(s, IR_OP_SATURATE,
               ir_op2(s, IR_OP_MUL, ir_op2(s, IR_OP_SUB, h, lv), ir_constf(s, 0.01))),
        ny);
    ir_texture snow_tex = tex("textures/snow_detail.png");
    ir_ref uv13 = ir_op2(s, IR_OP_MUL, uv, ir_splat(s, ir_constf(s, 13.0), IR_T_VEC2));
    ir_ref snow_alb = ir_swizzle(
        s, ir_op2(s, IR_OP_SAMPLE, ir_texture_ref(s, ir_add_texture(s, &snow_tex)), uv13),
        "rgb");
    set_outputs(s, "snow", snow_mask, snow_alb, n, ir_constf(s, 0.2), ir_constf(s, 0.9));
}

typedef struct fixture {
    ir           src;
    splat_layout L;
} fixture;

static int setup(void **state)
{
    fixture *f = calloc(1, sizeof *f);
    build_scene(&f->src);
    sg_diags d;
    sg_diags_init(&d);
    bool ok = splat_layout_init(&f->L, &f->src, NULL, NULL, mat_names, NMAT, NULL, 0, &d);
    sg_diags_print(&d, stderr);
    sg_diags_free(&d);
    assert_true(ok);
    *state = f;
    return 0;
}

static int teardown(void **state)
{
    fixture *f = *state;
    splat_layout_free(&f->L);
    ir_free(&f->src);
    free(f);
    return 0;
}

static void compose(fixture *f, const int *mats, int n, bool reference, splat_composite *c)
{
    sg_diags d;
    sg_diags_init(&d);
    splat_compose_desc desc = {.materials = mats, .nmaterials = n, .reference = reference};
    bool ok = splat_compose(&f->L, &desc, c, &d);
    sg_diags_print(&d, stderr);
    assert_true(ok);
    assert_int_equal(d.nerrors, 0);
    sg_diags_free(&d);
    assert_true(ir_validate(&c->ir, stderr));
}

static char *glsl_of(fixture *f, const splat_composite *c, bool flat)
{
    ir_buf b = {0};
    splat_glsl_desc gd = {.title = "test", .flat = flat};
    splat_composite_glsl(&f->L, c, &gd, &b);
    return b.s;
}

/* ---- CPU reference --------------------------------------------------------- */

/* Texture content depends on the file only (texture indices differ between
 * the scene's ir and a composite's). */
static void sample_fn(void *user, int texture, double u, double v, double rgba[4])
{
    const ir *ir = user;
    unsigned h = 5381;
    for (const char *s = ir->textures[texture].file; *s; s++)
        h = h * 33 + (unsigned char)*s;
    for (int c = 0; c < 4; c++)
        rgba[c] = 0.5 + 0.5 * sin(7.0 * u + 3.0 * v + c + (h % 1000) * 0.01);
}

static double rnd(double lo, double hi)
{
    return lo + (hi - lo) * ((double)rand() / RAND_MAX);
}

static ir_env random_env(void)
{
    ir_env e = {0};
    double nx = rnd(-1, 1), ny = rnd(0.05, 1), nz = rnd(-1, 1);
    double len = sqrt(nx * nx + ny * ny + nz * nz);
    e.normal[0] = nx / len;
    e.normal[1] = ny / len;
    e.normal[2] = nz / len;
    e.slope = 1 - e.normal[1];
    e.height = rnd(0, 300);
    e.uv[0] = rnd(0, 1);
    e.uv[1] = rnd(0, 1);
    e.position[0] = e.uv[0] * 1000;
    e.position[1] = e.height;
    e.position[2] = e.uv[1] * 1000;
    e.view_distance = rnd(1, 500);
    e.sample = sample_fn;
    return e;
}

static void eval_root(const ir *ir, const char *name, ir_env *e, double out[4])
{
    ir_ref r = ir_find_root(ir, name);
    assert_true(ir_ref_ok(r));
    memset(out, 0, 4 * sizeof *out);
    e->sample_user = (void *)ir;
    ir_eval(ir, r, e, out);
}

/* Multi-pass alpha (back to front, S = mix(S, s_i, m_i)) and front to back
 * (T = 1; w = T m; S += w s; T -= w) over `mats` (top first). */
static void reference(const ir *src, const char *const *names, const int *mats, int n,
                      ir_env *e, int out, double b2f[4], double f2b[4])
{
    double m[8], s[8][4];
    for (int j = 0; j < n; j++) {
        char root[64];
        snprintf(root, sizeof root, "%s.mask", names[mats[j]]);
        double mv[4];
        eval_root(src, root, e, mv);
        m[j] = j == n - 1 ? 1.0 : fmin(fmax(mv[0], 0.0), 1.0);
        snprintf(root, sizeof root, "%s.%s", names[mats[j]], sg_output_names[out]);
        eval_root(src, root, e, s[j]);
    }
    for (int c = 0; c < 4; c++) {
        b2f[c] = s[n - 1][c];
        for (int j = n - 2; j >= 0; j--)
            b2f[c] = b2f[c] * (1 - m[j]) + s[j][c] * m[j];
        double T = 1;
        f2b[c] = 0;
        for (int j = 0; j < n; j++) {
            double w = T * m[j];
            f2b[c] += w * s[j][c];
            T -= w;
        }
    }
}

static void check_exact_with(const splat_layout *L, const int *mats, int n)
{
    splat_composite c;
    sg_diags d;
    sg_diags_init(&d);
    splat_compose_desc desc = {.materials = mats, .nmaterials = n};
    bool ok = splat_compose(L, &desc, &c, &d);
    sg_diags_print(&d, stderr);
    sg_diags_free(&d);
    assert_true(ok);
    srand(1234);
    int partial = 0;  /* samples where the top mask is strictly inside (0, 1) */
    for (int i = 0; i < 2000; i++) {
        ir_env e = random_env();
        for (int o = SG_OUT_ALBEDO; o < SG_OUT_COUNT; o++) {
            double b2f[4], f2b[4], got[4];
            reference(L->src, (const char *const *)L->materials, mats, n, &e, o, b2f, f2b);
            char root[64];
            snprintf(root, sizeof root, "composite.%s", sg_output_names[o]);
            eval_root(&c.ir, root, &e, got);
            for (int k = 0; k < 4; k++) {
                assert_true(fabs(f2b[k] - b2f[k]) <= 1e-9);
                if (fabs(got[k] - b2f[k]) > 1e-9)
                    fail_msg("sample %d output %s[%d]: composite %.17g, reference %.17g", i,
                             sg_output_names[o], k, got[k], b2f[k]);
            }
        }
        double w[4];
        eval_root(&c.ir, "layer0.weight", &e, w);
        partial += w[0] > 0.01 && w[0] < 0.99;
    }
    assert_true(partial > 100);  /* the samples really blend */
    splat_composite_free(&c);
}

static void check_exact(fixture *f, const int *mats, int n)
{
    check_exact_with(&f->L, mats, n);
}

static void test_exact_against_multipass(void **state)
{
    fixture *f = *state;
    static const int three[] = {SNOW, CLIFF, BASE};
    static const int two[] = {CLIFF, BASE};
    static const int skip[] = {SNOW, BASE};
    check_exact(f, three, 3);
    check_exact(f, two, 2);
    check_exact(f, skip, 2);
}

/* ---- GLSL structure --------------------------------------------------------- */

static int count(const char *s, const char *what)
{
    int n = 0;
    for (const char *p = s; (p = strstr(p, what)); p += strlen(what))
        n++;
    return n;
}

/* The body of the composite path (after the mask view branch). */
static const char *composite_body(const char *glsl)
{
    const char *p = strstr(glsl, "vec3 s_albedo");
    assert_non_null(p);
    return p;
}

/* The header line of the innermost block enclosing offset `at` of `s`
 * (from "{" to its line start), or NULL at the top level of `s`; with
 * `block_end` the offset of that block's closing brace. */
static const char *enclosing(const char *s, size_t at, size_t *hdr_len, size_t *block_end)
{
    int depth = 0;
    size_t i = at;
    while (i-- > 0) {
        if (s[i] == '}')
            depth++;
        else if (s[i] == '{' && depth-- == 0)
            break;
    }
    if (i == (size_t)-1)
        return NULL;
    size_t start = i;
    while (start > 0 && s[start - 1] != '\n')
        start--;
    *hdr_len = i - start + 1;
    int d = 0;
    size_t k = i + 1;
    for (; s[k]; k++) {
        if (s[k] == '{')
            d++;
        else if (s[k] == '}' && d-- == 0)
            break;
    }
    *block_end = k;
    return s + start;
}

/* The text of a block without its nested blocks. */
static char *own_level(const char *s, size_t n)
{
    char *out = calloc(n + 1, 1);
    int depth = 0;
    size_t k = 0;
    for (size_t i = 0; i < n; i++) {
        if (s[i] == '{')
            depth++;
        else if (s[i] == '}')
            depth--;
        else if (depth == 0)
            out[k++] = s[i];
    }
    return out;
}

static void test_dedup_and_normal_once(void **state)
{
    fixture *f = *state;
    assert_int_equal(f->src.ntextures, 3);
    assert_int_equal(f->L.ntextures, 2);  /* rock.png twice -> one resource */
    static const int mats[] = {SNOW, CLIFF, BASE};
    splat_composite c;
    compose(f, mats, 3, false, &c);
    assert_int_equal(c.ir.ntextures, 2);
    assert_int_equal(c.ntextures, 2);
    char *g = glsl_of(f, &c, false);
    assert_int_equal(count(g, "uniform sampler2DArray u_texa_"), 2);
    assert_int_equal(count(g, "uniform sampler2DArray u_texa_0;"), 1);
    /* the rock sample at the same uv is one node: sampled once */
    const char *body = composite_body(g);
    assert_int_equal(count(body, "splat_texture_grad(u_texa_0"), 1);
    /* the terrain normal: three materials use it, computed once */
    assert_int_equal(count(body, "splat_normal()"), 1);
    free(g);
    splat_composite_free(&c);
}

static void test_placement(void **state)
{
    fixture *f = *state;
    static const int mats[] = {SNOW, CLIFF, BASE};
    splat_composite c;
    compose(f, mats, 3, false, &c);
    char *g = glsl_of(f, &c, false);
    const char *body = composite_body(g);

    /* snow's detail texture feeds only snow's surface: inside the
     * `if (w > 0.0)` block that accumulates it */
    const char *use = strstr(body, "splat_texture_grad(u_texa_1");
    assert_non_null(use);
    size_t hl, end;
    const char *hdr = enclosing(body, (size_t)(use - body), &hl, &end);
    assert_non_null(hdr);
    char *h = strndup(hdr, hl);
    assert_non_null(strstr(h, "if ("));
    assert_non_null(strstr(h, "> 0.0)) {"));
    char *block = strndup(hdr, (size_t)(body + end - hdr));
    assert_non_null(strstr(block, "s_albedo +="));
    free(block);
    free(h);

    /* the terrain normal (masks of snow and cliff, surfaces of all) is in
     * no `if`: hoisted to the outermost block that dominates its uses */
    const char *nrm = strstr(body, "splat_normal()");
    assert_non_null(nrm);
    size_t at = (size_t)(nrm - body);
    while ((hdr = enclosing(body, at, &hl, &end))) {
        h = strndup(hdr, hl);
        assert_null(strstr(h, "if ("));
        free(h);
        at = (size_t)(hdr - body);
    }

    /* the rock sample serves cliff's and base's surfaces, not snow's: it is
     * under cliff's coverage guard but not inside cliff's surface block */
    use = strstr(body, "splat_texture_grad(u_texa_0");
    assert_non_null(use);
    hdr = enclosing(body, (size_t)(use - body), &hl, &end);
    assert_non_null(hdr);
    block = own_level(hdr + hl, (size_t)(body + end - hdr) - hl);
    assert_null(strstr(block, "s_albedo +="));  /* not a surface block */
    free(block);
    block = strndup(hdr, (size_t)(body + end - hdr));
    assert_int_equal(count(block, "s_albedo +="), 2);  /* cliff's and base's */
    free(block);
    free(g);
    splat_composite_free(&c);
}

static void test_variants_compile(void **state)
{
    fixture *f = *state;
    static const int mats[] = {SNOW, CLIFF, BASE};
    static const int uber[] = {SNOW, CLIFF, BASE};
    splat_composite c;
    compose(f, mats, 3, false, &c);
    char *g = glsl_of(f, &c, false);
    glsl_check_compiles(g, SPV_STAGE_FRAGMENT, "composite");
    assert_true(count(composite_body(g), "if (") >= 3);
    free(g);
    g = glsl_of(f, &c, true);
    glsl_check_compiles(g, SPV_STAGE_FRAGMENT, "flat");
    assert_int_equal(count(composite_body(g), "if ("), 0);
    free(g);
    splat_composite_free(&c);

    compose(f, uber, 3, false, &c);
    g = glsl_of(f, &c, false);
    glsl_check_compiles(g, SPV_STAGE_FRAGMENT, "uber");
    free(g);
    splat_composite_free(&c);

    for (int k = 0; k < NMAT; k++) {
        compose(f, &k, 1, true, &c);
        g = glsl_of(f, &c, false);
        assert_non_null(strstr(g, "#define SPLAT_MULTIPASS"));
        assert_non_null(strstr(g, "splat_finish("));
        glsl_check_compiles(g, SPV_STAGE_FRAGMENT, "reference");
        free(g);
        splat_composite_free(&c);
    }
}

/* SPLAT_VIEW_MASK: a case per layer's scene material showing its own
 * clamped mask (1 for material 0), nothing for materials not in it. */
static void test_mask_view(void **state)
{
    fixture *f = *state;
    static const int mats[] = {SNOW, BASE};
    splat_composite c;
    compose(f, mats, 2, false, &c);
    char *g = glsl_of(f, &c, false);
    char want[64];
    snprintf(want, sizeof want, "splat_view() == %du", SPLAT_VIEW_MASK);
    const char *body = strstr(g, "void main()");  /* not the prelude's switch */
    assert_non_null(body);
    assert_non_null(strstr(body, want));
    assert_non_null(strstr(body, "case 2u:"));  /* snow */
    assert_non_null(strstr(body, "case 0u:"));  /* base */
    assert_null(strstr(body, "case 1u:"));      /* cliff is not in it */
    free(g);
    srand(99);
    for (int i = 0; i < 500; i++) {
        ir_env e = random_env();
        double top[4], bottom[4], mask[4];
        eval_root(&c.ir, "layer0.view_mask", &e, top);
        eval_root(&c.ir, "layer1.view_mask", &e, bottom);
        eval_root(&f->src, "snow.mask", &e, mask);
        assert_true(fabs(top[0] - fmin(fmax(mask[0], 0.0), 1.0)) <= 1e-12);
        assert_true(bottom[0] == 1.0);
    }
    splat_composite_free(&c);
}

/* Same inputs, same text. */
static void test_deterministic(void **state)
{
    fixture *f = *state;
    static const int mats[] = {SNOW, CLIFF, BASE};
    splat_composite a, b;
    compose(f, mats, 3, false, &a);
    compose(f, mats, 3, false, &b);
    char *ga = glsl_of(f, &a, false), *gb = glsl_of(f, &b, false);
    assert_string_equal(ga, gb);
    free(ga);
    free(gb);
    splat_composite_free(&a);
    splat_composite_free(&b);
}

/* ---- the same from graph text, with nodes/compositors.sg -------------------- */

static const char GRAPH[] =
    "import \"nodes/compositors.sg\"\n"
    "import \"nodes/masks.sg\"\n"
    "texture rock { file = \"graphs/textures/rock.png\" }\n"
    "material base {\n"
    "    node c : sample { tex = rock, uv = terrain.uv }\n"
    "    out albedo = c.rgb\n"
    "}\n"
    "material cliff {\n"
    "    node m : slope_ramp { lo = 0.2, hi = 0.6 }\n"
    "    node c : sample { tex = rock, uv = terrain.uv }\n"
    "    node a : mul { a = c.rgb, b = 0.5 }\n"
    "    out mask = m.out\n"
    "    out albedo = a.out\n"
    "    out roughness = 0.4\n"
    "}\n"
    "material snow {\n"
    "    param float level = 120\n"
    "    node d : sub { a = terrain.height, b = level }\n"
    "    node k : mul { a = d.out, b = 0.01 }\n"
    "    node s : saturate { x = k.out }\n"
    "    out mask = s.out\n"
    "    out albedo = vec3(0.95, 0.95, 1.0)\n"
    "    out roughness = 0.3\n"
    "    out height = 0.8\n"
    "}\n";

static void test_graph_compositor(void **state)
{
    static const char *const names[] = {"base", "cliff", "snow"};
    static const char *const search[] = {".", NULL};
    sg_diags d;
    sg_diags_init(&d);
    sg_program *p = sg_load_string("test.sg", GRAPH, search, &d);
    assert_non_null(p);
    ir src;
    ir_init(&src);
    for (int i = 0; i < 3; i++)
        assert_true(sg_lower_material(p, names[i], &src, &d));
    sg_diags_print(&d, stderr);
    assert_int_equal(d.nerrors, 0);

    splat_layout graph, builtin;
    assert_true(splat_layout_init(&graph, &src, p, "linear_alpha", names, 3, NULL, 0, &d));
    assert_true(splat_layout_init(&builtin, &src, NULL, NULL, names, 3, NULL, 0, &d));
    static const int mats[] = {2, 1, 0};
    check_exact_with(&graph, mats, 3);

    /* the graph's linear_alpha is the built-in w = T m, T' = T - w: the
     * same composite, to the byte */
    splat_composite a, b;
    splat_compose_desc desc = {.materials = mats, .nmaterials = 3};
    assert_true(splat_compose(&graph, &desc, &a, &d));
    assert_true(splat_compose(&builtin, &desc, &b, &d));
    ir_buf ga = {0}, gb = {0};
    splat_glsl_desc gd = {.title = "t"};
    splat_composite_glsl(&graph, &a, &gd, &ga);
    splat_composite_glsl(&builtin, &b, &gd, &gb);
    assert_string_equal(ga.s, gb.s);
    glsl_check_compiles(ga.s, SPV_STAGE_FRAGMENT, "graph composite");

    /* an unknown compositor is an error, not a crash */
    splat_layout bad;
    assert_true(splat_layout_init(&bad, &src, p, "no_such_compositor", names, 3, NULL, 0, &d));
    splat_composite c;
    int before = d.nerrors;
    assert_false(splat_compose(&bad, &desc, &c, &d));
    assert_true(d.nerrors > before);

    ir_buf_free(&ga);
    ir_buf_free(&gb);
    splat_composite_free(&a);
    splat_composite_free(&b);
    splat_layout_free(&bad);
    splat_layout_free(&graph);
    splat_layout_free(&builtin);
    ir_free(&src);
    sg_free(p);
    sg_diags_free(&d);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(test_exact_against_multipass, setup, teardown),
        cmocka_unit_test_setup_teardown(test_dedup_and_normal_once, setup, teardown),
        cmocka_unit_test_setup_teardown(test_placement, setup, teardown),
        cmocka_unit_test_setup_teardown(test_variants_compile, setup, teardown),
        cmocka_unit_test_setup_teardown(test_deterministic, setup, teardown),
        cmocka_unit_test_setup_teardown(test_mask_view, setup, teardown),
        cmocka_unit_test(test_graph_compositor),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
