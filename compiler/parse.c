/* parse.c — the .sg parser (tokens -> AST) and program loading (files,
 * imports, then resolve).
 *
 * Recursive descent over the token array, one function per rule with the
 * rule above it.  Newlines are not tokens, but they guide error recovery:
 * after a syntax error the parser skips to the next line (or the `}` that
 * closes the block) and goes on, so one run reports several errors.  A
 * top-level keyword at the start of a line inside a block means the block
 * was never closed: UNTERMINATED, pointing at its `{`.
 *
 * Imports are loaded depth first after the importing file is parsed; a
 * file reached twice (diamond) is parsed once; a file reached while it is
 * still being loaded is an import cycle. */
#include "mesh.h"
#include "sg_internal.h"
#include "util.h"

#include <stb_image.h>

#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

typedef struct parser {
    sg_program *p;
    sg_arena   *a;
    sg_file    *f;
    int         fi;
    sg_diags   *d;
    int         pos;          /* current token                          */
    sg_import **imports;
    int        *nimports;
    int         capimports;
} parser;

static sg_token *cur(parser *ps) { return &ps->f->toks[ps->pos]; }
static sg_token *peek_at(parser *ps, int k)
{
    int i = ps->pos + k;
    return &ps->f->toks[i < ps->f->ntoks ? i : ps->f->ntoks - 1];
}
static sg_token *next(parser *ps)
{
    sg_token *t = cur(ps);
    if (t->kind != SG_TK_EOF)
        ps->pos++;
    return t;
}

static sg_loc loc_of(parser *ps, const sg_token *t)
{
    return (sg_loc){ ps->f->path, t->line, t->col };
}

static bool is_kw(const sg_token *t, const char *kw)
{
    return t->kind == SG_TK_IDENT && (int)strlen(kw) == t->len &&
           !memcmp(t->start, kw, (size_t)t->len);
}

/* First token of its line? */
static bool line_start(parser *ps, const sg_token *t)
{
    int i = (int)(t - ps->f->toks);
    return i == 0 || ps->f->toks[i - 1].line < t->line;
}

static bool top_keyword(const sg_token *t)
{
    return is_kw(t, "import") || is_kw(t, "texture") || is_kw(t, "shader") ||
           is_kw(t, "material") || is_kw(t, "scene");
}

static char *tok_text(parser *ps, const sg_token *t)
{
    return sg_strndup(ps->a, t->start, (size_t)t->len);
}

/* "expected <what>, found <current token>" at the current token. */
static void expected(parser *ps, const char *what)
{
    char buf[96];
    sg_token *t = cur(ps);
    sg_error(ps->d, loc_of(ps, t), SG_E_SYNTAX, what,
             sg_tok_describe(t, buf, sizeof buf));
}

/* "did you mean" for a misspelt setting `key` among `keys` (NULL-ended),
 * on the diagnostic just reported. */
static void hint_key(parser *ps, const sg_token *key, const char *const *keys)
{
    if (key->kind != SG_TK_IDENT)
        return;
    char word[64];
    snprintf(word, sizeof word, "%.*s", key->len, key->start);
    sg_suggest sg;
    sg_suggest_init(&sg, word);
    for (int i = 0; keys[i]; i++)
        sg_suggest_offer(&sg, keys[i]);
    sg_hint_suggest(ps->d, sg_suggest_best(&sg));
}

static bool accept(parser *ps, sg_tok_kind k)
{
    if (cur(ps)->kind != k)
        return false;
    next(ps);
    return true;
}

static bool expect(parser *ps, sg_tok_kind k, const char *what)
{
    if (accept(ps, k))
        return true;
    expected(ps, what);
    return false;
}

/* Skip the rest of a bad statement: up to the next line or the `}` that
 * closes the enclosing block (not consumed); nested braces are skipped. */
static void sync_statement(parser *ps, int line)
{
    int depth = 0;
    for (;;) {
        sg_token *t = cur(ps);
        if (t->kind == SG_TK_EOF)
            return;
        if (depth == 0 && (t->kind == SG_TK_RBRACE || t->line > line))
            return;
        if (t->kind == SG_TK_LBRACE)
            depth++;
        else if (t->kind == SG_TK_RBRACE)
            depth--;
        next(ps);
    }
}

static ir_type type_name(const sg_token *t)
{
    static const char *const names[] = { "float", "vec2", "vec3", "vec4", "texture" };
    static const ir_type types[] = { IR_T_FLOAT, IR_T_VEC2, IR_T_VEC3, IR_T_VEC4, IR_T_TEX };
    for (int i = 0; i < 5; i++)
        if (is_kw(t, names[i]))
            return types[i];
    return IR_T_ERROR;
}

/* path = IDENT { "." IDENT } */
static bool parse_path(parser *ps, sg_value *v)
{
    sg_token *t = cur(ps);
    if (t->kind != SG_TK_IDENT) {
        expected(ps, "a name");
        return false;
    }
    v->kind = SG_V_PATH;
    v->loc = loc_of(ps, t);
    int cap = 0;
    for (;;) {
        char **slot = SG_PUSH(ps->a, v->parts, v->nparts, cap);
        *slot = tok_text(ps, next(ps));
        if (cur(ps)->kind != SG_TK_DOT)
            return true;
        next(ps);
        if (cur(ps)->kind != SG_TK_IDENT) {
            expected(ps, "a name after '.'");
            return false;
        }
    }
}

/* value = NUMBER
 *       | ("vec2" | "vec3" | "vec4") "(" NUMBER { "," NUMBER } ")"
 *       | STRING
 *       | path */
static bool parse_value(parser *ps, sg_value *v)
{
    sg_token *t = cur(ps);
    memset(v, 0, sizeof *v);
    v->loc = loc_of(ps, t);
    if (t->kind == SG_TK_NUMBER) {
        next(ps);
        v->kind = SG_V_NUMBER;
        v->num[0] = t->num;
        v->width = 1;
        return true;
    }
    if (t->kind == SG_TK_STRING) {
        next(ps);
        v->kind = SG_V_STRING;
        v->str = t->str;
        return true;
    }
    ir_type vt = type_name(t);
    if (vt >= IR_T_VEC2 && vt <= IR_T_VEC4 && peek_at(ps, 1)->kind == SG_TK_LPAREN) {
        int w = ir_type_width(vt);
        next(ps);
        sg_token *open = next(ps);
        int n = 0;
        do {
            if (cur(ps)->kind != SG_TK_NUMBER) {
                expected(ps, "a number");
                return false;
            }
            double x = next(ps)->num;
            if (n < 4)
                v->num[n] = x;
            n++;
        } while (accept(ps, SG_TK_COMMA));
        if (cur(ps)->kind != SG_TK_RPAREN) {
            if (cur(ps)->kind == SG_TK_EOF || cur(ps)->line > open->line)
                sg_error(ps->d, loc_of(ps, open), SG_E_UNTERMINATED, "'('", open->line);
            else
                expected(ps, "',' or ')'");
            return false;
        }
        next(ps);
        if (n == 1) {
            for (int i = 1; i < w; i++)
                v->num[i] = v->num[0];
        } else if (n != w) {
            char msg[96];
            snprintf(msg, sizeof msg, "%.*s needs %d components, found %d",
                     t->len, t->start, w, n);
            sg_error(ps->d, v->loc, SG_E_BAD_COMPONENTS, msg);
            return false;
        }
        v->kind = SG_V_VEC;
        v->width = w;
        return true;
    }
    if (t->kind == SG_TK_IDENT)
        return parse_path(ps, v);
    expected(ps, "a value (number, vecN(...), string or name)");
    return false;
}

/* bindings = "{" { IDENT "=" value [","] } "}"
 * `what` names the block for UNTERMINATED ("'{' of node 'd'").  Each
 * binding goes through `add`; a bad one is skipped up to the next ',',
 * line or '}'. */
typedef void (*binding_fn)(parser *ps, void *user, sg_token *key, sg_value *v);

/* A statement keyword starting a line (not a binding `out = …`)? */
static bool starts_statement(parser *ps, const sg_token *t)
{
    return line_start(ps, t) && peek_at(ps, 1)->kind != SG_TK_EQ &&
           (is_kw(t, "node") || is_kw(t, "out") || is_kw(t, "in") || is_kw(t, "param") ||
            is_kw(t, "undergrowth"));
}

/* Returns false if the list had errors (some bindings may be missing). */
static bool parse_bindings(parser *ps, const char *what, binding_fn add, void *user)
{
    sg_token *open = cur(ps);
    bool clean = true;
    if (!expect(ps, SG_TK_LBRACE, "'{'"))
        return false;
    for (;;) {
        sg_token *t = cur(ps);
        if (t->kind == SG_TK_RBRACE) {
            next(ps);
            return clean;
        }
        if (t->kind == SG_TK_EOF || (top_keyword(t) && line_start(ps, t)) ||
            (t->line > open->line && starts_statement(ps, t))) {
            sg_error(ps->d, loc_of(ps, open), SG_E_UNTERMINATED, what, open->line);
            return false;
        }
        int line = t->line;
        sg_value v;
        bool ok = false;
        if (t->kind != SG_TK_IDENT) {
            expected(ps, "a port name or '}'");
        } else {
            next(ps);
            if (expect(ps, SG_TK_EQ, "'='") && parse_value(ps, &v)) {
                add(ps, user, t, &v);
                ok = true;
            }
        }
        if (ok) {
            accept(ps, SG_TK_COMMA);
            continue;
        }
        clean = false;
        /* skip to ',' / '}' / next line */
        while (cur(ps)->kind != SG_TK_EOF && cur(ps)->kind != SG_TK_RBRACE &&
               cur(ps)->kind != SG_TK_COMMA && cur(ps)->line == line)
            next(ps);
        accept(ps, SG_TK_COMMA);
    }
}

/* ---- declarations inside shaders and materials -------------------------- */

static void add_node_binding(parser *ps, void *user, sg_token *key, sg_value *v)
{
    sg_node *n = user;
    sg_binding *b = SG_PUSH(ps->a, n->args, n->nargs, n->capargs);
    b->port = tok_text(ps, key);
    b->loc = loc_of(ps, key);
    b->val = *v;
    b->slot = -1;
}

/* node = "node" IDENT ":" path [ bindings ] */
static bool parse_node(parser *ps, sg_shader *s)
{
    next(ps);
    sg_token *name = cur(ps);
    if (!expect(ps, SG_TK_IDENT, "a node name"))
        return false;
    if (!expect(ps, SG_TK_COLON, "':' and a node type"))
        return false;
    sg_value type;
    memset(&type, 0, sizeof type);
    if (!parse_path(ps, &type))
        return false;
    sg_node *n = SG_PUSH(ps->a, s->nodes, s->nnodes, s->capnodes);
    n->name = tok_text(ps, name);
    n->loc = loc_of(ps, name);
    n->type_loc = type.loc;
    size_t len = 0;
    for (int i = 0; i < type.nparts; i++)
        len += strlen(type.parts[i]) + 1;
    n->type = sg_alloc(ps->a, len);
    for (int i = 0; i < type.nparts; i++) {
        if (i)
            strcat(n->type, ".");
        strcat(n->type, type.parts[i]);
    }
    if (cur(ps)->kind == SG_TK_LBRACE) {
        char what[160];
        snprintf(what, sizeof what, "'{' of node '%s'", n->name);
        n->incomplete = !parse_bindings(ps, sg_strdup(ps->a, what), add_node_binding, n);
    }
    return true;
}

/* in = "in" TYPE IDENT [ "=" value ] */
static bool parse_in(parser *ps, sg_shader *s)
{
    next(ps);
    ir_type t = type_name(cur(ps));
    if (t == IR_T_ERROR) {
        expected(ps, "a type (float, vec2, vec3, vec4 or texture)");
        return false;
    }
    next(ps);
    sg_token *name = cur(ps);
    if (!expect(ps, SG_TK_IDENT, "an input name"))
        return false;
    sg_port port = { .name = tok_text(ps, name), .loc = loc_of(ps, name), .type = t };
    if (accept(ps, SG_TK_EQ)) {
        if (!parse_value(ps, &port.value))
            return false;
        port.has_value = true;
    }
    *SG_PUSH(ps->a, s->ins, s->nins, s->capins) = port;
    return true;
}

/* out = "out" [ TYPE ] IDENT "=" value */
static bool parse_out(parser *ps, sg_shader *s)
{
    next(ps);
    ir_type t = IR_T_ERROR;
    if (type_name(cur(ps)) != IR_T_ERROR && peek_at(ps, 1)->kind == SG_TK_IDENT) {
        t = type_name(cur(ps));
        next(ps);
    } else if (!s->is_material) {
        expected(ps, "an output type (float, vec2, vec3, vec4 or texture)");
        return false;
    }
    sg_token *name = cur(ps);
    if (!expect(ps, SG_TK_IDENT, "an output name"))
        return false;
    sg_port port = { .name = tok_text(ps, name), .loc = loc_of(ps, name), .type = t,
                     .output = -1 };
    if (!expect(ps, SG_TK_EQ, "'='") || !parse_value(ps, &port.value))
        return false;
    port.has_value = true;
    *SG_PUSH(ps->a, s->outs, s->nouts, s->capouts) = port;
    return true;
}

static bool parse_number(parser *ps, double *x)
{
    if (cur(ps)->kind != SG_TK_NUMBER) {
        expected(ps, "a number");
        return false;
    }
    *x = next(ps)->num;
    return true;
}

/* param = "param" TYPE IDENT "=" value [ "range" NUMBER NUMBER ] */
static bool parse_param(parser *ps, sg_shader *s)
{
    next(ps);
    ir_type t = type_name(cur(ps));
    if (t == IR_T_ERROR || t == IR_T_TEX) {
        expected(ps, "a param type (float, vec2, vec3 or vec4)");
        return false;
    }
    next(ps);
    sg_token *name = cur(ps);
    if (!expect(ps, SG_TK_IDENT, "a param name"))
        return false;
    sg_port port = { .name = tok_text(ps, name), .loc = loc_of(ps, name), .type = t };
    if (!expect(ps, SG_TK_EQ, "'=' and a default value") || !parse_value(ps, &port.value))
        return false;
    port.has_value = true;
    if (is_kw(cur(ps), "range")) {
        next(ps);
        if (!parse_number(ps, &port.lo) || !parse_number(ps, &port.hi))
            return false;
        port.has_range = true;
    }
    *SG_PUSH(ps->a, s->params, s->nparams, s->capparams) = port;
    return true;
}

/* A block `{ statement* }` whose statements `stmt` parses; returns when the
 * block is closed (or found unterminated). */
typedef bool (*stmt_fn)(parser *ps, void *user);

static void parse_block_in(parser *ps, const char *what, stmt_fn stmt, void *user,
                           bool in_material);

static void parse_block(parser *ps, const char *what, stmt_fn stmt, void *user)
{
    parse_block_in(ps, what, stmt, user, false);
}

/* in_material: a block inside a material's, so a material statement
 * starting a later line (`node`, `out`, …) also means it was not closed. */
static void parse_block_in(parser *ps, const char *what, stmt_fn stmt, void *user,
                           bool in_material)
{
    sg_token *open = cur(ps);
    if (!expect(ps, SG_TK_LBRACE, "'{'"))
        return;
    for (;;) {
        sg_token *t = cur(ps);
        if (t->kind == SG_TK_RBRACE) {
            next(ps);
            return;
        }
        if (t->kind == SG_TK_EOF || (top_keyword(t) && line_start(ps, t)) ||
            (in_material && t->line > open->line && starts_statement(ps, t))) {
            sg_error(ps->d, loc_of(ps, open), SG_E_UNTERMINATED, what, open->line);
            return;
        }
        int line = t->line;
        int before = ps->pos;
        if (!stmt(ps, user)) {
            sync_statement(ps, line);
            if (ps->pos == before)
                next(ps);           /* always make progress */
        }
    }
}

/* ---- undergrowth ----------------------------------------------------------- */

/* The keys of each settings block, NULL-ended (sg_internal.h): the parser's
 * "did you mean" lists, and what an editor completes (lsp_complete.c). */
const char *const sg_ug_keys[] = { "density", "scale", "align", "blend", "color",
                                   "root_blend", "lighting", "cutout", "wind",
                                   "wind_dir", "gust", "shadow", "texture", NULL };
const char *const sg_texture_keys[] = { "file", "filter", "mip", "wrap", "srgb", NULL };
const char *const sg_scene_keys[] = { "heightfield", "heightfield_size", "size",
                                      "max_height", "height_offset", "materials",
                                      "compositor", "painted", "spline", "polygon",
                                      "destruction", "cell", "camera", "light", NULL };
const char *const sg_painted_keys[] = { "max_level", "max_error", "near", "origin",
                                        "size", NULL };
const char *const sg_camera_keys[] = { "position", "look", NULL };
const char *const sg_destruction_keys[] = { "origin", "size", "cell", NULL };

enum { UG_NKEYS = 13 };
#define UG_KEY_LIST "density, scale, align, blend, color, root_blend, lighting, cutout, " \
                    "wind, wind_dir, gust, shadow, texture"

typedef struct ug_parse {
    sg_undergrowth *u;
    sg_loc          seen[UG_NKEYS];   /* where each key was set (line 0: not yet) */
} ug_parse;

/* A number in [lo, hi] (lo excluded if open_lo) for `key`, or SETTING. */
static bool ug_number(parser *ps, const char *key, double lo, double hi, bool open_lo,
                      double *x)
{
    sg_loc at = loc_of(ps, cur(ps));
    if (!parse_number(ps, x))
        return false;
    if ((open_lo ? *x > lo : *x >= lo) && *x <= hi)
        return true;
    sg_errorf(ps->d, at, SG_E_SETTING, "'%s' must be in %c%g, %g], found %g", key,
              open_lo ? '(' : '[', lo, hi, *x);
    return true;   /* well-formed: parsing goes on */
}

/* One of two keywords for `key` (*x = whether the first), or SETTING. */
static bool ug_choice(parser *ps, const char *key, const char *yes, const char *no, bool *x)
{
    sg_token *vt = cur(ps);
    char buf[96];
    if (is_kw(vt, yes) || is_kw(vt, no)) {
        *x = is_kw(vt, yes);
    } else {
        if (vt->kind != SG_TK_IDENT && vt->kind != SG_TK_NUMBER && vt->kind != SG_TK_STRING) {
            snprintf(buf, sizeof buf, "%s or %s", yes, no);
            expected(ps, buf);
            return false;
        }
        sg_errorf(ps->d, loc_of(ps, vt), SG_E_SETTING, "'%s' must be %s or %s, found %s", key,
                  yes, no, sg_tok_describe(vt, buf, sizeof buf));
    }
    next(ps);
    return true;
}

/* Check an undergrowth texture now, so its errors are located at the
 * string: readable, an image, 1 to SPLAT_MAX_UG_TEXTURE texels a side. */
static void check_ug_texture(parser *ps, const char *path, sg_loc at)
{
    char why[160];
    FILE *f = splat_input_fopen(path, SPLAT_MAX_IMAGE_BYTES, why, sizeof why);
    if (!f) {
        sg_error(ps->d, at, SG_E_IO, path, why);
        return;
    }
    int w, h, comp;
    if (!stbi_info_from_file(f, &w, &h, &comp))
        sg_error(ps->d, at, SG_E_IO, path, "not an image stb_image reads");
    else if (w < 1 || h < 1 || w > SPLAT_MAX_UG_TEXTURE || h > SPLAT_MAX_UG_TEXTURE)
        sg_errorf(ps->d, at, SG_E_OVER_LIMIT, "texture '%s' is %d x %d; an undergrowth texture "
                  "may have at most %d texels a side", path, w, h, SPLAT_MAX_UG_TEXTURE);
    fclose(f);
}

/* ug_setting = "density" "=" NUM | "scale" "=" NUM [ NUM ]
 *            | "align" "=" ("normal" | "upright") | "blend" "=" NUM
 *            | "color" "=" "vec3" "(" NUM "," NUM "," NUM ")"
 *            | "root_blend" "=" NUM | "lighting" "=" ("terrain" | "mesh")
 *            | "cutout" "=" ("frond" | "alpha" | "none") | "wind" "=" NUM
 *            | "wind_dir" "=" NUM NUM | "gust" "=" NUM | "shadow" "=" NUM
 *            | "texture" "=" STRING */
static bool ug_stmt(parser *ps, void *user)
{
    ug_parse *up = user;
    sg_undergrowth *u = up->u;
    sg_token *key = cur(ps);
    if (key->kind != SG_TK_IDENT) {
        expected(ps, "an undergrowth setting (" UG_KEY_LIST ") or '}'");
        return false;
    }
    sg_loc kloc = loc_of(ps, key);
    int k = 0;
    while (k < UG_NKEYS && !is_kw(key, sg_ug_keys[k]))
        k++;
    if (k == UG_NKEYS) {
        sg_errorf(ps->d, kloc, SG_E_BAD_OPTION, "unknown undergrowth setting '%.*s' "
                  "(expected " UG_KEY_LIST ")", key->len, key->start);
        hint_key(ps, key, sg_ug_keys);
        /* skip its value (vec3(…) whole), then to ',', '}' or the next line */
        next(ps);
        sg_value v;
        if (accept(ps, SG_TK_EQ) && cur(ps)->kind != SG_TK_RBRACE)
            parse_value(ps, &v);
        while (cur(ps)->kind != SG_TK_EOF && cur(ps)->kind != SG_TK_RBRACE &&
               cur(ps)->kind != SG_TK_COMMA && cur(ps)->line == key->line)
            next(ps);
        accept(ps, SG_TK_COMMA);
        return true;
    }
    if (up->seen[k].line)
        sg_error(ps->d, kloc, SG_E_DUPLICATE, "undergrowth setting", sg_ug_keys[k],
                 up->seen[k].file, up->seen[k].line, up->seen[k].col);
    else
        up->seen[k] = kloc;
    next(ps);
    if (!expect(ps, SG_TK_EQ, "'='"))
        return false;
    sg_loc vloc = loc_of(ps, cur(ps));
    switch (k) {
    case 0:
        if (!ug_number(ps, "density", 0, 64, true, &u->density))
            return false;
        break;
    case 1:
        if (!parse_number(ps, &u->scale[0]))
            return false;
        u->scale[1] = u->scale[0];
        if (cur(ps)->kind == SG_TK_NUMBER)
            u->scale[1] = next(ps)->num;
        if (!(u->scale[0] > 0 && u->scale[0] <= u->scale[1] && u->scale[1] <= 100))
            sg_errorf(ps->d, vloc, SG_E_SETTING, "'scale' must be LO HI with 0 < LO <= HI "
                      "<= 100, found %g %g", u->scale[0], u->scale[1]);
        break;
    case 2:
        if (!ug_choice(ps, "align", "normal", "upright", &u->align_normal))
            return false;
        break;
    case 3:
        if (!ug_number(ps, "blend", 0, 1, false, &u->blend))
            return false;
        break;
    case 5:
        if (!ug_number(ps, "root_blend", 0, 1, false, &u->root_blend))
            return false;
        break;
    case 6:
        if (!ug_choice(ps, "lighting", "terrain", "mesh", &u->light_terrain))
            return false;
        break;
    case 7:
    {
        sg_token *vt = cur(ps);
        char buf[96];
        if (is_kw(vt, "none") || is_kw(vt, "frond") || is_kw(vt, "alpha")) {
            u->cutout = is_kw(vt, "frond") ? SG_UG_CUT_FROND
                      : is_kw(vt, "alpha") ? SG_UG_CUT_ALPHA : SG_UG_CUT_NONE;
        } else {
            if (vt->kind != SG_TK_IDENT && vt->kind != SG_TK_NUMBER && vt->kind != SG_TK_STRING) {
                expected(ps, "none, frond or alpha");
                return false;
            }
            sg_errorf(ps->d, vloc, SG_E_SETTING, "'cutout' must be none, frond or alpha, "
                      "found %s", sg_tok_describe(vt, buf, sizeof buf));
        }
        next(ps);
        break;
    }
    case 8:
        if (!ug_number(ps, "wind", 0, SPLAT_MAX_UG_WIND, false, &u->wind))
            return false;
        break;
    case 9: {
        double x, z;
        if (!parse_number(ps, &x) || !parse_number(ps, &z))
            return false;
        double len = hypot(x, z);
        if (!(len > 1e-6 && len <= 1e6)) {
            sg_errorf(ps->d, vloc, SG_E_SETTING, "'wind_dir' must be X Z, a direction in the "
                      "ground plane (not 0 0, each at most 1e6), found %g %g", x, z);
            break;
        }
        u->wind_dir[0] = x / len;
        u->wind_dir[1] = z / len;
        break;
    }
    case 10:
        if (!ug_number(ps, "gust", 0, 1, false, &u->gust))
            return false;
        break;
    case 11:
        if (!ug_number(ps, "shadow", 0, 1, false, &u->shadow))
            return false;
        break;
    case 12: {
        sg_token *vt = cur(ps);
        if (vt->kind != SG_TK_STRING) {
            expected(ps, "an image file in quotes");
            return false;
        }
        char *path = splat_path_join(ps->f->dir, vt->str);
        u->texture = sg_strdup(ps->a, path);
        free(path);
        check_ug_texture(ps, u->texture, vloc);
        next(ps);
        break;
    }
    case 4: {
        sg_value v;
        if (!parse_value(ps, &v))
            return false;
        if (v.kind != SG_V_VEC || v.width != 3) {
            sg_errorf(ps->d, vloc, SG_E_SETTING, "'color' must be vec3(r, g, b), "
                      "linear, each in [0, 1]");
            break;
        }
        if (!(v.num[0] >= 0 && v.num[0] <= 1 && v.num[1] >= 0 && v.num[1] <= 1 &&
              v.num[2] >= 0 && v.num[2] <= 1))
            sg_errorf(ps->d, vloc, SG_E_SETTING, "'color' components must be in [0, 1] "
                      "(linear), found vec3(%g, %g, %g)", v.num[0], v.num[1], v.num[2]);
        memcpy(u->color, v.num, sizeof u->color);
        break;
    }
    }
    accept(ps, SG_TK_COMMA);
    return true;
}

/* Load and check an undergrowth block's OBJ file now, so its errors are
 * located at the string (the pack writer loads it again). */
static void check_obj(parser *ps, const char *path, sg_loc at)
{
    splat_mesh m;
    char *err = NULL;
    if (!splat_mesh_obj(path, &m, &err)) {
        sg_error(ps->d, at, SG_E_IO, path, err);
        free(err);
        return;
    }
    if (m.nv > SPLAT_MAX_MESH_VERTICES || m.nidx > SPLAT_MAX_MESH_INDICES)
        sg_errorf(ps->d, at, SG_E_OVER_LIMIT, "mesh '%s' has %u vertices and %u indices; "
                  "an undergrowth mesh may have at most %d and %d", path, m.nv, m.nidx,
                  SPLAT_MAX_MESH_VERTICES, SPLAT_MAX_MESH_INDICES);
    /* meshes.bin's floats as the runtime's loader bounds them (abi.h) */
    for (uint32_t i = 0; i < m.nv; i++) {
        const splat_mesh_vertex *x = &m.v[i];
        const float v[5] = { x->pos[0], x->pos[1], x->pos[2], x->uv[0], x->uv[1] };
        for (int k = 0; k < 5; k++)
            if (!(fabsf(v[k]) <= (float)SPLAT_MAX_MESH_VALUE)) {
                sg_errorf(ps->d, at, SG_E_OVER_LIMIT, "mesh '%s' has a vertex %s of %g; the "
                          "pack limit is %g either way (metres at scale 1, and uv)", path,
                          k < 3 ? "coordinate" : "uv", (double)v[k], SPLAT_MAX_MESH_VALUE);
                splat_mesh_free(&m);
                return;
            }
    }
    splat_mesh_free(&m);
}

/* undergrowth = "undergrowth" (IDENT | STRING) [ "{" { ug_setting [","] } "}" ]
 * IDENT names a built-in mesh (mesh.h), STRING an OBJ file relative to
 * this file's folder (as a texture's file). */
static bool parse_undergrowth(parser *ps, sg_shader *s)
{
    static const double colors[][3] = {      /* per built-in mesh, then OBJ */
        { 0.16, 0.30, 0.06 }, { 0.12, 0.26, 0.05 }, { 0.35, 0.33, 0.30 }, { 0.5, 0.5, 0.5 },
    };
    /* per built-in mesh, then OBJ: lit with the terrain normal, cut out,
     * contact shadow (defaults: each can be set in the block) */
    static const bool terrain_lit[] = { true, true, false, false };
    static const int cut[] = { SG_UG_CUT_NONE, SG_UG_CUT_FROND, SG_UG_CUT_NONE,
                               SG_UG_CUT_NONE };
    static const double shadows[] = { 0.35, 0.3, 0.5, 0.4 };
    /* blend at the tip and at the root: a stone keeps its own colour and
     * takes the ground's only at its foot */
    static const double blends[][2] = { { 0.5, -1 }, { 0.5, -1 }, { 0.15, 0.5 }, { 0.5, -1 } };
    sg_undergrowth u = { .density = 1, .scale = { 1, 1 }, .wind_dir = { 1, 0 }, .gust = 0.5 };
    u.loc = loc_of(ps, next(ps));
    bool seen_color = false;
    sg_token *m = cur(ps);
    bool known = true;
    int kind = 0;
    if (m->kind == SG_TK_IDENT) {
        while (splat_mesh_builtins[kind] && !is_kw(m, splat_mesh_builtins[kind]))
            kind++;
        if (splat_mesh_builtins[kind]) {
            u.mesh = splat_mesh_builtins[kind];
        } else {
            sg_errorf(ps->d, loc_of(ps, m), SG_E_BAD_OPTION, "unknown undergrowth mesh "
                      "'%.*s' (built-in meshes: grass, plant, stone; or an OBJ file in quotes)",
                      m->len, m->start);
            known = false;
        }
    } else if (m->kind == SG_TK_STRING) {
        kind = (int)(sizeof colors / sizeof colors[0]) - 1;
        char *path = splat_path_join(ps->f->dir, m->str);
        u.obj = sg_strdup(ps->a, path);
        free(path);
        check_obj(ps, u.obj, loc_of(ps, m));
    } else {
        expected(ps, "a mesh (grass, plant, stone or an OBJ file in quotes)");
        return false;
    }
    next(ps);
    memcpy(u.color, colors[kind], sizeof u.color);
    u.light_terrain = terrain_lit[kind];
    u.cutout = cut[kind];
    u.shadow = shadows[kind];
    u.blend = blends[kind][0];
    u.root_blend = blends[kind][1];
    if (cur(ps)->kind == SG_TK_LBRACE) {
        ug_parse up = { &u, { { 0 } } };
        char what[160];
        snprintf(what, sizeof what, "block of undergrowth '%.*s'", m->len, m->start);
        parse_block_in(ps, what, ug_stmt, &up, true);
        seen_color = up.seen[4].line != 0;
        if (u.cutout == SG_UG_CUT_ALPHA && !u.texture)
            sg_errorf(ps->d, up.seen[7], SG_E_SETTING, "'cutout = alpha' needs a texture "
                      "(texture = \"file.png\") whose alpha cuts the mesh");
    }
    if (u.root_blend < 0)   /* not set: as the tip, unless a default of its own */
        u.root_blend = u.blend;
    if (u.texture && !seen_color)   /* the texture's own colour */
        u.color[0] = u.color[1] = u.color[2] = 1.0;
    if (!known)
        return true;
    if (s->nug == SG_MAX_UNDERGROWTH) {
        sg_errorf(ps->d, u.loc, SG_E_OVER_LIMIT, "material '%s' has more than %d "
                  "undergrowth blocks", s->name, SG_MAX_UNDERGROWTH);
        return true;
    }
    if (s->nug == 0 && ps->p->nug_materials == SG_MAX_UG_MATERIALS) {
        sg_errorf(ps->d, u.loc, SG_E_OVER_LIMIT, "more than %d materials have undergrowth "
                  "(the undergrowth masks hold %d weights)", SG_MAX_UG_MATERIALS,
                  SG_MAX_UG_MATERIALS);
        return true;
    }
    if (s->nug == 0)
        ps->p->nug_materials++;
    *SG_PUSH(ps->a, s->ug, s->nug, s->capug) = u;
    return true;
}

/* shader_stmt   = in | out | node
 * material_stmt = param | out | node | undergrowth */
static bool shader_stmt(parser *ps, void *user)
{
    sg_shader *s = user;
    sg_token *t = cur(ps);
    if (is_kw(t, "node"))
        return parse_node(ps, s);
    if (is_kw(t, "out"))
        return parse_out(ps, s);
    if (!s->is_material && is_kw(t, "in"))
        return parse_in(ps, s);
    if (s->is_material && is_kw(t, "param"))
        return parse_param(ps, s);
    if (s->is_material && is_kw(t, "undergrowth"))
        return parse_undergrowth(ps, s);
    expected(ps, s->is_material ? "'param', 'node', 'out', 'undergrowth' or '}'"
                                : "'in', 'node', 'out' or '}'");
    return false;
}

/* shader   = "shader" IDENT "{" { shader_stmt } "}"
 * material = "material" IDENT "{" { material_stmt } "}" */
static bool parse_shader(parser *ps, bool material)
{
    next(ps);
    sg_token *name = cur(ps);
    if (!expect(ps, SG_TK_IDENT, material ? "a material name" : "a shader name"))
        return false;
    sg_shader *s = sg_alloc(ps->a, sizeof *s);
    s->name = tok_text(ps, name);
    s->loc = loc_of(ps, name);
    s->is_material = material;
    s->file = ps->fi;
    sg_program *p = ps->p;
    *SG_PUSH(ps->a, p->shaders, p->nshaders, p->capshaders) = s;
    if (material)
        *SG_PUSH(ps->a, p->materials, p->nmaterials, p->capmaterials) = p->nshaders - 1;
    char what[160];
    snprintf(what, sizeof what, "block of %s '%s'", material ? "material" : "shader", s->name);
    parse_block(ps, sg_strdup(ps->a, what), shader_stmt, s);
    return true;
}

/* ---- textures ------------------------------------------------------------ */

void sg_texdecl_defaults(sg_texdecl *t)
{
    t->filter = IR_FILTER_LINEAR;
    t->mip = IR_FILTER_LINEAR;
    t->wrap = IR_WRAP_REPEAT;
    t->srgb = false;
}

static bool word_is(const sg_value *v, const char *w)
{
    return v->kind == SG_V_PATH && v->nparts == 1 && !strcmp(v->parts[0], w);
}

/* A bare word's text ("nearest"), or "" for any other value. */
static const char *word_of(const sg_value *v)
{
    return v->kind == SG_V_PATH && v->nparts == 1 ? v->parts[0] : "";
}

static void bad_setting(parser *ps, const sg_value *v, const char *key, const char *allowed)
{
    char msg[200];
    snprintf(msg, sizeof msg, "'%s' must be %s", key, allowed);
    sg_error(ps->d, v->loc, SG_E_BAD_OPTION, msg);
}

static void add_texture_setting(parser *ps, void *user, sg_token *key, sg_value *v)
{
    sg_texdecl *t = user;
    if (is_kw(key, "file")) {
        if (v->kind != SG_V_STRING)
            bad_setting(ps, v, "file", "a string");
        else {
            char *path = splat_path_join(ps->f->dir, v->str);
            t->file = sg_strdup(ps->a, path);
            t->file_loc = v->loc;
            free(path);
        }
    } else if (is_kw(key, "filter") || is_kw(key, "mip")) {
        ir_filter *f = is_kw(key, "mip") ? &t->mip : &t->filter;
        int k = ir_filter_by_name(word_of(v));
        if (k >= 0)
            *f = (ir_filter)k;
        else
            bad_setting(ps, v, is_kw(key, "mip") ? "mip" : "filter", "linear or nearest");
    } else if (is_kw(key, "wrap")) {
        int k = ir_wrap_by_name(word_of(v));
        if (k >= 0)
            t->wrap = (ir_wrap)k;
        else
            bad_setting(ps, v, "wrap", "repeat, clamp or mirror");
    } else if (is_kw(key, "srgb")) {
        if (word_is(v, "true"))
            t->srgb = true;
        else if (word_is(v, "false"))
            t->srgb = false;
        else
            bad_setting(ps, v, "srgb", "true or false");
    } else {
        char msg[160];
        snprintf(msg, sizeof msg, "unknown texture setting '%.*s' "
                 "(expected file, filter, mip, wrap or srgb)", key->len, key->start);
        sg_error(ps->d, loc_of(ps, key), SG_E_BAD_OPTION, msg);
        hint_key(ps, key, sg_texture_keys);
    }
}

/* texture = "texture" IDENT "{" { ("file" | "filter" | "mip" | "wrap" |
 *           "srgb") "=" value [","] } "}" */
static bool parse_texture(parser *ps)
{
    next(ps);
    sg_token *name = cur(ps);
    if (!expect(ps, SG_TK_IDENT, "a texture name"))
        return false;
    sg_texdecl *t = sg_alloc(ps->a, sizeof *t);
    t->name = tok_text(ps, name);
    t->loc = loc_of(ps, name);
    sg_texdecl_defaults(t);
    char what[160];
    snprintf(what, sizeof what, "block of texture '%s'", t->name);
    parse_bindings(ps, sg_strdup(ps->a, what), add_texture_setting, t);
    if (!t->file) {
        char msg[160];
        snprintf(msg, sizeof msg, "texture '%s' needs a file = \"...\"", t->name);
        sg_error(ps->d, t->loc, SG_E_MISSING_SETTING, msg);
        t->file = "";
    }
    sg_program *p = ps->p;
    *SG_PUSH(ps->a, p->textures, p->ntextures, p->captextures) = t;
    return true;
}

/* import = "import" STRING */
static bool parse_import(parser *ps)
{
    next(ps);
    sg_token *t = cur(ps);
    if (!expect(ps, SG_TK_STRING, "a file name in quotes"))
        return false;
    sg_import *im = SG_PUSH(ps->a, *ps->imports, *ps->nimports, ps->capimports);
    im->path = t->str;
    im->loc = loc_of(ps, t);
    return true;
}

/* ---- scenes -------------------------------------------------------------- */

typedef struct scene_parse {
    sg_scene *sc;
    int cap_materials, cap_material_locs, cap_painted, cap_cameras, cap_vectors;
} scene_parse;

static void scene_error(parser *ps, sg_error_id id, sg_loc loc, const char *fmt,
                        const char *a)
{
    char msg[256];
    snprintf(msg, sizeof msg, fmt, a);
    sg_error(ps->d, loc, id, msg);
}

static bool parse_numbers(parser *ps, double *out, int n)
{
    for (int i = 0; i < n; i++)
        if (!parse_number(ps, &out[i]))
            return false;
    return true;
}

static char *scene_path(parser *ps, const char *rel)
{
    char *path = splat_path_join(ps->f->dir, rel);
    char *r = sg_strdup(ps->a, path);
    free(path);
    return r;
}

/* painted_opts = "{" { ("max_level" "=" NUM | "max_error" "=" NUM |
 *                "near" "=" NUM NUM NUM NUM | "origin" "=" NUM NUM |
 *                "size" "=" NUM NUM) [","] } "}" */
static bool painted_stmt(parser *ps, void *user)
{
    sg_scene_painted *pm = user;
    sg_token *key = cur(ps);
    sg_loc kloc = loc_of(ps, key);
    const char *keys = "'max_level', 'max_error', 'near', 'origin', 'size' or '}'";
    if (key->kind != SG_TK_IDENT) {
        expected(ps, keys);
        return false;
    }
    bool ok;
    if (is_kw(key, "max_level")) {
        next(ps);
        double v = -1;
        ok = expect(ps, SG_TK_EQ, "'='") && parse_number(ps, &v);
        pm->max_level = v >= 0 && v <= 7 && v == (int)v ? (int)v : -1;
        pm->max_level_loc = kloc;
    } else if (is_kw(key, "max_error")) {
        next(ps);
        ok = expect(ps, SG_TK_EQ, "'='") && parse_number(ps, &pm->max_error);
        pm->max_error_loc = kloc;
    } else if (is_kw(key, "near")) {
        next(ps);
        ok = expect(ps, SG_TK_EQ, "'='") && parse_numbers(ps, pm->near, 4);
        pm->has_near = ok;
        pm->near_loc = kloc;
    } else if (is_kw(key, "origin") || is_kw(key, "size")) {
        bool size = is_kw(key, "size");
        next(ps);
        ok = expect(ps, SG_TK_EQ, "'='") && parse_numbers(ps, size ? pm->place : pm->origin, 2);
        if (ok) *(size ? &pm->place_loc : &pm->origin_loc) = kloc;
    } else {
        expected(ps, keys);
        hint_key(ps, key, sg_painted_keys);
        return false;
    }
    if (ok)
        accept(ps, SG_TK_COMMA);
    return ok;
}

/* destruction = "destruction" "{" { ("origin" NUM NUM | "size" NUM NUM |
 *               "cell" NUM) [","] } "}"
 * camera = "camera" IDENT "{" { ("position" | "look") "=" NUM NUM NUM
 *          [","] } "}"
 * Both use this statement function on their own little block. */
typedef struct sub_block { scene_parse *sp; sg_scene_camera *cam; } sub_block;

static bool sub_stmt(parser *ps, void *user)
{
    sub_block *b = user;
    sg_scene *sc = b->sp->sc;
    sg_token *key = cur(ps);
    if (key->kind != SG_TK_IDENT) {
        expected(ps, b->cam ? "'position', 'look' or '}'" : "'origin', 'size', 'cell' or '}'");
        return false;
    }
    bool ok;
    if (b->cam && (is_kw(key, "position") || is_kw(key, "look"))) {
        next(ps);
        ok = expect(ps, SG_TK_EQ, "'='") &&
             parse_numbers(ps, is_kw(key, "look") ? b->cam->look : b->cam->position, 3);
    } else if (!b->cam && (is_kw(key, "origin") || is_kw(key, "size"))) {
        next(ps);
        ok = expect(ps, SG_TK_EQ, "'='") &&
             parse_numbers(ps, is_kw(key, "origin") ? sc->destruction_origin
                                                    : sc->destruction_size, 2);
    } else if (!b->cam && is_kw(key, "cell")) {
        next(ps);
        sc->destruction_cell_loc = loc_of(ps, key);
        ok = expect(ps, SG_TK_EQ, "'='") && parse_number(ps, &sc->destruction_cell);
    } else {
        expected(ps, b->cam ? "'position', 'look' or '}'" : "'origin', 'size', 'cell' or '}'");
        hint_key(ps, key, b->cam ? sg_camera_keys : sg_destruction_keys);
        return false;
    }
    if (ok)
        accept(ps, SG_TK_COMMA);
    return ok;
}

/* light = "light" "{" { KEY "=" NUM... [","] } "}" (abi.h SPLAT_LIGHT_KEYS) */
static bool light_stmt(parser *ps, void *user)
{
    sg_scene_light *l = user;
    sg_token *key = cur(ps);
    int k = 0;
    while (key->kind == SG_TK_IDENT && k < SPLAT_LIGHT_COUNT &&
           !is_kw(key, splat_light_keys[k].key))
        k++;
    if (key->kind != SG_TK_IDENT || k == SPLAT_LIGHT_COUNT) {
        expected(ps, "'sun', 'sun_color', 'intensity', 'sky', 'fog_density', "
                     "'fog_height', 'exposure' or '}'");
        const char *keys[SPLAT_LIGHT_COUNT + 1];
        for (int i = 0; i < SPLAT_LIGHT_COUNT; i++)
            keys[i] = splat_light_keys[i].key;
        keys[SPLAT_LIGHT_COUNT] = NULL;
        hint_key(ps, key, keys);
        return false;
    }
    l->loc[k] = loc_of(ps, key);
    next(ps);
    bool ok = expect(ps, SG_TK_EQ, "'='") && parse_numbers(ps, l->v[k], splat_light_keys[k].n);
    if (ok) {
        l->given |= 1u << k;
        accept(ps, SG_TK_COMMA);
    }
    return ok;
}

/* camera NAME { position = X Y Z, look = X Y Z }, after "camera" */
static bool camera_decl(parser *ps, scene_parse *sp)
{
    sg_scene *sc = sp->sc;
    sg_token *name = cur(ps);
    if (!expect(ps, SG_TK_IDENT, "a camera name"))
        return false;
    sg_scene_camera *cam = SG_PUSH(ps->a, sc->cameras, sc->ncameras, sp->cap_cameras);
    cam->name = tok_text(ps, name);
    cam->loc = loc_of(ps, name);
    sub_block b = { sp, cam };
    parse_block(ps, "block of camera", sub_stmt, &b);
    return true;
}

/* painted NAME = "FILE" [painted_opts], after "painted"; NAME holes is
 * the terrain's holes mask, which takes no options */
static bool painted_decl(parser *ps, scene_parse *sp)
{
    sg_scene *sc = sp->sc;
    sg_token *name = cur(ps);
    if (!expect(ps, SG_TK_IDENT, "a painted mask name") || !expect(ps, SG_TK_EQ, "'='"))
        return false;
    sg_token *file = cur(ps);
    if (!expect(ps, SG_TK_STRING, "a file name in quotes"))
        return false;
    if (is_kw(name, "holes")) {
        if (sc->holes)
            sg_error(ps->d, loc_of(ps, name), SG_E_DUPLICATE, "painted mask", "holes",
                     sc->holes_loc.file, sc->holes_loc.line, sc->holes_loc.col);
        sc->holes = scene_path(ps, file->str);
        sc->holes_loc = loc_of(ps, name);
        if (cur(ps)->kind == SG_TK_LBRACE) {
            scene_error(ps, SG_E_SETTING, loc_of(ps, cur(ps)), "the holes mask takes no "
                        "options (it is not stored as a painted layer)%s", "");
            return false;
        }
        return true;
    }
    sg_scene_painted *pm = SG_PUSH(ps->a, sc->painted, sc->npainted, sp->cap_painted);
    pm->name = tok_text(ps, name);
    pm->file = scene_path(ps, file->str);
    pm->loc = loc_of(ps, name);
    pm->max_error = 1.0;
    if (cur(ps)->kind == SG_TK_LBRACE)
        parse_block(ps, "block of painted mask options", painted_stmt, pm);
    return true;
}

/* The parse of one spline or polygon block: its capacities. */
typedef struct vector_parse {
    sg_scene_vector *v;
    int cap_points, cap_curves, cap_locs;
} vector_parse;

/* points = "[" NUM NUM { "," NUM NUM } "]": x z pairs, terrain-local m;
 * each `points` adds a curve */
static bool vector_points(parser *ps, vector_parse *vp, sg_loc kloc)
{
    sg_scene_vector *v = vp->v;
    sg_token *open = cur(ps);
    if (!expect(ps, SG_TK_LBRACK, "'['"))
        return false;
    int n = 2 * v->npoints;      /* doubles pushed */
    while (cur(ps)->kind != SG_TK_RBRACK) {
        double xz[2];
        if (!parse_numbers(ps, xz, 2))
            return false;
        if (n < 2 * SPLAT_MAX_VECTOR_POINTS + 2) {   /* sg_scene_check says when over */
            SG_PUSH(ps->a, v->points, n, vp->cap_points)[0] = xz[0];
            SG_PUSH(ps->a, v->points, n, vp->cap_points)[0] = xz[1];
            v->npoints = n / 2;
        }
        if (!accept(ps, SG_TK_COMMA))
            break;
    }
    if (cur(ps)->kind != SG_TK_RBRACK) {
        if (cur(ps)->kind == SG_TK_EOF)
            sg_error(ps->d, loc_of(ps, open), SG_E_UNTERMINATED, "'['", open->line);
        else
            expected(ps, "',' or ']'");
        return false;
    }
    next(ps);
    int c = v->ncurves;
    *SG_PUSH(ps->a, v->curve_end, v->ncurves, vp->cap_curves) = v->npoints;
    *SG_PUSH(ps->a, v->curve_loc, c, vp->cap_locs) = kloc;
    if (v->points_loc.line == 0)
        v->points_loc = kloc;
    return true;
}

/* vector_stmt = "points" "=" "[" ... "]" | "width" "=" NUM
 *             | "falloff" "=" NUM | "profile" "=" ("linear" | "smoothstep") */
static bool vector_stmt(parser *ps, void *user)
{
    vector_parse *vp = user;
    sg_scene_vector *v = vp->v;
    sg_token *key = cur(ps);
    sg_loc kloc = loc_of(ps, key);
    bool spline = v->kind == SPLAT_VEC_SPLINE;
    const char *keys = spline ? "'points', 'width', 'falloff', 'profile' or '}'"
                              : "'points', 'falloff', 'profile' or '}'";
    bool ok;
    if (key->kind == SG_TK_IDENT && is_kw(key, "points")) {
        next(ps);
        ok = expect(ps, SG_TK_EQ, "'='") && vector_points(ps, vp, kloc);
    } else if (key->kind == SG_TK_IDENT && spline && is_kw(key, "width")) {
        next(ps);
        v->width_loc = kloc;
        ok = expect(ps, SG_TK_EQ, "'='") && parse_number(ps, &v->width);
    } else if (key->kind == SG_TK_IDENT && is_kw(key, "falloff")) {
        next(ps);
        v->falloff_loc = kloc;
        ok = expect(ps, SG_TK_EQ, "'='") && parse_number(ps, &v->falloff);
    } else if (key->kind == SG_TK_IDENT && is_kw(key, "profile")) {
        next(ps);
        v->profile_loc = kloc;
        ok = expect(ps, SG_TK_EQ, "'='");
        sg_token *p = cur(ps);
        if (ok && !expect(ps, SG_TK_IDENT, "'linear' or 'smoothstep'"))
            return false;
        if (ok)
            v->profile = is_kw(p, "linear") ? SPLAT_VEC_LINEAR
                       : is_kw(p, "smoothstep") ? SPLAT_VEC_SMOOTHSTEP : -1;
        if (ok && v->profile < 0)
            v->profile_loc = loc_of(ps, p);
    } else {
        expected(ps, keys);
        static const char *const sk[] = { "points", "width", "falloff", "profile", NULL };
        static const char *const pk[] = { "points", "falloff", "profile", NULL };
        if (key->kind == SG_TK_IDENT)
            hint_key(ps, key, spline ? sk : pk);
        return false;
    }
    if (ok)
        accept(ps, SG_TK_COMMA);
    return ok;
}

/* spline NAME "{" { vector_stmt } "}" | polygon NAME "{" ... "}", after
 * the keyword */
static bool vector_decl(parser *ps, scene_parse *sp, int kind)
{
    sg_scene *sc = sp->sc;
    sg_token *name = cur(ps);
    if (!expect(ps, SG_TK_IDENT, kind == SPLAT_VEC_SPLINE ? "a spline name" : "a polygon name"))
        return false;
    sg_scene_vector *v = SG_PUSH(ps->a, sc->vectors, sc->nvectors, sp->cap_vectors);
    memset(v, 0, sizeof *v);
    v->name = tok_text(ps, name);
    v->loc = loc_of(ps, name);
    v->kind = kind;
    v->profile = SPLAT_VEC_SMOOTHSTEP;
    if (cur(ps)->kind != SG_TK_LBRACE) {
        expected(ps, "'{'");
        return false;
    }
    vector_parse vp = { .v = v };
    parse_block(ps, kind == SPLAT_VEC_SPLINE ? "block of spline" : "block of polygon",
                vector_stmt, &vp);
    return true;
}

/* heightfield = "FILE": the format from the extension */
static bool heightfield_value(parser *ps, scene_parse *sp)
{
    sg_scene *sc = sp->sc;
    sg_token *file = cur(ps);
    if (!expect(ps, SG_TK_STRING, "a file name in quotes"))
        return false;
    sc->heightfield = scene_path(ps, file->str);
    sc->heightfield_loc = loc_of(ps, file);
    const char *dot = strrchr(file->str, '.');
    if (dot && !strcmp(dot, ".png"))
        sc->hf_format = SG_HF_PNG;
    else if (dot && (!strcmp(dot, ".r16") || !strcmp(dot, ".raw")))
        sc->hf_format = SG_HF_R16;
    else
        sc->hf_format = SG_HF_GDAL;   /* .tif, .hgt, .asc, …: raster.c */
    return true;
}

/* materials = "[" [ IDENT { "," IDENT } ] "]", after "=".  A second
 * `materials =` replaces the first, as every setting does (both lists
 * keep their capacity: found by fuzz_parse). */
static bool materials_list(parser *ps, scene_parse *sp)
{
    sg_scene *sc = sp->sc;
    sg_token *open = cur(ps);
    if (!expect(ps, SG_TK_LBRACK, "'['"))
        return false;
    sc->nmaterials = 0;
    if (accept(ps, SG_TK_RBRACK))
        return true;
    do {
        sg_token *m = cur(ps);
        if (!expect(ps, SG_TK_IDENT, "a material name"))
            return false;
        int n = sc->nmaterials;
        *SG_PUSH(ps->a, sc->materials, sc->nmaterials, sp->cap_materials) = tok_text(ps, m);
        *SG_PUSH(ps->a, sc->material_locs, n, sp->cap_material_locs) = loc_of(ps, m);
    } while (accept(ps, SG_TK_COMMA));
    if (cur(ps)->kind != SG_TK_RBRACK) {
        if (cur(ps)->kind == SG_TK_EOF)
            sg_error(ps->d, loc_of(ps, open), SG_E_UNTERMINATED, "'['", open->line);
        else
            expected(ps, "',' or ']'");
        return false;
    }
    next(ps);
    return true;
}

/* scene_stmt = "heightfield" "=" STRING | "heightfield_size" "=" NUM NUM
 *            | "size" "=" NUM NUM | "max_height" "=" NUM
 *            | "height_offset" "=" NUM | "cell" "=" NUM
 *            | "materials" "=" "[" IDENT { "," IDENT } "]"
 *            | "compositor" "=" IDENT
 *            | "painted" IDENT "=" STRING [painted_opts]
 *            | ("spline" | "polygon") IDENT "{" { vector_stmt } "}"
 *            | destruction | camera */
static bool scene_stmt(parser *ps, void *user)
{
    scene_parse *sp = user;
    sg_scene *sc = sp->sc;
    sg_token *key = cur(ps);
    sg_loc kloc = loc_of(ps, key);
    if (key->kind != SG_TK_IDENT) {
        expected(ps, "a scene setting or '}'");
        return false;
    }
    if (is_kw(key, "destruction")) {
        next(ps);
        sub_block b = { sp, NULL };
        sc->has_destruction = true;
        sc->destruction_loc = kloc;
        parse_block(ps, "block of destruction", sub_stmt, &b);
        return true;
    }
    if (is_kw(key, "light")) {
        next(ps);
        sc->has_light = true;
        sc->light_loc = kloc;
        parse_block(ps, "block of light", light_stmt, &sc->light);
        return true;
    }
    if (is_kw(key, "camera")) {
        next(ps);
        return camera_decl(ps, sp);
    }
    if (is_kw(key, "painted")) {
        next(ps);
        return painted_decl(ps, sp);
    }
    if (is_kw(key, "spline") || is_kw(key, "polygon")) {
        next(ps);
        return vector_decl(ps, sp, is_kw(key, "spline") ? SPLAT_VEC_SPLINE : SPLAT_VEC_POLYGON);
    }
    next(ps);
    if (!expect(ps, SG_TK_EQ, "'='"))
        return false;
    if (is_kw(key, "heightfield"))
        return heightfield_value(ps, sp);
    if (is_kw(key, "heightfield_size")) {
        double wh[2];
        if (!parse_numbers(ps, wh, 2))
            return false;
        bool whole = wh[0] >= 1 && wh[1] >= 1 && wh[0] <= INT_MAX && wh[1] <= INT_MAX &&
                     wh[0] == (int)wh[0] && wh[1] == (int)wh[1];
        sc->hf_width = whole ? (int)wh[0] : -1;
        sc->hf_height = whole ? (int)wh[1] : -1;
        sc->hf_size_loc = kloc;
        return true;
    }
    if (is_kw(key, "size")) {
        if (!parse_numbers(ps, sc->size, 2))
            return false;
        sc->size_loc = kloc;
        return true;
    }
    if (is_kw(key, "max_height")) {
        if (!parse_number(ps, &sc->max_height))
            return false;
        sc->max_height_loc = kloc;
        return true;
    }
    if (is_kw(key, "height_offset")) {
        sc->height_offset_loc = kloc;
        return parse_number(ps, &sc->height_offset);
    }
    if (is_kw(key, "cell")) {
        double c;
        if (!parse_number(ps, &c))
            return false;
        sc->cell_texels_loc = kloc;
        sc->cell_texels = c >= 1 && c <= 65536 && c == (int)c ? (int)c : -1;
        return true;
    }
    if (is_kw(key, "compositor")) {
        sg_token *name = cur(ps);
        if (!expect(ps, SG_TK_IDENT, "a compositor shader name"))
            return false;
        sc->compositor = tok_text(ps, name);
        sc->compositor_loc = loc_of(ps, name);
        return true;
    }
    if (is_kw(key, "materials")) {
        sc->materials_loc = kloc;
        return materials_list(ps, sp);
    }
    char buf[96];
    sg_error(ps->d, kloc, SG_E_SYNTAX,
             "a scene setting (heightfield, heightfield_size, size, max_height, "
             "height_offset, materials, compositor, painted, spline, polygon, destruction, "
             "cell, camera, light)",
             sg_tok_describe(key, buf, sizeof buf));
    hint_key(ps, key, sg_scene_keys);
    return false;
}

/* scene = "scene" IDENT "{" { scene_stmt } "}" */
static bool parse_scene(parser *ps)
{
    next(ps);
    sg_token *name = cur(ps);
    if (!expect(ps, SG_TK_IDENT, "a scene name"))
        return false;
    sg_scene *sc = sg_alloc(ps->a, sizeof *sc);
    sc->name = tok_text(ps, name);
    sc->loc = loc_of(ps, name);
    sc->compositor = "linear_alpha";
    sc->compositor_loc = sc->loc;
    sc->cell_texels = 32;
    sc->cell_texels_loc = sc->loc;
    sc->destruction_cell = 16;
    scene_parse sp = { .sc = sc };
    char what[160];
    snprintf(what, sizeof what, "block of scene '%s'", sc->name);
    parse_block(ps, sg_strdup(ps->a, what), scene_stmt, &sp);

    sg_scene_check(sc, ps->d);
    if (ps->fi == 0) {
        if (ps->p->scene) {
            sg_error(ps->d, sc->loc, SG_E_DUPLICATE, "scene", sc->name,
                     ps->p->scene->loc.file, ps->p->scene->loc.line, ps->p->scene->loc.col);
        } else {
            ps->p->scene = sc;
        }
    }
    return true;
}

/* file = { import | texture | shader | material | scene } */
void sg_parse(sg_program *p, int file, sg_import **imports, int *nimports, sg_diags *d)
{
    parser ps = { p, &p->arena, p->files[file], file, d, 0, imports, nimports, 0 };
    if (cur(&ps)->kind == SG_TK_EOF && d->nerrors == 0) {
        expected(&ps, "a declaration (import, texture, shader, material or scene)");
        return;
    }
    while (cur(&ps)->kind != SG_TK_EOF) {
        sg_token *t = cur(&ps);
        int line = t->line, before = ps.pos;
        bool ok;
        if (is_kw(t, "import"))
            ok = parse_import(&ps);
        else if (is_kw(t, "texture"))
            ok = parse_texture(&ps);
        else if (is_kw(t, "shader"))
            ok = parse_shader(&ps, false);
        else if (is_kw(t, "material"))
            ok = parse_shader(&ps, true);
        else if (is_kw(t, "scene"))
            ok = parse_scene(&ps);
        else {
            expected(&ps, "'import', 'texture', 'shader', 'material' or 'scene'");
            ok = false;
        }
        if (!ok) {
            /* skip to a top-level keyword that starts a line */
            do
                next(&ps);
            while (cur(&ps)->kind != SG_TK_EOF &&
                   !(top_keyword(cur(&ps)) && line_start(&ps, cur(&ps)) &&
                     cur(&ps)->line > line));
        }
        if (ps.pos == before)
            next(&ps);
    }
}

/* ---- loading ------------------------------------------------------------- */

typedef struct loader {
    sg_program *p;
    sg_diags   *d;
    const sg_overlay *ov;    /* texts held in memory, or NULL              */
    sg_map      keys;        /* file key -> index                          */
    int        *stack;       /* files being loaded (import cycle check)    */
    int         depth;
} loader;

/* Search folder s is the importing file's folder or an earlier one. */
static bool seen_before(const sg_program *p, const char *dir, int s)
{
    if (!strcmp(p->search[s], dir))
        return true;
    for (int k = 0; k < s; k++)
        if (!strcmp(p->search[k], p->search[s]))
            return true;
    return false;
}

/* An import found nowhere: the folders searched, in order, and how to add
 * one.  The errors that only follow from it (names it would have defined)
 * are left out by resolve (p->failed_imports). */
static void missing_import(loader *l, const sg_file *f, const sg_import *im)
{
    sg_program *p = l->p;
    size_t n = 256 + strlen(f->dir);
    for (int s = 0; s < p->nsearch; s++)
        n += strlen(p->search[s]) + 6;
    char *msg = xmalloc(n);
    size_t o = (size_t)snprintf(msg, n, "not found in '%s' (the importing file's folder)",
                                f->dir);
    /* each folder once, as given (the scene's folder often comes twice) */
    int last = -1;
    for (int s = 0; s < p->nsearch; s++)
        if (!seen_before(p, f->dir, s))
            last = s;
    for (int s = 0; s < p->nsearch; s++)
        if (!seen_before(p, f->dir, s))
            o += (size_t)snprintf(msg + o, n - o, "%s'%s'", s == last ? " or " : ", ",
                                  p->search[s]);
    snprintf(msg + o, n - o, "; add the folder that holds it with -I DIR or "
             "SPLATC_PATH=DIR[:DIR...]");
    sg_error(l->d, im->loc, SG_E_MISSING_IMPORT, im->path, msg);
    free(msg);
    p->failed_imports++;
}

/* The overlay's text for `path`, or NULL (read the disk). */
static const char *overlay_text(const loader *l, const char *path, size_t *len)
{
    return l->ov && l->ov->text ? l->ov->text(l->ov->user, path, len) : NULL;
}

/* Lex, parse and load the imports of `path` (text given, or read). */
static int load_file(loader *l, const char *path, const char *text, size_t len,
                     sg_loc from, bool is_import)
{
    sg_program *p = l->p;
    char *rp = realpath(path, NULL);
    const char *key = rp ? rp : path;
    int known = sg_map_get(&l->keys, key);
    if (known >= 0) {
        free(rp);
        for (int i = 0; i < l->depth; i++)
            if (l->stack[i] == known) {
                /* the cycle: stack[i] -> … -> top -> known */
                size_t n = 1;
                for (int j = i; j < l->depth; j++)
                    n += strlen(p->files[l->stack[j]]->path) + 4;
                n += strlen(p->files[known]->path);
                char *msg = xmalloc(n);
                msg[0] = 0;
                for (int j = i; j < l->depth; j++) {
                    strcat(msg, p->files[l->stack[j]]->path);
                    strcat(msg, " -> ");
                }
                strcat(msg, p->files[known]->path);
                sg_error(l->d, from, SG_E_IMPORT_CYCLE, msg);
                free(msg);
                break;
            }
        return known;
    }
    if (l->depth >= SG_MAX_DEPTH) {
        free(rp);
        sg_error(l->d, from, SG_E_TOO_DEEP, SG_MAX_DEPTH);
        return -1;
    }
    char *owned = NULL;
    if (!text && (text = overlay_text(l, path, &len)) && len > SPLAT_MAX_GRAPH_BYTES) {
        free(rp);
        sg_errorf(l->d, from, is_import ? SG_E_MISSING_IMPORT : SG_E_IO,
                  is_import ? "cannot import '%s': %s" : "cannot read '%s': %s", path,
                  "larger than the 16 MiB a graph file may have");
        if (is_import)
            p->failed_imports++;
        return -1;
    }
    if (!text) {
        /* only regular files: an import of /dev/zero or a FIFO must not hang */
        char err[256];
        owned = splat_input_read(path, SPLAT_MAX_GRAPH_BYTES, &len, err, sizeof err);
        if (!owned) {
            free(rp);
            if (is_import) {
                sg_error(l->d, from, SG_E_MISSING_IMPORT, path, err);
                p->failed_imports++;
            }
            else
                sg_error(l->d, from, SG_E_IO, path, err);
            return -1;
        }
        text = owned;
    }
    sg_file *f = sg_alloc(&p->arena, sizeof *f);
    f->path = sg_strdup(&p->arena, path);
    char *dir = splat_path_dir(path);
    f->dir = sg_strdup(&p->arena, dir);
    free(dir);
    f->key = sg_strdup(&p->arena, key);
    f->from = from;
    if (!is_import)
        f->from.file = f->path;   /* the caller's string need not outlive the load */
    free(rp);
    f->text = sg_alloc(&p->arena, len + 1);
    memcpy(f->text, text, len);
    f->len = len;
    free(owned);
    int fi = p->nfiles;
    *SG_PUSH(&p->arena, p->files, p->nfiles, p->capfiles) = f;
    sg_map_put(&l->keys, f->key, fi);
    sg_diags_add_source(l->d, f->path, f->text, f->len);

    sg_lex(&p->arena, f, l->d);
    sg_import *imports = NULL;
    int nimports = 0;
    sg_parse(p, fi, &imports, &nimports, l->d);

    l->stack[l->depth++] = fi;
    for (int i = 0; i < nimports; i++) {
        /* relative to the importing file, then the search paths */
        char *cand = splat_path_join(f->dir, imports[i].path);
        size_t olen;
        bool found = access(cand, R_OK) == 0 || overlay_text(l, cand, &olen);
        for (int s = 0; !found && s < p->nsearch; s++) {
            free(cand);
            cand = splat_path_join(p->search[s], imports[i].path);
            found = access(cand, R_OK) == 0 || overlay_text(l, cand, &olen);
        }
        if (!found) {
            free(cand);
            missing_import(l, f, &imports[i]);
            continue;
        }
        load_file(l, cand, NULL, 0, imports[i].loc, true);
        free(cand);
    }
    l->depth--;
    return fi;
}

static sg_program *load(const char *path, const char *text, size_t len,
                        const char *const *search_paths, const sg_overlay *ov,
                        sg_diags *d)
{
    sg_program *p = calloc(1, sizeof *p);
    if (!p)
        return NULL;
    int nsearch = 0;
    while (search_paths && search_paths[nsearch])
        nsearch++;
    p->search = sg_alloc(&p->arena, (size_t)(nsearch + 1) * sizeof *p->search);
    for (int i = 0; i < nsearch; i++)
        p->search[i] = sg_strdup(&p->arena, search_paths[i]);
    p->nsearch = nsearch;

    int errors0 = d->nerrors;
    loader l = { p, d, ov, { 0 }, NULL, 0 };
    l.stack = xmalloc(SG_MAX_DEPTH * sizeof *l.stack);
    load_file(&l, path, text, len, (sg_loc){ path, 0, 0 }, false);
    free(l.stack);
    sg_map_free(&l.keys);
    if (p->nfiles)
        sg_resolve(p, d);
    p->load_errors = d->nerrors - errors0;   /* this load's errors only */
    return p;
}

sg_program *sg_load(const char *path, const char *const *search_paths, sg_diags *d)
{
    return load(path, NULL, 0, search_paths, NULL, d);
}

sg_program *sg_load_overlay(const char *path, const char *const *search_paths,
                            const sg_overlay *ov, sg_diags *d)
{
    return load(path, NULL, 0, search_paths, ov, d);
}

sg_program *sg_load_string(const char *name, const char *text,
                           const char *const *search_paths, sg_diags *d)
{
    return load(name, text, strlen(text), search_paths, NULL, d);
}

void sg_free(sg_program *p)
{
    if (!p)
        return;
    for (int i = 0; i < p->nshaders; i++)
        free(p->shaders[i]->order);
    sg_map_free(&p->globals);
    sg_arena_free(&p->arena);
    free(p);
}

int sg_file_count(const sg_program *p) { return p->nfiles; }
const char *sg_file_path(const sg_program *p, int i) { return p->files[i]->path; }
int sg_material_count(const sg_program *p) { return p->nmaterials; }
const char *sg_material_name(const sg_program *p, int i)
{
    return p->shaders[p->materials[i]]->name;
}
sg_loc sg_material_loc(const sg_program *p, int i)
{
    return p->shaders[p->materials[i]]->loc;
}

int sg_material_find(const sg_program *p, const char *name)
{
    for (int i = 0; i < p->nmaterials; i++)
        if (!strcmp(p->shaders[p->materials[i]]->name, name))
            return i;
    return -1;
}
const sg_scene *sg_program_scene(const sg_program *p) { return p->scene; }
int sg_undergrowth_count(const sg_program *p, int material)
{
    return p->shaders[p->materials[material]]->nug;
}
const sg_undergrowth *sg_undergrowth_get(const sg_program *p, int material, int k)
{
    return &p->shaders[p->materials[material]]->ug[k];
}
