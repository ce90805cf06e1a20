/* parse.c — the .sg parser (tokens -> AST): a file's top level (sg_parse)
 * and its declarations: imports, textures, shaders and materials with
 * their nodes, ports and params.  The undergrowth blocks are
 * parse_undergrowth.c's, the scene parse_scene.c's, the shared machinery
 * (tokens, values, blocks, recovery) parse_base.c's; loading files and
 * imports is load.c's.
 *
 * Recursive descent over the token array, one function per rule with the
 * rule above it. */
#include "parse.h"
#include "sg_internal.h"
#include "util.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- declarations inside shaders and materials -------------------------- */

static void add_node_binding(parser *ps, void *user, sg_token *key, sg_value *v)
{
    sg_node *n = user;
    sg_binding *b = SG_PUSH(ps->a, n->args, n->nargs, n->capargs);
    b->port = ps_tok_text(ps, key);
    b->loc = ps_loc_of(ps, key);
    b->val = *v;
    b->slot = -1;
}

/* node = "node" IDENT ":" path [ bindings ] */
static bool parse_node(parser *ps, sg_shader *s)
{
    ps_next(ps);
    sg_token *name = ps_cur(ps);
    if (!ps_expect(ps, SG_TK_IDENT, "a node name"))
        return false;
    if (!ps_expect(ps, SG_TK_COLON, "':' and a node type"))
        return false;
    sg_value type;
    memset(&type, 0, sizeof type);
    if (!ps_path(ps, &type))
        return false;
    sg_node *n = SG_PUSH(ps->a, s->nodes, s->nnodes, s->capnodes);
    n->name = ps_tok_text(ps, name);
    n->loc = ps_loc_of(ps, name);
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
    if (ps_cur(ps)->kind == SG_TK_LBRACE) {
        char what[160];
        snprintf(what, sizeof what, "'{' of node '%s'", n->name);
        n->incomplete = !ps_bindings(ps, sg_strdup(ps->a, what), add_node_binding, n);
    }
    return true;
}

/* in = "in" TYPE IDENT [ "=" value ] */
static bool parse_in(parser *ps, sg_shader *s)
{
    ps_next(ps);
    ir_type t = ps_type_name(ps_cur(ps));
    if (t == IR_T_ERROR) {
        ps_expected(ps, "a type (float, vec2, vec3, vec4 or texture)");
        return false;
    }
    ps_next(ps);
    sg_token *name = ps_cur(ps);
    if (!ps_expect(ps, SG_TK_IDENT, "an input name"))
        return false;
    sg_port port = { .name = ps_tok_text(ps, name), .loc = ps_loc_of(ps, name), .type = t };
    if (ps_accept(ps, SG_TK_EQ)) {
        if (!ps_value(ps, &port.value))
            return false;
        port.has_value = true;
    }
    *SG_PUSH(ps->a, s->ins, s->nins, s->capins) = port;
    return true;
}

/* out = "out" [ TYPE ] IDENT "=" value */
static bool parse_out(parser *ps, sg_shader *s)
{
    ps_next(ps);
    ir_type t = IR_T_ERROR;
    if (ps_type_name(ps_cur(ps)) != IR_T_ERROR && ps_peek_at(ps, 1)->kind == SG_TK_IDENT) {
        t = ps_type_name(ps_cur(ps));
        ps_next(ps);
    } else if (!s->is_material) {
        ps_expected(ps, "an output type (float, vec2, vec3, vec4 or texture)");
        return false;
    }
    sg_token *name = ps_cur(ps);
    if (!ps_expect(ps, SG_TK_IDENT, "an output name"))
        return false;
    sg_port port = { .name = ps_tok_text(ps, name), .loc = ps_loc_of(ps, name), .type = t,
                     .output = -1 };
    if (!ps_expect(ps, SG_TK_EQ, "'='") || !ps_value(ps, &port.value))
        return false;
    port.has_value = true;
    *SG_PUSH(ps->a, s->outs, s->nouts, s->capouts) = port;
    return true;
}

/* param = "param" TYPE IDENT "=" value [ "range" NUMBER NUMBER ] */
static bool parse_param(parser *ps, sg_shader *s)
{
    ps_next(ps);
    ir_type t = ps_type_name(ps_cur(ps));
    if (t == IR_T_ERROR || t == IR_T_TEX) {
        ps_expected(ps, "a param type (float, vec2, vec3 or vec4)");
        return false;
    }
    ps_next(ps);
    sg_token *name = ps_cur(ps);
    if (!ps_expect(ps, SG_TK_IDENT, "a param name"))
        return false;
    sg_port port = { .name = ps_tok_text(ps, name), .loc = ps_loc_of(ps, name), .type = t };
    if (!ps_expect(ps, SG_TK_EQ, "'=' and a default value") || !ps_value(ps, &port.value))
        return false;
    port.has_value = true;
    if (ps_is_kw(ps_cur(ps), "range")) {
        ps_next(ps);
        if (!ps_number(ps, &port.lo) || !ps_number(ps, &port.hi))
            return false;
        port.has_range = true;
    }
    *SG_PUSH(ps->a, s->params, s->nparams, s->capparams) = port;
    return true;
}

/* shader_stmt   = in | out | node
 * material_stmt = param | out | node | undergrowth */
static bool shader_stmt(parser *ps, void *user)
{
    sg_shader *s = user;
    sg_token *t = ps_cur(ps);
    if (ps_is_kw(t, "node"))
        return parse_node(ps, s);
    if (ps_is_kw(t, "out"))
        return parse_out(ps, s);
    if (!s->is_material && ps_is_kw(t, "in"))
        return parse_in(ps, s);
    if (s->is_material && ps_is_kw(t, "param"))
        return parse_param(ps, s);
    if (s->is_material && ps_is_kw(t, "undergrowth"))
        return ps_undergrowth(ps, s);
    ps_expected(ps, s->is_material ? "'param', 'node', 'out', 'undergrowth' or '}'"
                                : "'in', 'node', 'out' or '}'");
    return false;
}

/* shader   = "shader" IDENT "{" { shader_stmt } "}"
 * material = "material" IDENT "{" { material_stmt } "}" */
static bool parse_shader(parser *ps, bool material)
{
    ps_next(ps);
    sg_token *name = ps_cur(ps);
    if (!ps_expect(ps, SG_TK_IDENT, material ? "a material name" : "a shader name"))
        return false;
    sg_shader *s = sg_alloc(ps->a, sizeof *s);
    s->name = ps_tok_text(ps, name);
    s->loc = ps_loc_of(ps, name);
    s->is_material = material;
    s->file = ps->fi;
    sg_program *p = ps->p;
    *SG_PUSH(ps->a, p->shaders, p->nshaders, p->capshaders) = s;
    if (material)
        *SG_PUSH(ps->a, p->materials, p->nmaterials, p->capmaterials) = p->nshaders - 1;
    char what[160];
    snprintf(what, sizeof what, "block of %s '%s'", material ? "material" : "shader", s->name);
    ps_block(ps, sg_strdup(ps->a, what), shader_stmt, s);
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
    if (ps_is_kw(key, "file")) {
        if (v->kind != SG_V_STRING)
            bad_setting(ps, v, "file", "a string");
        else {
            char *path = splat_path_join(ps->f->dir, v->str);
            t->file = sg_strdup(ps->a, path);
            t->file_loc = v->loc;
            free(path);
        }
    } else if (ps_is_kw(key, "filter") || ps_is_kw(key, "mip")) {
        ir_filter *f = ps_is_kw(key, "mip") ? &t->mip : &t->filter;
        int k = ir_filter_by_name(word_of(v));
        if (k >= 0)
            *f = (ir_filter)k;
        else
            bad_setting(ps, v, ps_is_kw(key, "mip") ? "mip" : "filter", "linear or nearest");
    } else if (ps_is_kw(key, "wrap")) {
        int k = ir_wrap_by_name(word_of(v));
        if (k >= 0)
            t->wrap = (ir_wrap)k;
        else
            bad_setting(ps, v, "wrap", "repeat, clamp or mirror");
    } else if (ps_is_kw(key, "srgb")) {
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
        sg_error(ps->d, ps_loc_of(ps, key), SG_E_BAD_OPTION, msg);
        ps_hint_key(ps, key, sg_texture_keys);
    }
}

/* texture = "texture" IDENT "{" { ("file" | "filter" | "mip" | "wrap" |
 *           "srgb") "=" value [","] } "}" */
static bool parse_texture(parser *ps)
{
    ps_next(ps);
    sg_token *name = ps_cur(ps);
    if (!ps_expect(ps, SG_TK_IDENT, "a texture name"))
        return false;
    sg_texdecl *t = sg_alloc(ps->a, sizeof *t);
    t->name = ps_tok_text(ps, name);
    t->loc = ps_loc_of(ps, name);
    sg_texdecl_defaults(t);
    char what[160];
    snprintf(what, sizeof what, "block of texture '%s'", t->name);
    ps_bindings(ps, sg_strdup(ps->a, what), add_texture_setting, t);
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
    ps_next(ps);
    sg_token *t = ps_cur(ps);
    if (!ps_expect(ps, SG_TK_STRING, "a file name in quotes"))
        return false;
    sg_import *im = SG_PUSH(ps->a, *ps->imports, *ps->nimports, ps->capimports);
    im->path = t->str;
    im->loc = ps_loc_of(ps, t);
    return true;
}

/* file = { import | texture | shader | material | scene } */
void sg_parse(sg_program *p, int file, sg_import **imports, int *nimports, sg_diags *d)
{
    parser ps = { p, &p->arena, p->files[file], file, d, 0, imports, nimports, 0 };
    if (ps_cur(&ps)->kind == SG_TK_EOF && d->nerrors == 0) {
        ps_expected(&ps, "a declaration (import, texture, shader, material or scene)");
        return;
    }
    while (ps_cur(&ps)->kind != SG_TK_EOF) {
        sg_token *t = ps_cur(&ps);
        int line = t->line, before = ps.pos;
        bool ok;
        if (ps_is_kw(t, "import"))
            ok = parse_import(&ps);
        else if (ps_is_kw(t, "texture"))
            ok = parse_texture(&ps);
        else if (ps_is_kw(t, "shader"))
            ok = parse_shader(&ps, false);
        else if (ps_is_kw(t, "material"))
            ok = parse_shader(&ps, true);
        else if (ps_is_kw(t, "scene"))
            ok = ps_scene(&ps);
        else {
            ps_expected(&ps, "'import', 'texture', 'shader', 'material' or 'scene'");
            ok = false;
        }
        if (!ok) {
            /* skip to a top-level keyword that starts a line */
            do
                ps_next(&ps);
            while (ps_cur(&ps)->kind != SG_TK_EOF &&
                   !(ps_top_keyword(ps_cur(&ps)) && ps_line_start(&ps, ps_cur(&ps)) &&
                     ps_cur(&ps)->line > line));
        }
        if (ps.pos == before)
            ps_next(&ps);
    }
}
