/* test_dump.c — ir_dump writes graph files that read back: for every
 * material of the graph files in graphs/, dump its IR, load the text with
 * sg_load_string, lower the material again and dump that: the same text (round trip), and
 * the same values as the original at sample points.  Both after the whole
 * pipeline (what `splatc dump` prints) and straight after lowering. */
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
#include "sg.h"

static const char *const search[] = {".", NULL};  /* tests run from the repository root */

static char *dump_text(const ir *ir)
{
    char *text = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&text, &len);
    assert_non_null(f);
    ir_dump(ir, f);
    fclose(f);
    return text;
}

static void fail_diags(sg_diags *d, const char *what, const char *text)
{
    sg_diags_print(d, stderr);
    if (text)
        fprintf(stderr, "--- the dump:\n%s", text);
    fail_msg("%s", what);
}

/* Lower material `m` of program `p` (optimised or not) into a fresh ir. */
static void lower(sg_program *p, const char *m, bool optimise, ir *out, const char *text)
{
    sg_diags d;
    sg_diags_init(&d);
    ir_init(out);
    if (!sg_lower_material(p, m, out, &d) || d.nerrors)
        fail_diags(&d, m, text);
    if (optimise)
        ir_optimize(out, NULL);
    assert_true(ir_validate(out, stderr));
    sg_diags_free(&d);
}

/* Values of every root agree at a few terrain points (textures read as
 * the evaluator's default). */
static void same_values(const ir *a, const ir *b, const char *m)
{
    assert_int_equal(a->nroots, b->nroots);
    double painted[64];
    assert_true(a->npainted <= 64 && b->npainted <= 64);
    for (int k = 0; k < 64; k++)
        painted[k] = 0.7;
    for (int k = 0; k < 5; k++) {
        ir_env env = {.height = 300.0 * k, .slope = 0.21 * k, .normal = {0.1 * k, 1, -0.05 * k},
                      .position = {13.0 * k, 300.0 * k, 7.5 * k}, .uv = {0.2 * k, 0.1 * k},
                      .view_distance = 40.0 * k, .destruction = 0.1 * k, .painted = painted};
        for (int r = 0; r < a->nroots; r++) {
            ir_ref rb = ir_find_root(b, a->roots[r].name);
            assert_true(ir_ref_ok(rb));
            double va[4] = {0}, vb[4] = {0};
            ir_eval(a, a->roots[r].ref, &env, va);
            ir_eval(b, rb, &env, vb);
            for (int c = 0; c < 4; c++)
                if (!(va[c] == vb[c] || (isnan(va[c]) && isnan(vb[c]))))
                    fail_msg("%s: root %s component %d: %.17g after the round trip, %.17g before",
                             m, a->roots[r].name, c, vb[c], va[c]);
        }
    }
}

static int round_trip_file(const char *path, bool optimise)
{
    sg_diags d;
    sg_diags_init(&d);
    sg_program *p = sg_load(path, search, &d);
    assert_non_null(p);
    if (d.nerrors)
        fail_diags(&d, path, NULL);
    int n = sg_material_count(p);
    for (int i = 0; i < n; i++) {
        const char *m = sg_material_name(p, i);
        ir a, b;
        lower(p, m, optimise, &a, NULL);
        char *text = dump_text(&a);

        sg_diags d2;
        sg_diags_init(&d2);
        sg_program *q = sg_load_string("dump.sg", text, search, &d2);
        assert_non_null(q);
        if (d2.nerrors)
            fail_diags(&d2, "the dump does not read back", text);
        assert_int_equal(sg_material_count(q), 1);
        lower(q, m, optimise, &b, text);
        char *again = dump_text(&b);
        if (strcmp(text, again)) {
            fprintf(stderr, "--- first dump of %s:\n%s--- second:\n%s", m, text, again);
            fail_msg("%s: the dump of the read-back material differs", m);
        }
        same_values(&a, &b, m);
        if (optimise) {
            /* and the read-back IR is at the pipeline's fixed point */
            ir c;
            lower(q, m, false, &c, text);
            ir_optimize(&c, NULL);
            char *third = dump_text(&c);
            assert_string_equal(text, third);
            free(third);
            ir_free(&c);
        }
        free(again);
        free(text);
        ir_free(&a);
        ir_free(&b);
        sg_free(q);
        sg_diags_free(&d2);
    }
    sg_free(p);
    sg_diags_free(&d);
    return n;
}

static void round_trip_all(bool optimise)
{
    glob_t g;
    assert_int_equal(glob("graphs/*.sg", 0, NULL, &g), 0);
    int materials = 0;
    for (size_t i = 0; i < g.gl_pathc; i++)
        materials += round_trip_file(g.gl_pathv[i], optimise);
    printf("%d materials of %zu files: dump -> read -> lower -> dump gives the same text%s\n",
           materials, g.gl_pathc, optimise ? " (optimised)" : " (as lowered)");
    assert_true(materials >= 15);
    globfree(&g);
}

static void test_round_trip_optimised(void **state)
{
    round_trip_all(true);
}

static void test_round_trip_lowered(void **state)
{
    round_trip_all(false);
}

/* The dump of a material that uses a param, a painted mask, a texture with
 * its own sampler state, splats and swizzles reads back as written. */
static void test_forms(void **state)
{
    static const char src[] =
        "texture detail { file = \"graphs/textures/rock.png\", filter = nearest, wrap = clamp, srgb = true }\n"
        "material m {\n"
        "    param vec3 tint = vec3(0.5, 0.25, 1.0) range 0 2\n"
        "    param float k = 3.0\n"
        "    node f : painted { mask = \"fields\" }\n"
        "    node p : terrain.position\n"
        "    node s : sample { tex = detail, uv = p.out.zx }\n"
        "    node a : mul { a = s.out.rgb, b = f.out }\n"
        "    node t : mul { a = a.out, b = tint }\n"
        "    node h : add { a = k, b = tint.y }\n"
        "    out mask = f.out\n"
        "    out albedo = t.out\n"
        "    out height = h.out\n"
        "}\n";
    sg_diags d;
    sg_diags_init(&d);
    sg_program *p = sg_load_string("forms.sg", src, search, &d);
    assert_non_null(p);
    if (d.nerrors)
        fail_diags(&d, "forms.sg", NULL);
    ir a;
    lower(p, "m", false, &a, NULL);
    char *text = dump_text(&a);
    assert_non_null(strstr(text, "texture t0 { file = \"graphs/textures/rock.png\", filter = nearest, "
                                 "mip = linear, wrap = clamp, srgb = true }\n"));
    assert_non_null(strstr(text, "    param vec3 tint = vec3(0.5, 0.25, 1.0) range 0.0 2.0\n"));
    assert_non_null(strstr(text, "    param float k = 3.0 range 3.0 3.0\n"));
    assert_non_null(strstr(text, " : painted { mask = \"fields\" }  # float\n"));
    /* swizzles on the operand; the float splatted into a vec3 */
    assert_non_null(strstr(text, "node n3 : sample { tex = t0, uv = n2.out.zx }  # vec4\n"));
    assert_non_null(strstr(text, "node n4 : mul { a = n1.out.xxx, b = n3.out.xyz }  # vec3\n"));
    assert_non_null(strstr(text, "add { a = k, b = tint.y }"));
    sg_diags d2;
    sg_diags_init(&d2);
    sg_program *q = sg_load_string("dump.sg", text, search, &d2);
    if (d2.nerrors)
        fail_diags(&d2, "the dump does not read back", text);
    ir b;
    lower(q, "m", false, &b, text);
    char *again = dump_text(&b);
    assert_string_equal(text, again);
    same_values(&a, &b, "m");
    free(text);
    free(again);
    ir_free(&a);
    ir_free(&b);
    sg_free(p);
    sg_free(q);
    sg_diags_free(&d);
    sg_diags_free(&d2);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_forms),
        cmocka_unit_test(test_round_trip_optimised),
        cmocka_unit_test(test_round_trip_lowered),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
