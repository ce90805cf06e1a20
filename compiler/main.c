/* main.c — the splatc command line.
 *
 *   splatc check FILE... [--json]              parse and type-check
 *   splatc glsl  FILE -m MAT [-o OUT.frag] [--stage fragment|compute]
 *                                              shader of one material
 *   splatc spirv FILE -m MAT -o OUT.spv [--stage …]  the same, compiled and validated
 *   splatc dot   FILE [-m MAT [--expand]] [-o OUT.dot]  Graphviz of the graphs
 *   splatc dump  FILE -m MAT [--after PASS]    the IR in .sg form
 *   splatc eval  FILE -m MAT [--output NAME] [--interval] --at KEY=V,...
 *   splatc build SCENE.sg -o PACK ...          (cli_build.c)
 *   splatc texgen --out DIR ...                (cli_texgen.c)
 *   splatc init DIR                            a starter project (cli_init.c)
 *   splatc doc [-o FILE]                       the language reference (cli_doc.c)
 *   splatc lsp [-I DIR]...                     a language server for editors (lsp.c)
 *
 * Exit status: 0 success, 1 input errors (diagnostics on stderr), 2 usage.
 * Files are written atomically (OUT.tmp-XXXXXX, then rename): on an error
 * nothing is written.  Imports are searched next to the importing file,
 * then in -I folders, $SPLATC_PATH (':'-separated), the current folder and
 * the nearest folder above the input file that has a nodes/ folder (the
 * repository root for files inside it). */
#include "args.h"
#include "cli.h"
#include "ir.h"
#include "scene.h"
#include "sg.h"
#include "shader.h"
#include "spv.h"
#include "texgen.h"
#include "util.h"

#include <errno.h>
#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

enum { EXIT_OK = 0, EXIT_INPUT = 1, EXIT_USAGE = 2 };

static int usage_error(const char *fmt, const char *arg)
{
    fputs("splatc: ", stderr);
    fprintf(stderr, fmt, arg);
    fputs("\n(splatc --help for usage)\n", stderr);
    return EXIT_USAGE;
}

/* ---- options shared by the commands ---------------------------------------- */

typedef struct options {
    const char **files;  int nfiles;
    const char  *material;
    const char  *out;
    const char  *after;
    const char  *output;
    const char  *at;
    const char  *stage;   /* --stage fragment|compute (glsl, spirv) */
    bool         interval;
    bool         json;    /* --json (check): diagnostics as JSON Lines */
    bool         expand;  /* --expand (dot): draw the instanced shaders' insides */
    const char **include; int ninclude;
} options;

/* The commands that parse `options`: a row's `only` bits (args.h). */
enum { C_CHECK = 1, C_GLSL = 2, C_SPIRV = 4, C_DOT = 8, C_DUMP = 16, C_EVAL = 32 };
static const char *const command_bits[] = { "check", "glsl", "spirv", "dot", "dump", "eval" };

/* -I and the files go into arrays of argc entries (options_new). */
static bool add_include(const char *v, void *o_, splat_arg_why *why)
{
    options *o = o_;
    (void)why;
    o->include[o->ninclude++] = v;
    return true;
}

static bool add_file(const char *word, void *o_, splat_arg_why *why)
{
    options *o = o_;
    (void)why;
    o->files[o->nfiles++] = word;
    return true;
}

/* The commands' options: one row each; `splatc --help` and README.md's
 * list print this table (docs.options checks the README). */
#define F(field) offsetof(options, field)
static const splat_arg option_rows[] = {
    { "-m", SPLAT_ARG_STRING, "MATERIAL", "the material", F(material),
      .only = C_GLSL | C_SPIRV | C_DOT | C_DUMP | C_EVAL },
    { "-o", SPLAT_ARG_STRING, "OUT", "the file to write (atomically; default stdout, spirv "
      "needs it)", F(out), .only = C_GLSL | C_SPIRV | C_DOT | C_DUMP },
    { "--stage", SPLAT_ARG_STRING, "fragment|compute", "the fragment shader (default) or the "
      "compute variant of screen-space shading; both sample with the compiler's derivatives",
      F(stage), .only = C_GLSL | C_SPIRV },
    { "--expand", SPLAT_ARG_FLAG, NULL, "draw the inside of every shader node too (with -m each "
      "is one box naming its type and wired ports)",
      F(expand), .only = C_DOT },
    { "--after", SPLAT_ARG_STRING, "PASS", "the IR after PASS instead of after the whole "
      "pipeline (lower: no pass)", F(after), .only = C_DUMP },
    { "--at", SPLAT_ARG_STRING, "KEY=V,...", "the inputs; keys: height=H slope=S "
      "normal=X,Y,Z position=X,Z uv=U,V distance=D destruction=D painted.NAME=V "
      "direction=X,Y,Z (unit, to the camera) PARAM=V... (unset: 0, normal and direction "
      "0,1,0, the params' defaults)", F(at), .only = C_EVAL },
    { "--output", SPLAT_ARG_STRING, "NAME", "one output (mask, albedo, normal, roughness, "
      "height) instead of all", F(output), .only = C_EVAL },
    { "--interval", SPLAT_ARG_FLAG, NULL, "the --at keys take LO:HI ranges; prints sound "
      "bounds (unset: slope 0:1, normal -1:1,0:1,-1:1, uv 0:1, distance 0:inf, others "
      "unbounded; direction is always -1:1)", F(interval), .only = C_EVAL },
    { "--json", SPLAT_ARG_FLAG, NULL, "the diagnostics as JSON Lines, for editors", F(json),
      .only = C_CHECK },
    { "-I", SPLAT_ARG_CUSTOM, "DIR", "also search DIR for imports (repeatable; "
      "SPLATC_PATH=DIR:DIR... in the environment does the same); may come before the command",
      .parse = add_include },
};
#undef F

static splat_args_desc options_desc(unsigned command)
{
    return (splat_args_desc){ .prog = "splatc", .args = option_rows,
                              .nargs = (int)(sizeof option_rows / sizeof option_rows[0]),
                              .column = 24, .command = command, .once = true,
                              .command_names = command_bits, .positional = add_file };
}

/* Parse argv[1..] by the rows `command` takes. */
static int parse_options(int argc, char **argv, unsigned command, options *o)
{
    memset(o, 0, sizeof *o);
    o->files = calloc((size_t)argc + 1, sizeof *o->files);
    o->include = calloc((size_t)argc + 1, sizeof *o->include);
    if (!o->files || !o->include)
        return EXIT_USAGE;
    splat_args_desc d = options_desc(command);
    return splat_args_parse(&d, argc, argv, 1, o) ? EXIT_USAGE : EXIT_OK;
}

static void options_free(options *o)
{
    free(o->files);
    free(o->include);
}

/* ---- loading ---------------------------------------------------------------- */

/* Load and check one file; diagnostics to stderr.  NULL on errors. */
static sg_program *load(const char *file, const options *o, sg_diags *d)
{
    char **paths = splat_search_path(o->include, o->ninclude, file);
    sg_program *p = sg_load(file, (const char *const *)paths, d);
    splat_search_path_free(paths);
    sg_diags_print(d, stderr);
    if (!p || d->nerrors) {
        sg_free(p);
        return NULL;
    }
    return p;
}

/* Load FILE and lower material -m into `ir`.  Returns an exit status. */
static int load_material(const options *o, const char *cmd, ir *ir, sg_program **pp)
{
    if (o->nfiles != 1)
        return usage_error("%s needs exactly one FILE", cmd);
    if (!o->material)
        return usage_error("%s needs -m MATERIAL", cmd);
    sg_diags d;
    sg_diags_init(&d);
    sg_program *p = load(o->files[0], o, &d);
    if (!p) {
        sg_diags_free(&d);
        return EXIT_INPUT;
    }
    if (sg_material_find(p, o->material) < 0) {
        fprintf(stderr, "%s: error: no material '%s' (", o->files[0], o->material);
        if (!sg_material_count(p))
            fputs("the file declares none", stderr);
        sg_suggest sg;
        sg_suggest_init(&sg, o->material);
        for (int i = 0; i < sg_material_count(p); i++) {
            fprintf(stderr, "%s%s", i ? ", " : "materials: ", sg_material_name(p, i));
            sg_suggest_offer(&sg, sg_material_name(p, i));
        }
        fputs(")", stderr);
        if (sg_suggest_best(&sg))
            fprintf(stderr, "; did you mean '%s'?", sg_suggest_best(&sg));
        fputc('\n', stderr);
        sg_free(p);
        sg_diags_free(&d);
        return EXIT_INPUT;
    }
    bool ok = sg_lower_material(p, o->material, ir, &d);
    sg_diags_print(&d, stderr);
    sg_diags_free(&d);
    if (!ok) {
        sg_free(p);
        return EXIT_INPUT;
    }
    *pp = p;
    return EXIT_OK;
}

/* ---- output ------------------------------------------------------------------ */

/* Write `len` bytes to `path` atomically, or to stdout if path is NULL. */
static int write_output(const char *path, const void *data, size_t len)
{
    if (!path) {
        if (fwrite(data, 1, len, stdout) != len || fflush(stdout)) {
            fprintf(stderr, "splatc: error: cannot write to standard output\n");
            return EXIT_INPUT;
        }
        return EXIT_OK;
    }
    if (!splat_write_atomic(path, data, len)) {
        fprintf(stderr, "splatc: error: cannot write '%s': %s\n", path, strerror(errno));
        return EXIT_INPUT;
    }
    return EXIT_OK;
}

/* ---- check ------------------------------------------------------------------- */

static int cmd_check(int argc, char **argv)
{
    options o;
    int st = parse_options(argc, argv, C_CHECK, &o);
    if (st == EXIT_OK && o.nfiles == 0)
        st = usage_error("%s needs at least one FILE", "check");
    /* one list for all the files, so an error in a file that several of
     * them import is printed once */
    sg_diags d;
    sg_diags_init(&d);
    d.unique = true;
    for (int i = 0; st != EXIT_USAGE && i < o.nfiles; i++) {
        int from = d.n, errors = d.nerrors;
        char **paths = splat_search_path(o.include, o.ninclude, o.files[i]);
        sg_program *p = sg_load(o.files[i], (const char *const *)paths, &d);
        splat_search_path_free(paths);
        if (p && d.nerrors == errors)
            sg_check(p, &d);   /* texture files, then the masks' bounds */
        if (o.json)
            sg_diags_print_json_from(&d, from, stderr);
        else
            sg_diags_print_from(&d, from, stderr);
        if (!p || d.nerrors > errors)
            st = EXIT_INPUT;
        sg_free(p);
    }
    if (d.ndropped && o.json)
        fprintf(stderr, "{\"dropped\": %d}\n", d.ndropped);
    else if (d.ndropped)
        fprintf(stderr, "splatc: note: %d more diagnostic%s not shown\n", d.ndropped,
                d.ndropped == 1 ? "" : "s");
    sg_diags_free(&d);
    options_free(&o);
    return st;
}

/* ---- glsl / spirv -------------------------------------------------------------- */

/* --stage: false for fragment (the default), true for compute; -1 if bad. */
static int stage_compute(const options *o)
{
    if (!o->stage || !strcmp(o->stage, "fragment"))
        return 0;
    if (!strcmp(o->stage, "compute"))
        return 1;
    return -1;
}

static int material_glsl(const options *o, const char *cmd, ir_buf *glsl)
{
    if (stage_compute(o) < 0)
        return usage_error("--stage takes 'fragment' or 'compute', not '%s'", o->stage);
    ir ir;
    ir_init(&ir);
    sg_program *p = NULL;
    int st = load_material(o, cmd, &ir, &p);
    if (st == EXIT_OK) {
        ir_optimize(&ir, NULL);
        glsl_material_shader_stage(&ir, o->material, stage_compute(o) == 1, glsl);
    }
    sg_free(p);
    ir_free(&ir);
    return st;
}

static int cmd_glsl(int argc, char **argv)
{
    options o;
    int st = parse_options(argc, argv, C_GLSL, &o);
    ir_buf glsl = { 0 };
    if (st == EXIT_OK)
        st = material_glsl(&o, "glsl", &glsl);
    if (st == EXIT_OK)
        st = write_output(o.out, glsl.s, glsl.len);
    ir_buf_free(&glsl);
    options_free(&o);
    return st;
}

static int cmd_spirv(int argc, char **argv)
{
    options o;
    int st = parse_options(argc, argv, C_SPIRV, &o);
    if (st == EXIT_OK && !o.out)
        st = usage_error("%s needs -o OUT.spv", "spirv");
    ir_buf glsl = { 0 };
    if (st == EXIT_OK)
        st = material_glsl(&o, "spirv", &glsl);
    if (st == EXIT_OK) {
        uint32_t *words = NULL;
        size_t nwords = 0;
        char *log = NULL;
        int stage = stage_compute(&o) == 1 ? SPV_STAGE_COMPUTE : SPV_STAGE_FRAGMENT;
        bool ok = spv_compile(glsl.s, stage, o.material, &words, &nwords, &log) &&
                  spv_validate(words, nwords, &log);
        if (!ok) {
            /* generated code that does not compile is a compiler bug */
            fprintf(stderr, "splatc: %s\n", log ? log : "internal compiler error");
            st = EXIT_INPUT;
        } else if (!spv_write_file(o.out, words, nwords)) {
            fprintf(stderr, "splatc: error: cannot write '%s': %s\n", o.out, strerror(errno));
            st = EXIT_INPUT;
        }
        free(words);
        free(log);
    }
    ir_buf_free(&glsl);
    options_free(&o);
    return st;
}

/* ---- dot / dump ------------------------------------------------------------------ */

/* Run `emit` into a memory stream, then write it out atomically. */
static int emit_to(const char *path, void (*emit)(void *user, FILE *f), void *user)
{
    char *buf = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&buf, &len);
    if (!f)
        abort();
    emit(user, f);
    fclose(f);
    int st = write_output(path, buf, len);
    free(buf);
    return st;
}

typedef struct dot_job { sg_program *p; const char *material; bool expand; } dot_job;
static void emit_dot(void *user, FILE *f)
{
    dot_job *j = user;
    sg_write_dot(j->p, j->material, j->expand, f);
}

static int cmd_dot(int argc, char **argv)
{
    options o;
    int st = parse_options(argc, argv, C_DOT, &o);
    if (st == EXIT_OK && o.nfiles != 1)
        st = usage_error("%s needs exactly one FILE", "dot");
    if (st == EXIT_OK) {
        sg_diags d;
        sg_diags_init(&d);
        sg_program *p = load(o.files[0], &o, &d);
        if (!p) {
            st = EXIT_INPUT;
        } else if (o.material && sg_material_find(p, o.material) < 0) {
            fprintf(stderr, "%s: error: no material '%s'\n", o.files[0], o.material);
            st = EXIT_INPUT;
        } else {
            dot_job j = { p, o.material, o.expand };
            st = emit_to(o.out, emit_dot, &j);
        }
        sg_free(p);
        sg_diags_free(&d);
    }
    options_free(&o);
    return st;
}

static void emit_dump(void *user, FILE *f)
{
    ir_dump(user, f);
}

/* Texture files are relative to the current folder in the IR; a dump
 * written to OUT names them relative to OUT's folder, as graph files do,
 * so the dump reads back from wherever it is. */
static void textures_relative_to(ir *ir, const char *out)
{
    char *abs_out = splat_path_absolute(out);
    char *slash = strrchr(abs_out, '/');
    if (slash == abs_out)
        slash[1] = 0;
    else if (slash)
        *slash = 0;
    for (int i = 0; i < ir->ntextures; i++) {
        char *abs_tex = splat_path_absolute(ir->textures[i].file);
        free(ir->textures[i].file);
        ir->textures[i].file = splat_path_relative(abs_out, abs_tex);
        free(abs_tex);
    }
    free(abs_out);
}

static int cmd_dump(int argc, char **argv)
{
    options o;
    int st = parse_options(argc, argv, C_DUMP, &o);
    if (st == EXIT_OK && o.after && strcmp(o.after, "lower")) {
        bool known = false;
        for (const ir_pass *ps = ir_passes; ps->name; ps++)
            known |= ps->pipeline && !strcmp(ps->name, o.after);
        if (!known) {
            fprintf(stderr, "splatc: unknown pass '%s'; passes: lower", o.after);
            for (const ir_pass *ps = ir_passes; ps->name; ps++)
                if (ps->pipeline)
                    fprintf(stderr, " %s", ps->name);
            fputc('\n', stderr);
            st = EXIT_USAGE;
        }
    }
    ir ir;
    ir_init(&ir);
    sg_program *p = NULL;
    if (st == EXIT_OK)
        st = load_material(&o, "dump", &ir, &p);
    if (st == EXIT_OK) {
        if (!o.after || strcmp(o.after, "lower"))
            ir_optimize(&ir, o.after);
        if (o.out)
            textures_relative_to(&ir, o.out);
        st = emit_to(o.out, emit_dump, &ir);
    }
    sg_free(p);
    ir_free(&ir);
    options_free(&o);
    return st;
}

/* ---- eval ---------------------------------------------------------------------- */

/* One `KEY=V,V,...` item of --at, values as intervals (a plain V is V:V). */
typedef struct at_item {
    char  *key;
    ir_iv  v[4];
    int    n;
} at_item;

static bool parse_bound(const char *s, double *x)
{
    char *end;
    if (!strcmp(s, "inf") || !strcmp(s, "+inf")) {
        *x = INFINITY;
        return true;
    }
    if (!strcmp(s, "-inf")) {
        *x = -INFINITY;
        return true;
    }
    errno = 0;
    *x = strtod(s, &end);
    return *s && !*end && !errno && isfinite(*x);
}

/* "height=1,normal=0,1,0,slope=0:0.5" -> items.  A value without '=' adds
 * a component to the previous key. */
static bool parse_at(const char *spec, bool ranges, at_item **items, int *n)
{
    char *copy = xstrdup(spec);
    *items = NULL;
    *n = 0;
    bool ok = true;
    char *save = NULL;
    for (char *t = strtok_r(copy, ",", &save); t && ok; t = strtok_r(NULL, ",", &save)) {
        char *eq = strchr(t, '=');
        if (eq) {
            *items = realloc(*items, (size_t)(*n + 1) * sizeof **items);
            if (!*items)
                abort();
            at_item *it = &(*items)[(*n)++];
            *eq = 0;
            it->key = strdup(t);
            it->n = 0;
            t = eq + 1;
        } else if (*n == 0) {
            ok = false;
            break;
        }
        at_item *it = &(*items)[*n - 1];
        if (it->n == 4) {
            ok = false;
            break;
        }
        char *colon = strchr(t, ':');
        if (colon && !ranges) {
            ok = false;
            break;
        }
        if (colon) {
            *colon = 0;
            ok = parse_bound(t, &it->v[it->n].lo) && parse_bound(colon + 1, &it->v[it->n].hi) &&
                 it->v[it->n].lo <= it->v[it->n].hi;
        } else {
            ok = parse_bound(t, &it->v[it->n].lo);
            it->v[it->n].hi = it->v[it->n].lo;
        }
        it->n++;
    }
    free(copy);
    return ok;
}

/* Shortest text that reads back as the same double. */
static void print_double(FILE *f, double x)
{
    char buf[40];
    for (int prec = 15; prec <= 17; prec++) {
        snprintf(buf, sizeof buf, "%.*g", prec, x);
        if (strtod(buf, NULL) == x || isnan(x))
            break;
    }
    fputs(buf, f);
}

typedef struct eval_inputs {
    ir_env   env;
    ir_ienv  ienv;
    double  *params;    /* 4 per param */
    ir_iv   *iparams;
    double  *painted;
    ir_iv   *ipainted;
} eval_inputs;

static int set_inputs(const ir *ir, const char *material, const at_item *items, int n,
                      eval_inputs *in)
{
    memset(in, 0, sizeof *in);
    ir_env *e = &in->env;
    ir_ienv *ie = &in->ienv;
    e->normal[1] = 1;                 /* flat ground until told */
    ir_ienv_domain(ie);               /* every input anywhere in its domain */
    const ir_iv unit = { 0, 1 };
    in->params = calloc((size_t)ir->nparams * 4 + 1, sizeof *in->params);
    in->iparams = calloc((size_t)ir->nparams + 1, sizeof *in->iparams);
    in->painted = calloc((size_t)ir->npainted + 1, sizeof *in->painted);
    in->ipainted = calloc((size_t)ir->npainted + 1, sizeof *in->ipainted);
    if (!in->params || !in->iparams || !in->painted || !in->ipainted)
        abort();
    for (int i = 0; i < ir->nparams; i++) {
        memcpy(&in->params[4 * i], ir->params[i].def, sizeof ir->params[i].def);
        in->iparams[i] = (ir_iv){ ir->params[i].lo, ir->params[i].hi };
    }
    for (int i = 0; i < ir->npainted; i++)
        in->ipainted[i] = unit;
    bool have_height = false, have_pos = false;
    for (int i = 0; i < n; i++) {
        const at_item *it = &items[i];
        const char *k = it->key;
        int want = -1;
        ir_iv *iv[4] = { 0 };     /* NULL: no bounds slot (view.direction) */
        double *dv[4] = { 0 };
        int input = -1;
        for (int j = 0; j < IR_IN_COUNT; j++)
            if (!strcmp(k, ir_input_get((ir_input_kind)j)->key))
                input = j;
        if (input >= 0 && input != IR_IN_POSITION) {
            double *d = ir_env_slot(e, (ir_input_kind)input);
            ir_iv *s = ir_ienv_slot(ie, (ir_input_kind)input);
            want = ir_type_width(ir_input_get((ir_input_kind)input)->type);
            for (int c = 0; c < want; c++) {
                dv[c] = d + c;
                iv[c] = s ? s + c : NULL;
            }
            have_height = have_height || input == IR_IN_HEIGHT;
        } else if (input == IR_IN_POSITION) {
            /* X,Z (y is the height) or X,Y,Z */
            want = it->n == 3 ? 3 : 2;
            int map[3] = { 0, 2, 1 };
            if (want == 3) { map[1] = 1; map[2] = 2; }
            for (int c = 0; c < want; c++) {
                iv[c] = &ie->position[map[c]];
                dv[c] = &e->position[map[c]];
            }
            have_pos = want == 3;
        } else if (!strncmp(k, "painted.", 8)) {
            for (int j = 0; j < ir->npainted; j++)
                if (!strcmp(ir->painted[j].name, k + 8)) {
                    want = 1; iv[0] = &in->ipainted[j]; dv[0] = &in->painted[j];
                }
            if (want < 0) {
                fprintf(stderr, "splatc: error: material '%s' reads no painted mask '%s'\n",
                        material, k + 8);
                return EXIT_INPUT;
            }
        } else {
            /* a param: "wetness" or "cliff.wetness" */
            size_t qn = strlen(material) + strlen(k) + 2;
            char *q = xmalloc(qn);
            snprintf(q, qn, "%s.%s", material, k);
            for (int j = 0; j < ir->nparams; j++)
                if (!strcmp(ir->params[j].name, q) || !strcmp(ir->params[j].name, k)) {
                    want = ir_type_width(ir->params[j].type);
                    for (int c = 0; c < want; c++) {
                        dv[c] = &in->params[4 * j + c];
                        iv[c] = c == 0 ? &in->iparams[j] : NULL;
                    }
                }
            free(q);
            if (want < 0) {
                fprintf(stderr, "splatc: error: unknown --at key '%s' (not an input or a "
                        "param of '%s')\n", k, material);
                return EXIT_USAGE;
            }
        }
        if (it->n != want) {
            fprintf(stderr, "splatc: error: --at %s takes %d value%s, found %d\n", k, want,
                    want == 1 ? "" : "s", it->n);
            return EXIT_USAGE;
        }
        for (int c = 0; c < want; c++) {
            *dv[c] = it->v[c].lo;
            if (iv[c])
                *iv[c] = it->v[c];
        }
    }
    if (!have_pos) {              /* position.y follows the height */
        e->position[1] = e->height;
        if (have_height)
            ie->position[1] = ie->height;
    }
    e->params = in->params;
    e->painted = in->painted;
    ie->params = in->iparams;
    ie->painted = in->ipainted;
    return EXIT_OK;
}

static int cmd_eval(int argc, char **argv)
{
    options o;
    int st = parse_options(argc, argv, C_EVAL, &o);
    if (st == EXIT_OK && !o.at)
        st = usage_error("%s needs --at KEY=V,...", "eval");
    at_item *items = NULL;
    int nitems = 0;
    if (st == EXIT_OK && !parse_at(o.at, o.interval, &items, &nitems))
        st = usage_error(o.interval ? "bad --at '%s' (expected KEY=V or KEY=LO:HI, "
                                      "comma-separated)"
                                    : "bad --at '%s' (expected KEY=V,..., comma-separated)",
                         o.at);
    if (st == EXIT_OK && o.output) {
        bool known = false;
        for (int k = 0; k < SG_OUT_COUNT; k++)
            known |= !strcmp(o.output, sg_output_names[k]);
        if (!known)
            st = usage_error("unknown --output '%s' (mask, albedo, normal, roughness, height)",
                             o.output);
    }
    ir ir;
    ir_init(&ir);
    sg_program *p = NULL;
    eval_inputs in = { 0 };
    if (st == EXIT_OK)
        st = load_material(&o, "eval", &ir, &p);
    if (st == EXIT_OK)
        st = set_inputs(&ir, o.material, items, nitems, &in);
    for (int k = 0; st == EXIT_OK && k < SG_OUT_COUNT; k++) {
        if (o.output && strcmp(o.output, sg_output_names[k]))
            continue;
        char root[512];
        snprintf(root, sizeof root, "%s.%s", o.material, sg_output_names[k]);
        ir_ref r = ir_find_root(&ir, root);
        int w = ir_type_width(ir_typeof(&ir, r));
        if (!o.output)
            printf("%s = ", sg_output_names[k]);
        if (o.interval) {
            ir_iv b[4];
            ir_interval(&ir, r, &in.ienv, b);
            for (int c = 0; c < w; c++) {
                printf("%s[", c ? " " : "");
                print_double(stdout, b[c].lo);
                fputs(", ", stdout);
                print_double(stdout, b[c].hi);
                fputs("]", stdout);
            }
        } else {
            double v[4];
            ir_eval(&ir, r, &in.env, v);
            for (int c = 0; c < w; c++) {
                if (c)
                    fputc(' ', stdout);
                print_double(stdout, v[c]);
            }
        }
        fputc('\n', stdout);
    }
    for (int i = 0; i < nitems; i++)
        free(items[i].key);
    free(items);
    free(in.params);
    free(in.iparams);
    free(in.painted);
    free(in.ipainted);
    sg_free(p);
    ir_free(&ir);
    options_free(&o);
    return st;
}

/* ---- dispatch ------------------------------------------------------------------- */

typedef int (*command_fn)(int argc, char **argv);

/* Every subcommand gets argv starting at its own name.  own_help: it
 * answers --help itself; general: -I given before it is passed on. */
static const struct {
    const char *name;
    command_fn  run;
    const char *synopsis, *help;
    bool        own_help, general;
} commands[] = {
    { "check", cmd_check, "splatc check FILE... [--json]", "parse and type-check graph files, their "
      "texture files and their masks' bounds", false, true },
    { "glsl", cmd_glsl, "splatc glsl FILE -m MATERIAL [-o OUT] [--stage fragment|compute]",
      "Vulkan GLSL 450 shader of a material", false, true },
    { "spirv", cmd_spirv, "splatc spirv FILE -m MATERIAL -o OUT.spv [--stage ...]",
      "the same compiled to SPIR-V and validated", false, true },
    { "dot", cmd_dot, "splatc dot FILE [-m MATERIAL [--expand]] [-o OUT]", "Graphviz DOT of the "
      "graphs (dot -Tsvg draws it)", false, true },
    { "dump", cmd_dump, "splatc dump FILE -m MATERIAL [--after PASS]", "the material's IR in .sg "
      "form", false, true },
    { "eval", cmd_eval, "splatc eval FILE -m MATERIAL [--output NAME] [--interval] --at KEY=V,...",
      "the CPU reference value (double precision), or with --interval sound bounds over "
      "ranges", false, true },
    { "build", splat_cli_build, "splatc build SCENE.sg -o PACKDIR [options]", "compile a scene into "
      "a shader pack (splatc build --help)", true, true },
    { "texgen", splat_cli_texgen, "splatc texgen --out DIR [options]", "write the example textures, "
      "their mips and the colour PBR surface sets (splatc texgen --help, docs/textures.md)",
      true, false },
    { "init", splat_cli_init, "splatc init DIR", "a starter project: scene.sg, heightfield.png, "
      "README.md (builds and renders as it stands)", true, false },
    { "doc", splat_cli_doc, "splatc doc [-o FILE]", "the language reference (docs/language.md) from "
      "the compiler's tables and the node library", true, false },
    { "lsp", splat_cli_lsp, "splatc lsp [-I DIR]...", "a Language Server Protocol server on stdin and "
      "stdout, for editors (docs/editors.md)", true, true },
};
enum { NCOMMANDS = sizeof commands / sizeof commands[0] };

/* The commands and their options (base 4: README.md's code block). */
static void print_usage(FILE *f, int base)
{
    if (!base)
        fputs("usage: splatc COMMAND [options]\ncommands:\n", f);
    for (int i = 0; i < NCOMMANDS; i++)
        splat_args_item(f, commands[i].synopsis, commands[i].help, base, 36);
    fprintf(f, "\n%*soptions of the commands above:\n", base, "");
    splat_args_desc d = options_desc(0);
    if (base)
        splat_args_markdown(&d, f);
    else
        splat_args_help(&d, f);
    splat_args_item(f, "--help", "this text (build --help, texgen --help: theirs)", base, 24);
    splat_args_item(f, "--version", "the compiler version", base, 24);
    if (!base)
        fputs("exit status: 0 ok, 1 errors in the input, 2 usage errors\n", f);
}

/* General options may come before the command (`splatc -I DIR check F`):
 * they are moved behind the command's name, where every command that reads
 * graph files takes them (texgen reads none and ignores them). */
int main(int argc, char **argv)
{
    int first = 1;
    while (first < argc && !strcmp(argv[first], "-I")) {
        if (first + 1 >= argc)
            return usage_error("option '%s' needs a value", argv[first]);
        first += 2;
    }
    if (first >= argc)
        return usage_error("%s", "no command given");
    const char *cmd = argv[first];
    if (!strcmp(cmd, "--help") || !strcmp(cmd, "-h") || !strcmp(cmd, "help") ||
        !strcmp(cmd, "--help-markdown")) {
        print_usage(stdout, strcmp(cmd, "--help-markdown") ? 0 : 4);
        return EXIT_OK;
    }
    if (!strcmp(cmd, "--version")) {
        printf("splatc %s\n", SPLATC_VERSION);
        return EXIT_OK;
    }
    for (int i = 0; i < NCOMMANDS; i++)
        if (!strcmp(cmd, commands[i].name)) {
            for (int j = first + 1; j < argc && !commands[i].own_help; j++)
                if (!strcmp(argv[j], "--help")) {
                    print_usage(stdout, 0);
                    return EXIT_OK;
                }
            /* argv for the command: its name, the general options, the rest */
            char **av = calloc((size_t)argc + 1, sizeof *av);
            if (!av)
                return EXIT_USAGE;
            int n = 0;
            av[n++] = argv[first];
            for (int j = 1; commands[i].general && j < first; j++)
                av[n++] = argv[j];
            for (int j = first + 1; j < argc; j++)
                av[n++] = argv[j];
            int st = commands[i].run(n, av);
            free(av);
            return st;
        }
    return usage_error("unknown command '%s'", cmd);
}
