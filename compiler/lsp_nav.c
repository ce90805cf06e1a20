/* lsp_nav.c — hover and go-to-definition: what the word under the cursor
 * names, found in the analysed program's AST (never by parsing again).
 *
 * The word is the token at the cursor in the document's own tokens; a
 * dotted name (`n.out`, `terrain.slope`) is taken from its first token,
 * with the part under the cursor.  It is then matched by location against
 * the document's declarations: shader and material names, ports (`in`,
 * `out`, `param`), nodes, their types and port bindings, the names values
 * refer to (resolved by resolve.c: a node, an input or param, a texture,
 * a terrain input), textures, the scene's materials and compositor, and
 * `import` strings.  What it names is an `entity`, which hover describes
 * (type, default, doc comment: sg_doc_comment) and definition locates:
 *
 *     node r : ramp { lo = 0.3 }     hover `lo`   -> in float lo = 0.0, its comment
 *                                    definition `ramp` -> nodes/masks.sg:7:8
 */
#include "lsp.h"
#include "scene_load.h"
#include "util.h"

#include <stdlib.h>
#include <string.h>
#include <unistd.h>

typedef enum ent_kind {
    ENT_NONE,
    ENT_SHADER,     /* a shader or material: p->shaders[index]             */
    ENT_PORT,       /* port `index` of shader `shader`, role "in"/"out"/"param" */
    ENT_NODE,       /* node `index` of shader `shader`                     */
    ENT_OP,         /* built-in op `index`                                 */
    ENT_OP_PORT,    /* port `port` of built-in op `index`                  */
    ENT_INPUT,      /* terrain or view input `index`                       */
    ENT_TEXTURE,    /* p->textures[index]                                  */
    ENT_PAINTED,    /* the `painted` node type                             */
    ENT_FILE,       /* an imported file (path)                             */
} ent_kind;

typedef struct entity {
    ent_kind    kind;
    int         shader, index, port;
    const char *role;
    char       *path;       /* ENT_FILE, malloc'd */
    const sg_token *tok;    /* the word under the cursor */
} entity;

/* ---- words ------------------------------------------------------------------ */

/* The name, string or number token at byte `at` (at its end counts), or -1. */
static int token_at(const sg_file *f, size_t at)
{
    int best = -1;
    for (int i = 0; i < f->ntoks; i++) {
        const sg_token *t = &f->toks[i];
        size_t a = (size_t)(t->start - f->text), b = a + (size_t)t->len;
        if (a > at)
            break;
        if (t->kind != SG_TK_IDENT && t->kind != SG_TK_STRING && t->kind != SG_TK_NUMBER)
            continue;
        if (at < b)
            return i;
        if (at == b)
            best = i;
    }
    return best;
}

static bool at_loc(const sg_token *t, sg_loc loc)
{
    return loc.line == t->line && loc.col == t->col;
}

/* Index of the shader called `name` (a material too), or -1. */
static int shader_named(const sg_program *p, const char *name)
{
    for (int i = 0; i < p->nshaders; i++)
        if (!strcmp(p->shaders[i]->name, name))
            return i;
    return -1;
}

static int port_named(const sg_port *ports, int n, const char *name)
{
    for (int i = 0; i < n; i++)
        if (!strcmp(ports[i].name, name))
            return i;
    return -1;
}

/* ---- what the word names ------------------------------------------------------ */

/* A node's type: the op, input, painted or shader it is. */
static entity node_type(const sg_program *p, const sg_node *n)
{
    entity e = { ENT_NONE };
    switch (n->kind) {
    case SG_NODE_OP:       e.kind = ENT_OP; e.index = n->op; break;
    case SG_NODE_INPUT:    e.kind = ENT_INPUT; e.index = SG_INPUT_OF(n->op); break;
    case SG_NODE_PAINTED:  e.kind = ENT_PAINTED; break;
    case SG_NODE_INSTANCE: e.kind = ENT_SHADER; e.index = n->shader; break;
    default:
        /* not resolved (errors elsewhere): look the name up alone */
        if ((e.index = shader_named(p, n->type)) >= 0)
            e.kind = ENT_SHADER;
        else if ((e.index = ir_op_by_name(n->type)) >= 0)
            e.kind = ENT_OP;
        else if ((e.index = ir_input_by_name(n->type)) >= 0)
            e.kind = ENT_INPUT;
        break;
    }
    return e;
}

/* Part `part` of value v (a path) in the scope of shader si. */
static entity value_ref(const sg_program *p, int si, const sg_value *v, int part)
{
    const sg_shader *s = p->shaders[si];
    entity e = { ENT_NONE };
    switch (v->ref) {
    case SG_REF_NODE: {
        const sg_node *n = &s->nodes[v->node];
        e.kind = ENT_NODE;
        e.shader = si;
        e.index = v->node;
        if (part == 1 && n->kind == SG_NODE_INSTANCE &&
            port_named(p->shaders[n->shader]->outs, p->shaders[n->shader]->nouts,
                       v->parts[1]) >= 0) {
            e = (entity){ ENT_PORT, n->shader, v->index, 0, "out" };
        }
        break;
    }
    case SG_REF_IN:      e = (entity){ ENT_PORT, si, v->index, 0, "in" }; break;
    case SG_REF_PARAM:   e = (entity){ ENT_PORT, si, v->index, 0, "param" }; break;
    case SG_REF_TEXTURE: e.kind = ENT_TEXTURE; e.index = v->index; break;
    case SG_REF_INPUT:   e.kind = ENT_INPUT; e.index = v->index; break;
    default:
        if (v->nparts >= 2) {               /* unresolved terrain.x */
            char name[160];
            snprintf(name, sizeof name, "%s.%s", v->parts[0], v->parts[1]);
            if ((e.index = ir_input_by_name(name)) >= 0)
                e.kind = ENT_INPUT;
        }
        break;
    }
    return e;
}

/* An import string's file, found as the loader finds it. */
static char *import_target(lsp_server *s, const sg_program *p, const sg_token *t)
{
    char *cand = splat_path_join(p->files[0]->dir, t->str);
    for (int k = -1; k < p->nsearch; k++) {
        if (k >= 0) {
            free(cand);
            cand = splat_path_join(p->search[k], t->str);
        }
        char *canon = lsp_canonical(cand);
        bool found = access(canon, R_OK) == 0 || lsp_doc_by_path(s, canon);
        free(cand);
        cand = canon;
        if (found)
            return cand;
    }
    free(cand);
    return NULL;
}

static entity find(lsp_server *s, const sg_program *p, size_t at)
{
    entity none = { ENT_NONE };
    const sg_file *f = p->files[0];
    int ti = token_at(f, at);
    if (ti < 0)
        return none;
    const sg_token *t = &f->toks[ti];
    /* the first token of a dotted name, and which part the cursor is on */
    int first = ti, part = 0;
    while (first >= 2 && f->toks[first - 1].kind == SG_TK_DOT &&
           f->toks[first - 2].kind == SG_TK_IDENT)
        first -= 2, part++;
    const sg_token *t0 = &f->toks[first];
    entity e = none;
    if (t->kind == SG_TK_STRING && ti > 0 && f->toks[ti - 1].kind == SG_TK_IDENT &&
        f->toks[ti - 1].len == 6 && !memcmp(f->toks[ti - 1].start, "import", 6)) {
        char *path = import_target(s, p, t);
        if (path)
            e = (entity){ .kind = ENT_FILE, .path = path };
    }
    for (int si = 0; e.kind == ENT_NONE && si < p->nshaders; si++) {
        const sg_shader *sh = p->shaders[si];
        if (sh->file != 0)
            continue;
        if (at_loc(t, sh->loc)) {
            e = (entity){ ENT_SHADER, 0, si };
            break;
        }
        static const char *const roles[] = { "in", "out", "param" };
        const sg_port *lists[] = { sh->ins, sh->outs, sh->params };
        int counts[] = { sh->nins, sh->nouts, sh->nparams };
        for (int r = 0; e.kind == ENT_NONE && r < 3; r++)
            for (int k = 0; k < counts[r]; k++) {
                const sg_port *port = &lists[r][k];
                if (at_loc(t, port->loc))
                    e = (entity){ ENT_PORT, si, k, 0, roles[r] };
                else if (port->has_value && port->value.kind == SG_V_PATH &&
                         at_loc(t0, port->value.loc))
                    e = value_ref(p, si, &port->value, part);
            }
        for (int k = 0; e.kind == ENT_NONE && k < sh->nnodes; k++) {
            const sg_node *n = &sh->nodes[k];
            if (at_loc(t, n->loc)) {
                e = (entity){ ENT_NODE, si, k };
            } else if (at_loc(t0, n->type_loc)) {
                e = node_type(p, n);
            }
            for (int b = 0; e.kind == ENT_NONE && b < n->nargs; b++) {
                const sg_binding *bd = &n->args[b];
                if (at_loc(t, bd->loc)) {
                    entity callee = node_type(p, n);
                    if (callee.kind == ENT_SHADER) {
                        const sg_shader *c = p->shaders[callee.index];
                        int k2 = port_named(c->ins, c->nins, bd->port);
                        if (k2 >= 0)
                            e = (entity){ ENT_PORT, callee.index, k2, 0, "in" };
                    } else if (callee.kind == ENT_OP) {
                        const ir_opinfo *in = ir_opinfo_get((ir_op)callee.index);
                        for (int k2 = 0; k2 < in->nargs && k2 < 4; k2++)
                            if (in->ports[k2] && !strcmp(in->ports[k2], bd->port))
                                e = (entity){ ENT_OP_PORT, 0, callee.index, k2 };
                    } else if (callee.kind == ENT_PAINTED) {
                        e.kind = ENT_PAINTED;
                    }
                } else if (bd->val.kind == SG_V_PATH && at_loc(t0, bd->val.loc)) {
                    e = value_ref(p, si, &bd->val, part);
                }
            }
        }
    }
    for (int k = 0; e.kind == ENT_NONE && k < p->ntextures; k++)
        if (at_loc(t, p->textures[k]->loc) && p->textures[k]->loc.file &&
            !strcmp(p->textures[k]->loc.file, f->path))
            e = (entity){ .kind = ENT_TEXTURE, .index = k };
    const sg_scene *sc = p->scene;
    for (int k = 0; sc && e.kind == ENT_NONE && k < sc->nmaterials; k++)
        if (at_loc(t, sc->material_locs[k]) && (e.index = shader_named(p, sc->materials[k])) >= 0)
            e.kind = ENT_SHADER;
    if (sc && e.kind == ENT_NONE && sc->compositor && at_loc(t, sc->compositor_loc) &&
        (e.index = shader_named(p, sc->compositor)) >= 0)
        e.kind = ENT_SHADER;
    e.tok = t;
    return e;
}

/* ---- words for hover and completion --------------------------------------------- */

void lsp_port_text(const sg_port *port, const char *role, char *buf, size_t n)
{
    char v[256] = "";
    if (port->has_value)
        sg_value_text(&port->value, v, sizeof v);
    size_t o = (size_t)snprintf(buf, n, "%s%s%s %s%s%s", role, port->type != IR_T_ERROR ? " " : "",
                                port->type != IR_T_ERROR ? ir_type_name(port->type) : "",
                                port->name, *v ? " = " : "", v);
    if (port->has_range && o < n)
        snprintf(buf + o, n - o, " range %g %g", port->lo, port->hi);
}

void lsp_op_port_types(int op, int k, char *buf, size_t n)
{
    const ir_opinfo *in = ir_opinfo_get((ir_op)op);
    int na = in->nargs > 4 ? 4 : in->nargs;
    bool ok[IR_T_TEX + 1] = { false };
    for (int w = 1; w <= 4; w++) {
        ir_type args[4];
        for (int i = 0; i < na; i++)
            args[i] = !strcmp(in->ports[i], "tex") ? IR_T_TEX
                    : !strcmp(in->ports[i], "uv") ? IR_T_VEC2 : ir_type_vec(w);
        if (in->type(args, na) != IR_T_ERROR && args[k] <= IR_T_TEX)
            ok[args[k]] = true;
    }
    size_t o = 0;
    buf[0] = 0;
    for (int t = 0; t <= IR_T_TEX && o < n; t++)
        if (ok[t])
            o += (size_t)snprintf(buf + o, n - o, "%s%s", o ? " | " : "", ir_type_name((ir_type)t));
}

void lsp_shader_text(const sg_program *p, int si, char *buf, size_t n)
{
    const sg_shader *sh = p->shaders[si];
    size_t o = (size_t)snprintf(buf, n, "%s %s", sh->is_material ? "material" : "shader",
                                sh->name);
    const sg_port *lists[] = { sh->is_material ? sh->params : sh->ins, sh->outs };
    int counts[] = { sh->is_material ? sh->nparams : sh->nins, sh->nouts };
    const char *roles[] = { sh->is_material ? "param" : "in", "out" };
    for (int r = 0; r < 2; r++)
        for (int k = 0; k < counts[r] && o < n; k++) {
            char line[400];
            sg_port port = lists[r][k];
            if (r == 1)
                port.has_value = false;     /* an output's wiring is not its interface */
            lsp_port_text(&port, roles[r], line, sizeof line);
            o += (size_t)snprintf(buf + o, n - o, "\n    %s", line);
        }
}

/* ---- hover ---------------------------------------------------------------------------- */

/* The file a shader is declared in, relative to the document's folder. */
static char *file_of(const sg_program *p, int file)
{
    char *dir = splat_path_dir(p->files[0]->path);
    char *abs = splat_path_absolute(p->files[file]->path);
    char *adir = splat_path_absolute(dir);
    char *rel = splat_path_relative(adir, abs);
    free(adir);
    free(abs);
    free(dir);
    return rel;
}

static json_t *hover_text(const sg_program *p, const entity *e)
{
    char code[4096] = "", doc[2048] = "", where[1024] = "";
    switch (e->kind) {
    case ENT_SHADER: {
        const sg_shader *sh = p->shaders[e->index];
        lsp_shader_text(p, e->index, code, sizeof code);
        sg_doc_comment(p->files[sh->file], sh->loc.line, false, doc, sizeof doc);
        char *rel = file_of(p, sh->file);
        snprintf(where, sizeof where, "declared in `%s`", rel);
        free(rel);
        break;
    }
    case ENT_PORT: {
        const sg_shader *sh = p->shaders[e->shader];
        const sg_port *port = !strcmp(e->role, "in") ? &sh->ins[e->index]
                            : !strcmp(e->role, "out") ? &sh->outs[e->index]
                            : &sh->params[e->index];
        lsp_port_text(port, e->role, code, sizeof code);
        sg_doc_comment(p->files[sh->file], port->loc.line, true, doc, sizeof doc);
        char *rel = file_of(p, sh->file);
        snprintf(where, sizeof where, "%s of %s `%s` (`%s`)%s",
                 !strcmp(e->role, "in") ? "input" : !strcmp(e->role, "out") ? "output" : "param",
                 sh->is_material ? "material" : "shader", sh->name, rel,
                 !strcmp(e->role, "in") && !port->has_value ? "; required" : "");
        free(rel);
        break;
    }
    case ENT_NODE: {
        const sg_shader *sh = p->shaders[e->shader];
        const sg_node *n = &sh->nodes[e->index];
        size_t o = (size_t)snprintf(code, sizeof code, "node %s : %s", n->name, n->type);
        int nout = n->kind == SG_NODE_INSTANCE ? p->shaders[n->shader]->nouts : 1;
        for (int k = 0; k < nout && o < sizeof code; k++) {
            ir_type t = sg_node_output_type(p, sh, n, k);
            const char *name = n->kind == SG_NODE_INSTANCE ? p->shaders[n->shader]->outs[k].name
                                                           : "out";
            if (t != IR_T_ERROR)
                o += (size_t)snprintf(code + o, sizeof code - o, "%s%s %s.%s",
                                      k ? ", " : "  -> ", ir_type_name(t), n->name, name);
        }
        sg_doc_comment(p->files[sh->file], n->loc.line, true, doc, sizeof doc);
        break;
    }
    case ENT_OP: {
        const ir_opinfo *in = ir_opinfo_get((ir_op)e->index);
        size_t o = (size_t)snprintf(code, sizeof code, "%s {", in->name);
        for (int k = 0; k < in->nargs && k < 4 && o < sizeof code; k++)
            o += (size_t)snprintf(code + o, sizeof code - o, "%s %s", k ? "," : "", in->ports[k]);
        if (o < sizeof code)
            snprintf(code + o, sizeof code - o, " }  -> out");
        snprintf(where, sizeof where, "built-in op; GLSL `%s`", in->glsl);
        break;
    }
    case ENT_OP_PORT: {
        const ir_opinfo *in = ir_opinfo_get((ir_op)e->index);
        char types[128];
        lsp_op_port_types(e->index, e->port, types, sizeof types);
        snprintf(code, sizeof code, "in %s %s", types, in->ports[e->port]);
        snprintf(where, sizeof where, "input of built-in op `%s` (GLSL `%s`); required; "
                 "a float splats to the other operands' width", in->name, in->glsl);
        break;
    }
    case ENT_INPUT: {
        const ir_input_info *in = ir_input_get((ir_input_kind)e->index);
        size_t o = (size_t)snprintf(code, sizeof code, "%s %s", ir_type_name(in->type), in->name);
        for (int c = 0; c < ir_type_width(in->type) && o < sizeof code; c++)
            o += (size_t)snprintf(code + o, sizeof code - o, "%s[%g, %g]", c ? " " : "  in ",
                                  in->domain[c].lo, in->domain[c].hi);
        snprintf(where, sizeof where, "terrain or view input (`splatc eval --at %s=…`)", in->key);
        break;
    }
    case ENT_TEXTURE: {
        const sg_texdecl *t = p->textures[e->index];
        snprintf(code, sizeof code, "texture %s { file = \"%s\", filter = %s, mip = %s, "
                 "wrap = %s, srgb = %s }", t->name, t->file, ir_filter_name(t->filter),
                 ir_filter_name(t->mip), ir_wrap_name(t->wrap), t->srgb ? "true" : "false");
        break;
    }
    case ENT_PAINTED:
        snprintf(code, sizeof code, "painted { mask = \"NAME\" }  -> float out");
        snprintf(where, sizeof where, "a painted mask the scene declares "
                 "(`painted NAME = \"file.png\"`), in [0, 1]");
        break;
    default:
        return NULL;
    }
    char *md = xasprintf("```sg\n%s\n```%s%s%s%s", code, *doc ? "\n\n" : "", doc,
                         *where ? "\n\n" : "", where);
    json_t *out = json_pack("{s:s, s:s}", "kind", "markdown", "value", md);
    free(md);
    return out;
}

json_t *lsp_hover(lsp_server *s, lsp_doc *doc, size_t at)
{
    const sg_program *p = doc->prog;
    if (!p || !p->nfiles)
        return json_null();
    entity e = find(s, p, at);
    json_t *contents = hover_text(p, &e);
    free(e.path);
    if (!contents)
        return json_null();
    const sg_file *f = p->files[0];
    return json_pack("{s:o, s:o}", "contents", contents, "range",
                     lsp_range_at(s, f->text, f->len, e.tok->line, e.tok->col));
}

/* ---- definition ------------------------------------------------------------------------- */

/* The location of `loc` in whichever of the program's files it is in. */
static json_t *location_of(lsp_server *s, const sg_program *p, sg_loc loc)
{
    for (int i = 0; loc.file && i < p->nfiles; i++)
        if (!strcmp(p->files[i]->path, loc.file))
            return lsp_location(s, p->files[i], loc.line, loc.col);
    return json_null();
}

json_t *lsp_definition(lsp_server *s, lsp_doc *doc, size_t at)
{
    const sg_program *p = doc->prog;
    if (!p || !p->nfiles)
        return json_null();
    entity e = find(s, p, at);
    json_t *out = json_null();
    switch (e.kind) {
    case ENT_SHADER:
        out = location_of(s, p, p->shaders[e.index]->loc);
        break;
    case ENT_PORT: {
        const sg_shader *sh = p->shaders[e.shader];
        out = location_of(s, p, !strcmp(e.role, "in") ? sh->ins[e.index].loc
                              : !strcmp(e.role, "out") ? sh->outs[e.index].loc
                              : sh->params[e.index].loc);
        break;
    }
    case ENT_NODE:
        out = location_of(s, p, p->shaders[e.shader]->nodes[e.index].loc);
        break;
    case ENT_TEXTURE:
        out = location_of(s, p, p->textures[e.index]->loc);
        break;
    case ENT_FILE: {
        lsp_doc *open = lsp_doc_by_path(s, e.path);
        char *uri = open ? xstrdup(open->uri) : lsp_path_uri(e.path);
        out = json_pack("{s:s, s:{s:{s:i, s:i}, s:{s:i, s:i}}}", "uri", uri, "range", "start",
                        "line", 0, "character", 0, "end", "line", 0, "character", 0);
        free(uri);
        break;
    }
    default:
        break;
    }
    free(e.path);
    return out;
}
