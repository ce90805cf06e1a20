/* parse_base.c — the .sg parser's shared machinery (parse.h): the token
 * cursor, "expected X" errors with their "did you mean" hints, error
 * recovery to the next line, values (numbers, strings, vectors, paths),
 * binding lists `{ key = value, … }`, statement blocks `{ … }`, and the
 * keys each settings block takes.  The rule files (parse.c,
 * parse_undergrowth.c, parse_scene.c) build on it.
 *
 * Newlines are not tokens, but they guide error recovery: after a syntax
 * error the parser skips to the next line (or the `}` that closes the
 * block) and goes on, so one run reports several errors.  A top-level
 * keyword at the start of a line inside a block means the block was never
 * closed: UNTERMINATED, pointing at its `{`. */
#include "parse.h"
#include "sg_internal.h"
#include "util.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

sg_token *ps_cur(parser *ps) { return &ps->f->toks[ps->pos]; }
sg_token *ps_peek_at(parser *ps, int k)
{
    int i = ps->pos + k;
    return &ps->f->toks[i < ps->f->ntoks ? i : ps->f->ntoks - 1];
}
sg_token *ps_next(parser *ps)
{
    sg_token *t = ps_cur(ps);
    if (t->kind != SG_TK_EOF)
        ps->pos++;
    return t;
}

sg_loc ps_loc_of(parser *ps, const sg_token *t)
{
    return (sg_loc){ ps->f->path, t->line, t->col };
}

bool ps_is_kw(const sg_token *t, const char *kw)
{
    return t->kind == SG_TK_IDENT && (int)strlen(kw) == t->len &&
           !memcmp(t->start, kw, (size_t)t->len);
}

/* First token of its line? */
bool ps_line_start(parser *ps, const sg_token *t)
{
    int i = (int)(t - ps->f->toks);
    return i == 0 || ps->f->toks[i - 1].line < t->line;
}

bool ps_top_keyword(const sg_token *t)
{
    return ps_is_kw(t, "import") || ps_is_kw(t, "texture") || ps_is_kw(t, "shader") ||
           ps_is_kw(t, "material") || ps_is_kw(t, "scene");
}

char *ps_tok_text(parser *ps, const sg_token *t)
{
    return sg_strndup(ps->a, t->start, (size_t)t->len);
}

/* "expected <what>, found <current token>" at the current token. */
void ps_expected(parser *ps, const char *what)
{
    char buf[96];
    sg_token *t = ps_cur(ps);
    sg_error(ps->d, ps_loc_of(ps, t), SG_E_SYNTAX, what,
             sg_tok_describe(t, buf, sizeof buf));
}

/* "did you mean" for a misspelt setting `key` among `keys` (NULL-ended),
 * on the diagnostic just reported. */
void ps_hint_key(parser *ps, const sg_token *key, const char *const *keys)
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

bool ps_accept(parser *ps, sg_tok_kind k)
{
    if (ps_cur(ps)->kind != k)
        return false;
    ps_next(ps);
    return true;
}

bool ps_expect(parser *ps, sg_tok_kind k, const char *what)
{
    if (ps_accept(ps, k))
        return true;
    ps_expected(ps, what);
    return false;
}

/* Skip the rest of a bad statement: up to the next line or the `}` that
 * closes the enclosing block (not consumed); nested braces are skipped. */
static void sync_statement(parser *ps, int line)
{
    int depth = 0;
    for (;;) {
        sg_token *t = ps_cur(ps);
        if (t->kind == SG_TK_EOF)
            return;
        if (depth == 0 && (t->kind == SG_TK_RBRACE || t->line > line))
            return;
        if (t->kind == SG_TK_LBRACE)
            depth++;
        else if (t->kind == SG_TK_RBRACE)
            depth--;
        ps_next(ps);
    }
}

ir_type ps_type_name(const sg_token *t)
{
    static const char *const names[] = { "float", "vec2", "vec3", "vec4", "texture" };
    static const ir_type types[] = { IR_T_FLOAT, IR_T_VEC2, IR_T_VEC3, IR_T_VEC4, IR_T_TEX };
    for (int i = 0; i < 5; i++)
        if (ps_is_kw(t, names[i]))
            return types[i];
    return IR_T_ERROR;
}

/* path = IDENT { "." IDENT } */
bool ps_path(parser *ps, sg_value *v)
{
    sg_token *t = ps_cur(ps);
    if (t->kind != SG_TK_IDENT) {
        ps_expected(ps, "a name");
        return false;
    }
    v->kind = SG_V_PATH;
    v->loc = ps_loc_of(ps, t);
    int cap = 0;
    for (;;) {
        char **slot = SG_PUSH(ps->a, v->parts, v->nparts, cap);
        *slot = ps_tok_text(ps, ps_next(ps));
        if (ps_cur(ps)->kind != SG_TK_DOT)
            return true;
        ps_next(ps);
        if (ps_cur(ps)->kind != SG_TK_IDENT) {
            ps_expected(ps, "a name after '.'");
            return false;
        }
    }
}

/* value = NUMBER
 *       | ("vec2" | "vec3" | "vec4") "(" NUMBER { "," NUMBER } ")"
 *       | STRING
 *       | path */
bool ps_value(parser *ps, sg_value *v)
{
    sg_token *t = ps_cur(ps);
    memset(v, 0, sizeof *v);
    v->loc = ps_loc_of(ps, t);
    if (t->kind == SG_TK_NUMBER) {
        ps_next(ps);
        v->kind = SG_V_NUMBER;
        v->num[0] = t->num;
        v->width = 1;
        return true;
    }
    if (t->kind == SG_TK_STRING) {
        ps_next(ps);
        v->kind = SG_V_STRING;
        v->str = t->str;
        return true;
    }
    ir_type vt = ps_type_name(t);
    if (vt >= IR_T_VEC2 && vt <= IR_T_VEC4 && ps_peek_at(ps, 1)->kind == SG_TK_LPAREN) {
        int w = ir_type_width(vt);
        ps_next(ps);
        sg_token *open = ps_next(ps);
        int n = 0;
        do {
            if (ps_cur(ps)->kind != SG_TK_NUMBER) {
                ps_expected(ps, "a number");
                return false;
            }
            double x = ps_next(ps)->num;
            if (n < 4)
                v->num[n] = x;
            n++;
        } while (ps_accept(ps, SG_TK_COMMA));
        if (ps_cur(ps)->kind != SG_TK_RPAREN) {
            if (ps_cur(ps)->kind == SG_TK_EOF || ps_cur(ps)->line > open->line)
                sg_error(ps->d, ps_loc_of(ps, open), SG_E_UNTERMINATED, "'('", open->line);
            else
                ps_expected(ps, "',' or ')'");
            return false;
        }
        ps_next(ps);
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
        return ps_path(ps, v);
    ps_expected(ps, "a value (number, vecN(...), string or name)");
    return false;
}

/* bindings = "{" { IDENT "=" value [","] } "}"
 * `what` names the block for UNTERMINATED ("'{' of node 'd'").  Each
 * binding goes through `add`; a bad one is skipped up to the next ',',
 * line or '}'. */

/* A statement keyword starting a line (not a binding `out = …`)? */
static bool starts_statement(parser *ps, const sg_token *t)
{
    return ps_line_start(ps, t) && ps_peek_at(ps, 1)->kind != SG_TK_EQ &&
           (ps_is_kw(t, "node") || ps_is_kw(t, "out") || ps_is_kw(t, "in") || ps_is_kw(t, "param") ||
            ps_is_kw(t, "undergrowth"));
}

/* Returns false if the list had errors (some bindings may be missing). */
bool ps_bindings(parser *ps, const char *what, binding_fn add, void *user)
{
    sg_token *open = ps_cur(ps);
    bool clean = true;
    if (!ps_expect(ps, SG_TK_LBRACE, "'{'"))
        return false;
    for (;;) {
        sg_token *t = ps_cur(ps);
        if (t->kind == SG_TK_RBRACE) {
            ps_next(ps);
            return clean;
        }
        if (t->kind == SG_TK_EOF || (ps_top_keyword(t) && ps_line_start(ps, t)) ||
            (t->line > open->line && starts_statement(ps, t))) {
            sg_error(ps->d, ps_loc_of(ps, open), SG_E_UNTERMINATED, what, open->line);
            return false;
        }
        int line = t->line;
        sg_value v;
        bool ok = false;
        if (t->kind != SG_TK_IDENT) {
            ps_expected(ps, "a port name or '}'");
        } else {
            ps_next(ps);
            if (ps_expect(ps, SG_TK_EQ, "'='") && ps_value(ps, &v)) {
                add(ps, user, t, &v);
                ok = true;
            }
        }
        if (ok) {
            ps_accept(ps, SG_TK_COMMA);
            continue;
        }
        clean = false;
        /* skip to ',' / '}' / next line */
        while (ps_cur(ps)->kind != SG_TK_EOF && ps_cur(ps)->kind != SG_TK_RBRACE &&
               ps_cur(ps)->kind != SG_TK_COMMA && ps_cur(ps)->line == line)
            ps_next(ps);
        ps_accept(ps, SG_TK_COMMA);
    }
}

bool ps_number(parser *ps, double *x)
{
    if (ps_cur(ps)->kind != SG_TK_NUMBER) {
        ps_expected(ps, "a number");
        return false;
    }
    *x = ps_next(ps)->num;
    return true;
}


/* A block `{ statement* }` whose statements `stmt` parses; returns when the
 * block is closed (or found unterminated). */
void ps_block(parser *ps, const char *what, stmt_fn stmt, void *user)
{
    ps_block_in(ps, what, stmt, user, false);
}

/* in_material: a block inside a material's, so a material statement
 * starting a later line (`node`, `out`, …) also means it was not closed. */
void ps_block_in(parser *ps, const char *what, stmt_fn stmt, void *user,
                 bool in_material)
{
    sg_token *open = ps_cur(ps);
    if (!ps_expect(ps, SG_TK_LBRACE, "'{'"))
        return;
    for (;;) {
        sg_token *t = ps_cur(ps);
        if (t->kind == SG_TK_RBRACE) {
            ps_next(ps);
            return;
        }
        if (t->kind == SG_TK_EOF || (ps_top_keyword(t) && ps_line_start(ps, t)) ||
            (in_material && t->line > open->line && starts_statement(ps, t))) {
            sg_error(ps->d, ps_loc_of(ps, open), SG_E_UNTERMINATED, what, open->line);
            return;
        }
        int line = t->line;
        int before = ps->pos;
        if (!stmt(ps, user)) {
            sync_statement(ps, line);
            if (ps->pos == before)
                ps_next(ps);           /* always make progress */
        }
    }
}

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
