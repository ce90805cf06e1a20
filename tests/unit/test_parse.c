/* test_parse.c — the parser: the AST of each declaration, values of every
 * kind, scenes, error recovery (several errors, each at its line), and
 * unterminated blocks pointing at their '{'. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "sg_internal.h"

static sg_program *load(const char *text, sg_diags *d)
{
    sg_diags_init(d);
    sg_program *p = sg_load_string("t.sg", text, NULL, d);
    assert_non_null(p);
    return p;
}

static void assert_diag(const sg_diags *d, int i, sg_error_id id, int line, int col)
{
    assert_true(i < d->n);
    if (d->items[i].id != id || d->items[i].loc.line != line || d->items[i].loc.col != col)
        fail_msg("diag %d: got id %d at %d:%d (%s), want id %d at %d:%d", i, d->items[i].id,
                 d->items[i].loc.line, d->items[i].loc.col, d->items[i].msg, id, line, col);
}

static void test_shader_ast(void **state)
{
    sg_diags d;
    sg_program *p = load("shader ramp {\n"
                         "    in float x\n"
                         "    in float lo = 0.25\n"
                         "    node d : sub { a = x, b = lo }\n"
                         "    node c : saturate { x = d.out }\n"
                         "    out float out = c.out\n"
                         "}\n", &d);
    assert_int_equal(d.nerrors, 0);
    assert_int_equal(p->nshaders, 1);
    sg_shader *s = p->shaders[0];
    assert_string_equal(s->name, "ramp");
    assert_false(s->is_material);
    assert_int_equal(s->nins, 2);
    assert_false(s->ins[0].has_value);
    assert_true(s->ins[1].has_value);
    assert_int_equal(s->ins[1].value.kind, SG_V_NUMBER);
    assert_true(s->ins[1].value.num[0] == 0.25);
    assert_int_equal(s->nnodes, 2);
    assert_string_equal(s->nodes[0].type, "sub");
    assert_int_equal(s->nodes[0].nargs, 2);
    assert_string_equal(s->nodes[0].args[1].port, "b");
    assert_int_equal(s->nodes[0].args[1].loc.line, 4);
    assert_int_equal(s->nodes[0].args[1].loc.col, 27);
    sg_value *v = &s->nodes[1].args[0].val;
    assert_int_equal(v->kind, SG_V_PATH);
    assert_int_equal(v->nparts, 2);
    assert_string_equal(v->parts[1], "out");
    /* resolved: node 0, output 0 */
    assert_int_equal(v->ref, SG_REF_NODE);
    assert_int_equal(v->node, 0);
    assert_int_equal(s->nouts, 1);
    assert_int_equal(s->outs[0].type, IR_T_FLOAT);
    /* order: d before c */
    assert_int_equal(s->order[0], 0);
    assert_int_equal(s->order[1], 1);
    sg_free(p);
    sg_diags_free(&d);
}

static void test_values(void **state)
{
    sg_diags d;
    sg_program *p = load("texture rock { file = \"tex/rock.png\", filter = nearest, "
                         "mip = linear, wrap = mirror, srgb = true }\n"
                         "material m {\n"
                         "  param vec3 tint = vec3(1, 0.5, .25) range 0 2\n"
                         "  param float k = 2\n"
                         "  node a : mul { a = terrain.position.xz, b = -0.5 }\n"
                         "  node s : sample { tex = rock, uv = a.out }\n"
                         "  node t : sample { tex = \"tex/x.png\", uv = vec2(0.5) }\n"
                         "  node p : painted { mask = \"fields\" }\n"
                         "  out albedo = s.rgb\n"
                         "  out float mask = p.out\n"
                         "}\n", &d);
    sg_diags_print(&d, stderr);
    assert_int_equal(d.nerrors, 0);
    assert_int_equal(p->ntextures, 1);
    sg_texdecl *t = p->textures[0];
    assert_string_equal(t->file, "tex/rock.png");
    assert_int_equal(t->filter, IR_FILTER_NEAREST);
    assert_int_equal(t->mip, IR_FILTER_LINEAR);
    assert_int_equal(t->wrap, IR_WRAP_MIRROR);
    assert_true(t->srgb);
    sg_shader *m = p->shaders[0];
    assert_true(m->is_material);
    assert_int_equal(m->nparams, 2);
    assert_int_equal(m->params[0].type, IR_T_VEC3);
    assert_int_equal(m->params[0].value.kind, SG_V_VEC);
    assert_true(m->params[0].value.num[2] == 0.25);
    assert_true(m->params[0].has_range && m->params[0].hi == 2);
    assert_false(m->params[1].has_range);
    sg_value *pos = &m->nodes[0].args[0].val;
    assert_int_equal(pos->ref, SG_REF_INPUT);
    assert_int_equal(pos->index, IR_IN_POSITION);
    assert_string_equal(pos->swizzle, "xz");
    assert_int_equal(pos->type, IR_T_VEC2);
    assert_true(m->nodes[0].args[1].val.num[0] == -0.5);
    assert_int_equal(m->nodes[1].args[0].val.ref, SG_REF_TEXTURE);
    assert_int_equal(m->nodes[2].args[0].val.kind, SG_V_STRING);
    assert_int_equal(m->nodes[2].args[1].val.kind, SG_V_VEC);
    assert_true(m->nodes[2].args[1].val.num[1] == 0.5);  /* vec2(0.5) splats */
    assert_int_equal(m->nodes[3].kind, SG_NODE_PAINTED);
    /* `s.rgb` is `s.out.rgb` */
    assert_int_equal(m->outs[0].value.type, IR_T_VEC3);
    assert_string_equal(m->outs[0].value.swizzle, "rgb");
    assert_int_equal(m->outs[0].output, SG_OUT_ALBEDO);
    sg_free(p);
    sg_diags_free(&d);
}

static void test_scene(void **state)
{
    sg_diags d;
    sg_program *p = load("shader linear_alpha { in float T in float m in float h = 0\n"
                         "  node w : mul { a = T, b = m }\n"
                         "  out float weight = w.out  out float T_next = w.out }\n"
                         "material grass { }\n"
                         "material cliff { }\n"
                         "scene colorado {\n"
                         "  heightfield = \"hf/trinidad.r16\"\n"
                         "  heightfield_size = 2401 1201\n"
                         "  size = 176500 111200\n"
                         "  max_height = 2962.24\n"
                         "  height_offset = 1358.65\n"
                         "  materials = [grass, cliff]\n"
                         "  compositor = linear_alpha\n"
                         "  painted fields = \"masks/fields.png\"\n"
                         "  destruction { origin = 10 20, size = 2048 1024, cell = 8 }\n"
                         "  cell = 16\n"
                         "  camera overview { position = 1000 3000 1000, look = 5000 2000 5000 }\n"
                         "}\n", &d);
    sg_diags_print(&d, stderr);
    assert_int_equal(d.nerrors, 0);
    const sg_scene *sc = sg_program_scene(p);
    assert_non_null(sc);
    assert_string_equal(sc->name, "colorado");
    assert_string_equal(sc->heightfield, "hf/trinidad.r16");
    assert_int_equal(sc->hf_format, SG_HF_R16);
    assert_int_equal(sc->hf_width, 2401);
    assert_int_equal(sc->hf_height, 1201);
    assert_true(sc->size[0] == 176500 && sc->size[1] == 111200);
    assert_true(sc->max_height == 2962.24 && sc->height_offset == 1358.65);
    assert_int_equal(sc->nmaterials, 2);
    assert_string_equal(sc->materials[1], "cliff");
    assert_int_equal(sc->material_locs[1].line, 12);
    assert_int_equal(sc->material_locs[1].col, 23);
    assert_int_equal(sc->npainted, 1);
    assert_string_equal(sc->painted[0].file, "masks/fields.png");
    assert_true(sc->has_destruction);
    assert_true(sc->destruction_origin[1] == 20 && sc->destruction_size[0] == 2048);
    assert_true(sc->destruction_cell == 8);
    assert_int_equal(sc->cell_texels, 16);
    assert_int_equal(sc->ncameras, 1);
    assert_true(sc->cameras[0].look[1] == 2000);
    sg_free(p);
    sg_diags_free(&d);

    /* missing pieces and bad values: MISSING_SETTING and SETTING errors (and the
     * default compositor, not imported, UNDECLARED) */
    p = load("scene s { size = 0 10 }\n", &d);
    assert_true(d.nerrors >= 4);   /* size <= 0, no heightfield, max_height, materials */
    int bad = 0, missing = 0, undeclared = 0;
    for (int i = 0; i < d.n; i++) {
        bad += d.items[i].id == SG_E_SETTING;
        missing += d.items[i].id == SG_E_MISSING_SETTING;
        undeclared += d.items[i].id == SG_E_UNDECLARED;   /* no compositor imported */
    }
    assert_int_equal(bad + missing + undeclared, d.nerrors);
    assert_true(bad >= 1 && missing >= 3);   /* the size; the rest missing */
    sg_free(p);
    sg_diags_free(&d);
}

static void test_recovery(void **state)
{
    sg_diags d;
    sg_program *p = load("material m {\n"
                         "    node a : add { a = 1, b = }\n"      /* 2: value missing */
                         "    node b : sub { a = 1 b = 2 }\n"     /* fine: commas optional */
                         "    nod c : mul\n"                       /* 4: not a statement */
                         "    param float k 2\n"                   /* 5: '=' missing */
                         "    out mask = b.out\n"
                         "}\n"
                         "shadr x { }\n"                           /* 8: not a declaration */
                         "shader y { in flot v }\n",               /* 9: bad type */
                         &d);
    assert_diag(&d, 0, SG_E_SYNTAX, 2, 31);
    assert_string_equal(d.items[0].msg,
                        "expected a value (number, vecN(...), string or name), found '}'");
    assert_diag(&d, 1, SG_E_SYNTAX, 4, 5);
    assert_string_equal(d.items[1].msg, "expected 'param', 'node', 'out', 'undergrowth' or '}', found 'nod'");
    assert_diag(&d, 2, SG_E_SYNTAX, 5, 19);
    assert_diag(&d, 3, SG_E_SYNTAX, 8, 1);
    assert_diag(&d, 4, SG_E_SYNTAX, 9, 15);
    assert_string_equal(d.items[4].msg,
                        "expected a type (float, vec2, vec3, vec4 or texture), found 'flot'");
    /* the statements around the errors were kept */
    assert_int_equal(p->shaders[0]->nnodes, 2);
    assert_int_equal(p->shaders[0]->nouts, 1);
    sg_free(p);
    sg_diags_free(&d);
}

static void test_unterminated(void **state)
{
    sg_diags d;
    /* a block left open before the next declaration */
    sg_program *p = load("shader a {\n  in float x\n\nmaterial b { out mask = 1 }\n", &d);
    assert_int_equal(d.nerrors, 1);
    assert_diag(&d, 0, SG_E_UNTERMINATED, 1, 10);
    assert_string_equal(d.items[0].msg, "unterminated block of shader 'a' (opened at line 1)");
    assert_int_equal(sg_material_count(p), 1);     /* b still parsed */
    sg_free(p);
    sg_diags_free(&d);

    /* at the end of the file, inside a node's inputs */
    p = load("material m {\n  node n : add {\n    a = 1,\n", &d);
    assert_diag(&d, 0, SG_E_UNTERMINATED, 2, 16);
    assert_string_equal(d.items[0].msg, "unterminated '{' of node 'n' (opened at line 2)");
    assert_diag(&d, 1, SG_E_UNTERMINATED, 1, 12);
    sg_free(p);
    sg_diags_free(&d);
}

static void test_empty_and_truncated(void **state)
{
    sg_diags d;
    sg_program *p = load("", &d);
    assert_int_equal(d.nerrors, 1);
    assert_diag(&d, 0, SG_E_SYNTAX, 1, 1);
    assert_string_equal(d.items[0].msg, "expected a declaration (import, texture, shader, "
                                        "material or scene), found end of file");
    sg_free(p);
    sg_diags_free(&d);

    /* every prefix of a good file parses without crashing; the proper
     * prefixes that cut a declaration are errors */
    const char *good = "import \"x.sg\"\nshader s { in float x = 1 node n : add "
                       "{ a = x, b = vec2(1, 2).x } out float o = n.out }\n";
    size_t n = strlen(good);
    char *buf = malloc(n + 1);
    for (size_t k = 1; k < n; k++) {
        memcpy(buf, good, k);
        buf[k] = 0;
        p = load(buf, &d);
        assert_true(d.nerrors >= 1);
        sg_free(p);
        sg_diags_free(&d);
    }
    free(buf);
}

static void test_imports(void **state)
{
    char dir[] = "/tmp/splat_parse_XXXXXX";
    assert_non_null(mkdtemp(dir));
    char path[256];
    struct { const char *name, *text; } files[] = {
        { "main.sg", "import \"lib/a.sg\"\nimport \"lib/b.sg\"\nmaterial m { node r : fa { } out mask = r.out }\n" },
        { "lib/a.sg", "import \"b.sg\"\nshader fa { node t : fb { } out float out = t.out }\n" },
        { "lib/b.sg", "shader fb { node s : terrain.slope out float out = s.out }\n" },
        { "cyc1.sg", "import \"cyc2.sg\"\n" },
        { "cyc2.sg", "import \"cyc1.sg\"\n" },
        { "miss.sg", "\n  import \"nowhere.sg\"\n" },
    };
    snprintf(path, sizeof path, "%s/lib", dir);
    assert_int_equal(mkdir(path, 0777), 0);
    for (size_t i = 0; i < sizeof files / sizeof files[0]; i++) {
        snprintf(path, sizeof path, "%s/%s", dir, files[i].name);
        FILE *f = fopen(path, "w");
        fputs(files[i].text, f);
        fclose(f);
    }
    sg_diags d;
    sg_diags_init(&d);
    snprintf(path, sizeof path, "%s/main.sg", dir);
    sg_program *p = sg_load(path, NULL, &d);
    sg_diags_print(&d, stderr);
    assert_int_equal(d.nerrors, 0);
    assert_int_equal(sg_file_count(p), 3);       /* b.sg once (diamond) */
    snprintf(path, sizeof path, "%s/lib/b.sg", dir);
    assert_string_equal(sg_file_path(p, 2), path);
    sg_free(p);
    sg_diags_free(&d);

    sg_diags_init(&d);
    snprintf(path, sizeof path, "%s/cyc1.sg", dir);
    p = sg_load(path, NULL, &d);
    assert_int_equal(d.nerrors, 1);
    assert_int_equal(d.items[0].id, SG_E_IMPORT_CYCLE);
    assert_int_equal(d.items[0].loc.line, 1);
    assert_int_equal(d.items[0].loc.col, 8);
    assert_non_null(strstr(d.items[0].msg, "cyc1.sg -> "));
    assert_non_null(strstr(d.items[0].msg, "cyc2.sg -> "));
    sg_free(p);
    sg_diags_free(&d);

    sg_diags_init(&d);
    snprintf(path, sizeof path, "%s/miss.sg", dir);
    p = sg_load(path, NULL, &d);
    assert_int_equal(d.nerrors, 1);
    assert_int_equal(d.items[0].id, SG_E_MISSING_IMPORT);
    assert_int_equal(d.items[0].loc.line, 2);
    assert_int_equal(d.items[0].loc.col, 10);
    sg_free(p);
    sg_diags_free(&d);

    /* an unreadable root file is an IO error */
    sg_diags_init(&d);
    snprintf(path, sizeof path, "%s/none.sg", dir);
    p = sg_load(path, NULL, &d);
    assert_int_equal(d.nerrors, 1);
    assert_int_equal(d.items[0].id, SG_E_IO);
    sg_free(p);
    sg_diags_free(&d);

    const char *rm[] = { "main.sg", "lib/a.sg", "lib/b.sg", "cyc1.sg", "cyc2.sg", "miss.sg", "lib", "" };
    for (size_t i = 0; i < sizeof rm / sizeof rm[0]; i++) {
        snprintf(path, sizeof path, "%s/%s", dir, rm[i]);
        remove(path);
    }
}

/* Undergrowth blocks through the public API: settings, defaults per mesh,
 * OBJ paths relative to the declaring file, source order. */
static void test_undergrowth(void **state)
{
    char dir[] = "/tmp/splat_parse_XXXXXX";
    assert_non_null(mkdtemp(dir));
    char path[256], obj[256];
    snprintf(path, sizeof path, "%s/rocks", dir);
    assert_int_equal(mkdir(path, 0777), 0);
    snprintf(obj, sizeof obj, "%s/rocks/r.obj", dir);
    FILE *f = fopen(obj, "w");
    fputs("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", f);
    fclose(f);
    snprintf(path, sizeof path, "%s/m.sg", dir);
    sg_diags d;
    sg_diags_init(&d);
    sg_program *p = sg_load_string(path,
        "material bare { out mask = 1 }\n"
        "material m {\n"
        "    undergrowth grass { density = 2.0, scale = 0.6 1.2, align = normal, blend = 0.6, color = vec3(0.20, 0.32, 0.08) }\n"
        "    undergrowth \"rocks/r.obj\" { density = 0.05 }\n"
        "    out mask = 1\n"
        "    undergrowth stone { scale = 2\n"
        "        align = upright }\n"
        "    undergrowth plant\n"
        "}\n", NULL, &d);
    sg_diags_print(&d, stderr);
    assert_int_equal(d.nerrors, 0);
    assert_int_equal(sg_undergrowth_count(p, sg_material_find(p, "bare")), 0);
    int m = sg_material_find(p, "m");
    assert_int_equal(sg_undergrowth_count(p, m), 4);

    const sg_undergrowth *u = sg_undergrowth_get(p, m, 0);
    assert_string_equal(u->mesh, "grass");
    assert_null(u->obj);
    assert_true(u->density == 2.0 && u->scale[0] == 0.6 && u->scale[1] == 1.2);
    assert_true(u->align_normal && u->blend == 0.6);
    assert_true(u->color[0] == 0.20 && u->color[1] == 0.32 && u->color[2] == 0.08);
    assert_string_equal(u->loc.file, path);
    assert_int_equal(u->loc.line, 3);
    assert_int_equal(u->loc.col, 5);

    u = sg_undergrowth_get(p, m, 1);             /* defaults; OBJ grey */
    assert_null(u->mesh);
    assert_string_equal(u->obj, obj);
    assert_true(u->density == 0.05 && u->scale[0] == 1 && u->scale[1] == 1);
    assert_true(!u->align_normal && u->blend == 0.5);
    assert_true(u->color[0] == 0.5 && u->color[1] == 0.5 && u->color[2] == 0.5);

    u = sg_undergrowth_get(p, m, 2);             /* one scale: lo = hi */
    assert_string_equal(u->mesh, "stone");
    assert_true(u->density == 1 && u->scale[0] == 2 && u->scale[1] == 2);
    assert_true(u->color[0] == 0.35 && u->color[1] == 0.33 && u->color[2] == 0.30);
    u = sg_undergrowth_get(p, m, 3);
    assert_string_equal(u->mesh, "plant");
    assert_true(u->color[0] == 0.12 && u->color[1] == 0.26 && u->color[2] == 0.05);
    sg_free(p);
    sg_diags_free(&d);

    /* 17 materials with undergrowth: the 17th is over the limit */
    size_t cap = 4096, n = 0;
    char *text = malloc(cap);
    for (int i = 0; i < 17; i++)
        n += (size_t)snprintf(text + n, cap - n, "material m%d { undergrowth grass }\n", i);
    sg_diags_init(&d);
    p = sg_load_string("many.sg", text, NULL, &d);
    assert_int_equal(d.nerrors, 1);
    assert_int_equal(d.items[0].id, SG_E_OVER_LIMIT);
    assert_int_equal(d.items[0].loc.line, 17);
    sg_free(p);
    sg_diags_free(&d);
    free(text);
    snprintf(path, sizeof path, "rm -rf '%s'", dir);
    assert_int_equal(system(path), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_shader_ast),
        cmocka_unit_test(test_values),
        cmocka_unit_test(test_scene),
        cmocka_unit_test(test_recovery),
        cmocka_unit_test(test_unterminated),
        cmocka_unit_test(test_empty_and_truncated),
        cmocka_unit_test(test_imports),
        cmocka_unit_test(test_undergrowth),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
