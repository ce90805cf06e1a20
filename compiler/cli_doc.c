/* cli_doc.c — `splatc doc [-o FILE]`: the language reference
 * (docs/language.md) written from the compiler's own tables, so it cannot
 * leave anything out: the statements, every built-in op of the IR op table
 * with its ports, types and GLSL, every terrain and view input of
 * IR_INPUTS with its type and range, the material outputs (SG_OUTPUTS)
 * and their defaults, the scene and light keys (splat_light_keys), texture
 * settings, and every shader of the node library (the .sg files of nodes/, as the
 * installed or built splatc finds it) with its ports and its comment.
 * The test docs.language compares the file with this output.
 */
#include "cli.h"
#include "abi.h"
#include "ir.h"
#include "scene_load.h"
#include "sg_internal.h"
#include "util.h"

#include <dirent.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char intro[] =
    "# The splatc language reference\n"
    "\n"
    "<!-- Written by `splatc doc -o docs/language.md` from the compiler's own\n"
    "     tables; the test docs.language fails when it is out of date.  Edit\n"
    "     compiler/cli_doc.c (or the tables), not this file. -->\n"
    "\n"
    "A graph file (`.sg`) holds `import`s, `texture`s, `shader`s, `material`s\n"
    "and at most one `scene`.  `#` starts a comment.  Start with\n"
    "[getting-started.md](getting-started.md).\n"
    "\n"
    "## Statements\n"
    "\n"
    "| statement | meaning |\n"
    "|---|---|\n"
    "| `import \"nodes/masks.sg\"` | another graph file: next to this one, then in `-I` folders, `SPLATC_PATH`, the current folder, the project root, the node library |\n"
    "| `texture NAME { file = \"f.png\", filter = …, mip = …, wrap = …, srgb = … }` | a texture and its sampler (below); a string on a texture port is one with the defaults |\n"
    "| `shader NAME { in TYPE x [= default] … node … out TYPE y = value … }` | a reusable graph, instantiated as a node type |\n"
    "| `material NAME { param TYPE p = v [range lo hi] … node … out OUTPUT = value … }` | a terrain layer; outputs below; params can be set at run time within their range |\n"
    "| `node NAME : TYPE { port = value, … }` | a built-in op, a terrain input (`terrain.slope`), `painted { mask = \"NAME\" }` or a shader |\n"
    "| `undergrowth MESH { density = …, scale = LO HI, align = normal, blend = …, root_blend = …, color = vec3(…), lighting = terrain, cutout = frond, texture = \"…\", wind = …, wind_dir = X Z, gust = …, shadow = … }` | (materials) instanced meshes: grass, plant, stone or an OBJ file |\n"
    "| `scene NAME { … }` | the heightfield, the material stack and the rest (keys below) |\n"
    "\n"
    "Values: numbers, `vec2(…)` to `vec4(…)`, strings (texture files, painted\n"
    "mask names), and names: a node (`n` or `n.out`, `n.port`), an input or\n"
    "param, a texture, a terrain input; any of them with a swizzle (`.xz`,\n"
    "`.rgb`).  Types: float, vec2, vec3, vec4, texture.  A float operand of a\n"
    "componentwise op is splatted to the others' width.\n";

/* "float → float; vec2 → vec2 …": for each width, the result of operands
 * of that width (a texture for `tex`, a vec2 for `uv`), where the op's
 * type rule takes them. */
static void types_of(const ir_opinfo *in, char *buf, size_t n)
{
    size_t o = 0;
    buf[0] = 0;
    int na = in->nargs > 4 ? 4 : in->nargs;
    char last[128] = "";
    for (int w = 1; w <= 4; w++) {
        ir_type args[4];
        char ops[96] = "";
        size_t k = 0;
        for (int i = 0; i < na && k < sizeof ops; i++) {
            args[i] = !strcmp(in->ports[i], "tex") ? IR_T_TEX
                    : !strcmp(in->ports[i], "uv") ? IR_T_VEC2 : ir_type_vec(w);
            k += (size_t)snprintf(ops + k, sizeof ops - k, "%s%s", i ? ", " : "",
                                  ir_type_name(args[i]));
        }
        ir_type r = in->type(args, na);
        if (r == IR_T_ERROR)
            continue;
        char one[128];
        snprintf(one, sizeof one, "%s → %s", ops, ir_type_name(r));
        if (!strcmp(one, last))
            continue;   /* sample: the same for every width */
        snprintf(last, sizeof last, "%s", one);
        if (o < n)
            o += (size_t)snprintf(buf + o, n - o, "%s%s", o ? "; " : "", one);
    }
}

static void ops_table(FILE *out)
{
    fputs("\n## Built-in ops\n\n"
          "Node types of the IR op table (compiler/ir.h IR_OPS).  Operand types: all\n"
          "of one width (a float splats); the result for each width the op takes.\n\n"
          "| op | ports | types | GLSL |\n|---|---|---|---|\n", out);
    for (int op = 0; op < IR_OP_COUNT; op++) {
        const ir_opinfo *in = ir_opinfo_get((ir_op)op);
        if (!in->name)
            continue;
        char ports[96] = "", types[256];
        size_t o = 0;
        for (int i = 0; i < in->nargs && i < 4; i++)
            o += (size_t)snprintf(ports + o, sizeof ports - o, "%s`%s`", i ? ", " : "",
                                  in->ports[i]);
        types_of(in, types, sizeof types);
        char glsl[128];
        snprintf(glsl, sizeof glsl, "%s", in->glsl);
        for (char *c = glsl; *c; c++)
            if (*c == '|')
                *c = '/';
        fprintf(out, "| `%s` | %s | %s | `%s` |\n", in->name, ports, types, glsl);
    }
}

static void fmt_bound(double v, char *buf, size_t n)
{
    if (isinf(v))
        snprintf(buf, n, "%s∞", v < 0 ? "-" : "");
    else
        snprintf(buf, n, "%g", v);
}

static void inputs_table(FILE *out)
{
    fputs("\n## Terrain and view inputs\n\n"
          "Read as node types (`node s : terrain.slope`) or as values\n"
          "(`x = terrain.position.xz`); IR_INPUTS in compiler/ir.h.  The range is every\n"
          "value the input can take (a scene's terrain bounds height and position\n"
          "tighter); `splatc eval --at KEY=…` sets it.  Height, normal and slope\n"
          "read smoothly between the heightfield's texels: the cubic B-spline over\n"
          "them (it never overshoots the texels), the normal Listing 1's cross\n"
          "filter on it, so mask edges follow curves, not the texel grid.\n\n"
          "| input | type | range (per component) | eval key |\n|---|---|---|---|\n", out);
    for (int k = 0; k < IR_IN_COUNT; k++) {
        const ir_input_info *in = ir_input_get((ir_input_kind)k);
        char range[160] = "";
        size_t o = 0;
        for (int c = 0; c < ir_type_width(in->type) && o < sizeof range; c++) {
            char lo[32], hi[32];
            fmt_bound(in->domain[c].lo, lo, sizeof lo);
            fmt_bound(in->domain[c].hi, hi, sizeof hi);
            o += (size_t)snprintf(range + o, sizeof range - o, "%s[%s, %s]", c ? " " : "", lo, hi);
        }
        fprintf(out, "| `%s` | %s | %s | `%s` |\n", in->name, ir_type_name(in->type), range,
                in->key);
    }
    fputs("| `vector.NAME` | float | [0, 1] | — |\n"
          "| `vector.NAME.across` | float | [0, 1] | — |\n\n"
          "`vector.NAME` reads the scene's `spline` or `polygon` NAME (values only, not\n"
          "node types): its mask, 1 within half the width of the curve (inside the\n"
          "polygon) falling to 0 over `falloff` metres; `.across` is the distance from\n"
          "the centre line (the polygon's edge) over half width + falloff, clamped to\n"
          "[0, 1]: 0 on the centre line, 1 at the outer edge of the falloff and beyond,\n"
          "for profiles across a road (tyre tracks, verges).\n", out);
}

static void outputs_table(FILE *out)
{
    static const char *const defaults[SG_OUT_COUNT] = {
        [SG_OUT_MASK] = "1", [SG_OUT_ALBEDO] = "vec3(0.5, 0.5, 0.5)",
        [SG_OUT_NORMAL] = "terrain.normal", [SG_OUT_ROUGHNESS] = "0.8",
        [SG_OUT_HEIGHT] = "0.5",
    };
    static const ir_type types[SG_OUT_COUNT] = {
#define X(id, name, type) type,
        SG_OUTPUTS(X)
#undef X
    };
    fputs("\n## Material outputs\n\n"
          "A material writes any of these (SG_OUTPUTS in compiler/sg.h); the rest\n"
          "take their defaults (a mask of 1 covers everything below).  `mask` is\n"
          "clamped to [0, 1] (`splatc check` warns when it can leave it); `height`\n"
          "drives height-based blending.\n\n"
          "| output | type | default |\n|---|---|---|\n", out);
    for (int k = 0; k < SG_OUT_COUNT; k++)
        fprintf(out, "| `%s` | %s | `%s` |\n", sg_output_names[k], ir_type_name(types[k]),
                defaults[k]);
}

static void settings_tables(FILE *out)
{
    fputs("\n## Texture settings\n\n"
          "| setting | values | default |\n|---|---|---|\n"
          "| `file` | a path, relative to the graph file | (required) |\n", out);
    fputs("| `filter` |", out);
    for (int i = 0; strcmp(ir_filter_name((ir_filter)i), "?"); i++)
        fprintf(out, "%s `%s`", i ? "," : "", ir_filter_name((ir_filter)i));
    fprintf(out, " | `%s` |\n", ir_filter_name(IR_FILTER_LINEAR));
    fputs("| `mip` | the same | `linear` |\n| `wrap` |", out);
    for (int i = 0; strcmp(ir_wrap_name((ir_wrap)i), "?"); i++)
        fprintf(out, "%s `%s`", i ? "," : "", ir_wrap_name((ir_wrap)i));
    fprintf(out, " | `%s` |\n", ir_wrap_name(IR_WRAP_REPEAT));
    fputs("| `srgb` | `true`, `false` | `false` |\n", out);

    fputs("\n## Scene keys\n\n"
          "| key | value |\n|---|---|\n"
          "| `heightfield` | `\"file\"`: a 16-bit (or 8-bit) greyscale PNG, a raw `.r16`/`.raw` (16-bit little-endian, with `heightfield_size`), or any raster GDAL reads (size and origin from its geotransform) |\n"
          "| `heightfield_size` | `W H`: texels of a raw heightfield |\n"
          "| `size` | `X Z`: metres the heightfield covers (east, south) |\n"
          "| `max_height` | metres at the heightfield's white |\n"
          "| `height_offset` | metres added to every height |\n"
          "| `materials` | `[bottom, …, top]`: the stack |\n"
          "| `compositor` | the shader that blends the layers (`linear_alpha`, `height_blend`, `stochastic_select`, `height_softmax`) |\n"
          "| `painted` | `NAME = \"file\" [{ max_level, max_error, near, origin, size }]`: a painted mask; `holes` cuts the terrain |\n"
          "| `spline` | `NAME { points = [x z, x z, …], width = W, falloff = F, profile = smoothstep\\|linear }`: a road through the points (centripetal Catmull-Rom, terrain-local metres; each further `points` adds a curve), read as `vector.NAME` |\n"
          "| `polygon` | `NAME { points = [x z, …], falloff = F, profile = … }`: a decal area (a further `points` ring cuts a hole: even-odd), read as `vector.NAME` |\n"
          "| `cell` | heightfield texels per analysis cell (default 32) |\n"
          "| `destruction` | `{ origin = X Z, size = X Z, cell = C }`: where craters can be made |\n"
          "| `camera` | `NAME { position = X Y Z, look = X Y Z }`: a preset (`overview` is the default view) |\n"
          "| `light` | `{ KEY = …, … }`: keys below |\n", out);

    fputs("\n## Light keys\n\n"
          "splat_light_keys in compiler/abi.h; splatview `--light KEY=…` overrides.\n\n"
          "| key | numbers | range |\n|---|---|---|\n", out);
    for (int k = 0; k < SPLAT_LIGHT_COUNT; k++) {
        char lo[32], hi[32];
        fmt_bound(splat_light_keys[k].lo, lo, sizeof lo);
        fmt_bound(splat_light_keys[k].hi, hi, sizeof hi);
        fprintf(out, "| `%s` | %d | [%s, %s] |\n", splat_light_keys[k].key,
                splat_light_keys[k].n, lo, hi);
    }
    /* the defaults runtime/light.c applies (rt_light_default,
     * rt_light_fog_default): keep in step */
    fputs("\nWithout a key, the runtime's default (runtime/light.c): `sun = 144 21`, "
          "`intensity = 2.9`, `exposure = 0`, no `fog_height` (the same fog at every "
          "height), and a `fog_density` derived from the cameras: 0.375 / D per metre, "
          "where D is the farthest any `camera` preset stands from the point it looks "
          "at, and at least a quarter of the terrain's larger side.  The fog then hides "
          "31 % of the colour (1 - e^-0.375) at D, less nearer; a point d metres away "
          "keeps exp(-density * d) of its colour.  Without presets this is 1.5 / the "
          "larger side.  An explicit `fog_density` is used as given (0: no fog).\n",
          out);
}

static int cmp_str(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

/* The `#` lines right above line `line` of f (sg_doc_comment), with '|'
 * made '/' for the table. */
static void comment_above(const sg_file *f, int line, char *buf, size_t n)
{
    sg_doc_comment(f, line, false, buf, n);
    for (char *c = buf; *c; c++)
        if (*c == '|')
            *c = '/';
}

static bool nodes_tables(FILE *out, const char *data, const char *nodes)
{
    DIR *dir = opendir(nodes);
    if (!dir) {
        fprintf(stderr, "splatc doc: error: cannot read the node library '%s': %s\n", nodes,
                strerror(errno));
        return false;
    }
    char *names[256];
    int n = 0;
    struct dirent *e;
    while ((e = readdir(dir)) && n < 256) {
        size_t len = strlen(e->d_name);
        if (len > 3 && !strcmp(e->d_name + len - 3, ".sg"))
            names[n++] = xstrdup(e->d_name);
    }
    closedir(dir);
    qsort(names, (size_t)n, sizeof *names, cmp_str);
    fputs("\n## The node library\n\n"
          "The shaders of `nodes/` (installed with splatc), by file: `import\n"
          "\"nodes/FILE\"` and use them as node types.  Inputs with a default may be\n"
          "left out.\n", out);
    bool ok = true;
    for (int f = 0; f < n; f++) {
        char *path = splat_path_join(nodes, names[f]);
        sg_diags d;
        sg_diags_init(&d);
        const char *const search[] = { data, NULL };   /* import "nodes/…" */
        sg_program *p = sg_load(path, search, &d);
        if (!p || d.nerrors) {
            sg_diags_print(&d, stderr);
            ok = false;
        } else {
            fprintf(out, "\n### nodes/%s\n\n| shader | inputs | outputs | what |\n"
                    "|---|---|---|---|\n", names[f]);
            for (int i = 0; i < p->nshaders; i++) {
                const sg_shader *s = p->shaders[i];
                if (s->is_material || s->file != 0)
                    continue;   /* this file's own shaders */
                char ins[1024] = "", outs[512] = "", what[1024];
                size_t o = 0;
                for (int k = 0; k < s->nins && o < sizeof ins; k++) {
                    char v[128] = "";
                    if (s->ins[k].has_value)
                        sg_value_text(&s->ins[k].value, v, sizeof v);
                    o += (size_t)snprintf(ins + o, sizeof ins - o, "%s%s `%s`%s%s",
                                          k ? ", " : "", ir_type_name(s->ins[k].type),
                                          s->ins[k].name, *v ? " = " : "", v);
                }
                o = 0;
                for (int k = 0; k < s->nouts && o < sizeof outs; k++)
                    o += (size_t)snprintf(outs + o, sizeof outs - o, "%s%s `%s`", k ? ", " : "",
                                          ir_type_name(s->outs[k].type), s->outs[k].name);
                comment_above(p->files[0], s->loc.line, what, sizeof what);
                fprintf(out, "| `%s` | %s | %s | %s |\n", s->name, ins, outs, what);
            }
        }
        sg_free(p);
        sg_diags_free(&d);
        free(path);
        free(names[f]);
    }
    return ok;
}

int splat_cli_doc(int argc, char **argv)
{
    const char *out_path = NULL;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "-o") && i + 1 < argc) {
            out_path = argv[++i];
        } else if (!strcmp(argv[i], "--help") || !strcmp(argv[i], "-h")) {
            fputs("usage: splatc doc [-o FILE]\n"
                  "  the language reference (docs/language.md) from the compiler's tables\n",
                  stdout);
            return 0;
        } else {
            fprintf(stderr, "splatc doc: unknown argument '%s' (splatc doc --help)\n", argv[i]);
            return 2;
        }
    }
    char *data = splat_data_dir();
    if (!data) {
        fputs("splatc doc: error: no node library (PREFIX/share/splatc/nodes) beside "
              "this splatc\n", stderr);
        return 1;
    }
    char *nodes = splat_path_join(data, "nodes");
    char *buf = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&buf, &len);
    if (!f)
        abort();
    fputs(intro, f);
    ops_table(f);
    inputs_table(f);
    outputs_table(f);
    settings_tables(f);
    bool ok = nodes_tables(f, data, nodes);
    fclose(f);
    free(nodes);
    free(data);
    int st = 0;
    if (!ok) {
        st = 1;
    } else if (!out_path) {
        if (fwrite(buf, 1, len, stdout) != len)
            st = 1;
    } else if (!splat_write_atomic(out_path, buf, len)) {
        fprintf(stderr, "splatc doc: error: cannot write '%s': %s\n", out_path, strerror(errno));
        st = 1;
    }
    free(buf);
    return st;
}
