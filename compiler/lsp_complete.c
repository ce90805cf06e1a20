/* lsp_complete.c — completion: what may come at the cursor, from the
 * document's own tokens (the compiler's lexer ran on the text being
 * edited) and the names of the analysed program (its shaders, materials,
 * textures, the op and input tables).
 *
 * The place is read off the tokens before the cursor:
 *
 *   node a : |               node types: built-in ops, painted, terrain and
 *                            view inputs, the shaders of the file and its imports
 *   x = terrain.|            terrain inputs (view.| view inputs), n.| n's outputs
 *   node r : ramp { |        r's input ports not bound yet (after `{` or `,`)
 *   node r : ramp { x = |    names in scope: nodes, inputs, params, textures
 *   scene s { |              scene keys; light { |, camera c { |, … their keys
 *   materials = [a, |        materials;  compositor = |  shaders
 *   texture t { wrap = |     the setting's values
 *   material m { |           statements; out |  material outputs
 *   |                        top-level statements
 *
 * Blocks are found as the parser finds them: a top-level keyword at the
 * start of a line closes whatever was left open.  Nothing is offered in a
 * comment or a string.  Clients filter by the word under the cursor. */
#include "lsp.h"
#include "mesh.h"

#include <string.h>

/* CompletionItemKind */
enum { K_FUNCTION = 3, K_FIELD = 5, K_VARIABLE = 6, K_CLASS = 7, K_MODULE = 9,
       K_PROPERTY = 10, K_VALUE = 12, K_KEYWORD = 14, K_STRUCT = 22, K_TYPE = 25 };

typedef struct ctx {
    lsp_server       *s;
    const sg_program *p;
    const sg_file    *f;
    json_t           *items;
} ctx;

static void add(ctx *c, const char *label, int kind, const char *detail, const char *doc)
{
    size_t i;
    json_t *it;
    json_array_foreach(c->items, i, it)
        if (!strcmp(json_string_value(json_object_get(it, "label")), label))
            return;
    it = json_pack("{s:s, s:i}", "label", label, "kind", kind);
    if (detail && *detail)
        json_object_set_new(it, "detail", json_string(detail));
    if (doc && *doc)
        json_object_set_new(it, "documentation",
                            json_pack("{s:s, s:s}", "kind", "markdown", "value", doc));
    json_array_append_new(c->items, it);
}

static void add_words(ctx *c, const char *const *words, int kind)
{
    for (int i = 0; words[i]; i++)
        add(c, words[i], kind, NULL, NULL);
}

/* ---- tokens ------------------------------------------------------------------ */

static bool is_word(const sg_token *t, const char *w)
{
    return t->kind == SG_TK_IDENT && (int)strlen(w) == t->len && !memcmp(t->start, w, (size_t)t->len);
}

static bool top_keyword(const sg_token *t)
{
    return is_word(t, "import") || is_word(t, "texture") || is_word(t, "shader") ||
           is_word(t, "material") || is_word(t, "scene");
}

/* Token i, or an EOF-like blank before the first. */
static const sg_token *tok(const ctx *c, int i)
{
    static const sg_token none = { SG_TK_EOF };
    return i >= 0 && i < c->f->ntoks ? &c->f->toks[i] : &none;
}

static void text_of(const sg_token *t, char *buf, size_t n)
{
    snprintf(buf, n, "%.*s", t->len, t->start);
}

/* Inside a comment or a string on the cursor's line? */
static bool in_comment_or_string(const sg_file *f, size_t at)
{
    size_t a = at;
    while (a > 0 && f->text[a - 1] != '\n')
        a--;
    bool str = false;
    for (size_t i = a; i < at; i++) {
        if (f->text[i] == '"')
            str = !str;
        else if (str && f->text[i] == '\\' && i + 1 < at)
            i++;
        else if (!str && f->text[i] == '#')
            return true;
    }
    return str;
}

/* ---- blocks -------------------------------------------------------------------- */

typedef enum block_kind {
    B_TOP, B_SHADER, B_MATERIAL, B_NODE, B_SCENE, B_LIGHT, B_CAMERA, B_DESTRUCTION,
    B_PAINTED, B_TEXTURE, B_UNDERGROWTH, B_OTHER,
} block_kind;

typedef struct block {
    block_kind kind;
    int        open;        /* index of its `{` */
    int        head;        /* NODE: the type's first token; SHADER/MATERIAL: the name */
} block;

static block classify(const ctx *c, int ob)
{
    block b = { B_OTHER, ob, -1 };
    const sg_token *t1 = tok(c, ob - 1), *t2 = tok(c, ob - 2);
    if (t1->kind == SG_TK_IDENT && is_word(t2, "shader"))
        b.kind = B_SHADER, b.head = ob - 1;
    else if (t1->kind == SG_TK_IDENT && is_word(t2, "material"))
        b.kind = B_MATERIAL, b.head = ob - 1;
    else if (t1->kind == SG_TK_IDENT && is_word(t2, "scene"))
        b.kind = B_SCENE;
    else if (t1->kind == SG_TK_IDENT && is_word(t2, "texture"))
        b.kind = B_TEXTURE;
    else if (t1->kind == SG_TK_IDENT && is_word(t2, "camera"))
        b.kind = B_CAMERA;
    else if (is_word(t1, "light"))
        b.kind = B_LIGHT;
    else if (is_word(t1, "destruction"))
        b.kind = B_DESTRUCTION;
    else if (is_word(t2, "undergrowth"))
        b.kind = B_UNDERGROWTH;
    else if (t1->kind == SG_TK_STRING && tok(c, ob - 2)->kind == SG_TK_EQ &&
             is_word(tok(c, ob - 4), "painted"))
        b.kind = B_PAINTED;
    else {
        /* node N : T(.T)* { */
        int j = ob - 1;
        while (tok(c, j)->kind == SG_TK_IDENT && tok(c, j - 1)->kind == SG_TK_DOT)
            j -= 2;
        if (tok(c, j)->kind == SG_TK_IDENT && tok(c, j - 1)->kind == SG_TK_COLON &&
            tok(c, j - 2)->kind == SG_TK_IDENT && is_word(tok(c, j - 3), "node"))
            b.kind = B_NODE, b.head = j;
    }
    return b;
}

/* The blocks open at token `end` (exclusive), outermost first; returns
 * how many (at most max).  *bracket: the last `[` still open in the
 * innermost block, or -1. */
static int open_blocks(const ctx *c, int end, block *out, int max, int *bracket)
{
    int stack[64], n = 0, depth = 0;
    *bracket = -1;
    for (int i = 0; i < end; i++) {
        const sg_token *t = tok(c, i);
        bool line_start = i == 0 || tok(c, i - 1)->line < t->line;
        if (top_keyword(t) && line_start) {
            n = depth = 0;                  /* the parser closes what was open */
            *bracket = -1;
        }
        /* a statement starting a line closes a node's (or undergrowth's)
         * unclosed braces, as parse.c's starts_statement has it */
        if (line_start && tok(c, i + 1)->kind != SG_TK_EQ &&
            (is_word(t, "node") || is_word(t, "out") || is_word(t, "in") ||
             is_word(t, "param") || is_word(t, "undergrowth")))
            while (n > 0 && n == depth && (classify(c, stack[n - 1]).kind == B_NODE ||
                                           classify(c, stack[n - 1]).kind == B_UNDERGROWTH))
                n--, depth--;
        if (t->kind == SG_TK_LBRACE) {
            if (depth < 64)
                stack[n++] = i;
            depth++;
            *bracket = -1;
        } else if (t->kind == SG_TK_RBRACE && depth > 0) {
            depth--;
            if (n > depth)
                n = depth;
            *bracket = -1;
        } else if (t->kind == SG_TK_LBRACK) {
            *bracket = i;
        } else if (t->kind == SG_TK_RBRACK ||
                   (t->kind == SG_TK_IDENT && tok(c, i + 1)->kind == SG_TK_EQ)) {
            *bracket = -1;                  /* closed, or a next `key =` */
        }
    }
    int k = 0;
    for (int i = 0; i < n && k < max; i++)
        out[k++] = classify(c, stack[i]);
    return k;
}

/* The shader or material whose name token is `head` in the document. */
static int shader_at(const ctx *c, int head)
{
    const sg_token *t = tok(c, head);
    for (int i = 0; i < c->p->nshaders; i++) {
        const sg_shader *s = c->p->shaders[i];
        if (s->file == 0 && s->loc.line == t->line && s->loc.col == t->col)
            return i;
    }
    return -1;
}

/* ---- what is offered ------------------------------------------------------------- */

static void shader_doc(const ctx *c, int si, char *doc, size_t n)
{
    const sg_shader *s = c->p->shaders[si];
    char sig[2048], comment[1024];
    lsp_shader_text(c->p, si, sig, sizeof sig);
    sg_doc_comment(c->p->files[s->file], s->loc.line, false, comment, sizeof comment);
    snprintf(doc, n, "```sg\n%s\n```%s%s", sig, *comment ? "\n\n" : "", comment);
}

static void node_types(ctx *c)
{
    for (int op = 0; op < IR_OP_COUNT; op++) {
        const ir_opinfo *in = ir_opinfo_get((ir_op)op);
        if (!in->name)
            continue;
        char detail[160];
        size_t o = (size_t)snprintf(detail, sizeof detail, "built-in {");
        for (int k = 0; k < in->nargs && k < 4 && o < sizeof detail; k++)
            o += (size_t)snprintf(detail + o, sizeof detail - o, "%s %s", k ? "," : "", in->ports[k]);
        if (o < sizeof detail)
            snprintf(detail + o, sizeof detail - o, " }: %s", in->glsl);
        add(c, in->name, K_FUNCTION, detail, NULL);
    }
    add(c, "painted", K_KEYWORD, "painted { mask = \"NAME\" }: a painted mask", NULL);
    for (int k = 0; k < IR_IN_COUNT; k++) {
        const ir_input_info *in = ir_input_get((ir_input_kind)k);
        add(c, in->name, K_VARIABLE, ir_type_name(in->type), NULL);
    }
    for (int i = 0; i < c->p->nshaders; i++) {
        const sg_shader *s = c->p->shaders[i];
        if (s->is_material)
            continue;
        char doc[4096];
        shader_doc(c, i, doc, sizeof doc);
        char detail[600];
        snprintf(detail, sizeof detail, "shader (%s)", c->p->files[s->file]->path);
        add(c, s->name, K_CLASS, detail, doc);
    }
}

/* `prefix.` inputs: terrain.| or view.| */
static void inputs(ctx *c, const char *prefix)
{
    size_t n = strlen(prefix);
    for (int k = 0; k < IR_IN_COUNT; k++) {
        const ir_input_info *in = ir_input_get((ir_input_kind)k);
        if (strncmp(in->name, prefix, n) || in->name[n] != '.')
            continue;
        char doc[256];
        size_t o = (size_t)snprintf(doc, sizeof doc, "`%s` %s, range", in->name,
                                    ir_type_name(in->type));
        for (int i = 0; i < ir_type_width(in->type) && o < sizeof doc; i++)
            o += (size_t)snprintf(doc + o, sizeof doc - o, " [%g, %g]", in->domain[i].lo,
                                  in->domain[i].hi);
        add(c, in->name + n + 1, K_VARIABLE, ir_type_name(in->type), doc);
    }
}

/* The input ports of node type `type` not bound yet in block b. */
static void ports(ctx *c, const char *type, const block *b, int end)
{
    /* bound already: IDENT '=' at this block's depth */
    char bound[32][64];
    int nb = 0, depth = 0;
    for (int i = b->open + 1; i < end && nb < 32; i++) {
        const sg_token *t = tok(c, i);
        depth += t->kind == SG_TK_LBRACE ? 1 : t->kind == SG_TK_RBRACE ? -1 : 0;
        if (depth == 0 && t->kind == SG_TK_IDENT && tok(c, i + 1)->kind == SG_TK_EQ)
            text_of(t, bound[nb++], sizeof bound[0]);
    }
    int si = -1, op;
    for (int i = 0; i < c->p->nshaders && si < 0; i++)
        if (!c->p->shaders[i]->is_material && !strcmp(c->p->shaders[i]->name, type))
            si = i;
    if (si >= 0) {
        const sg_shader *s = c->p->shaders[si];
        for (int k = 0; k < s->nins; k++) {
            bool done = false;
            for (int j = 0; j < nb; j++)
                done |= !strcmp(bound[j], s->ins[k].name);
            if (done)
                continue;
            char detail[400], doc[1024];
            lsp_port_text(&s->ins[k], "in", detail, sizeof detail);
            sg_doc_comment(c->p->files[s->file], s->ins[k].loc.line, true, doc, sizeof doc);
            add(c, s->ins[k].name, K_FIELD, detail, doc);
        }
    } else if ((op = ir_op_by_name(type)) >= 0) {
        const ir_opinfo *in = ir_opinfo_get((ir_op)op);
        for (int k = 0; k < in->nargs && k < 4; k++) {
            bool done = false;
            for (int j = 0; j < nb; j++)
                done |= !strcmp(bound[j], in->ports[k]);
            if (done)
                continue;
            char types[128], detail[200];
            lsp_op_port_types(op, k, types, sizeof types);
            snprintf(detail, sizeof detail, "in %s %s", types, in->ports[k]);
            add(c, in->ports[k], K_FIELD, detail, NULL);
        }
    } else if (!strcmp(type, "painted")) {
        add(c, "mask", K_FIELD, "in \"NAME\": the scene's painted mask", NULL);
    }
}

/* The names a value in shader si can use. */
static void scope(ctx *c, int si)
{
    if (si >= 0) {
        const sg_shader *s = c->p->shaders[si];
        char detail[400];
        for (int k = 0; k < s->nins; k++) {
            lsp_port_text(&s->ins[k], "in", detail, sizeof detail);
            add(c, s->ins[k].name, K_VARIABLE, detail, NULL);
        }
        for (int k = 0; k < s->nparams; k++) {
            lsp_port_text(&s->params[k], "param", detail, sizeof detail);
            add(c, s->params[k].name, K_VARIABLE, detail, NULL);
        }
        for (int k = 0; k < s->nnodes; k++) {
            snprintf(detail, sizeof detail, "node : %s", s->nodes[k].type);
            add(c, s->nodes[k].name, K_VARIABLE, detail, NULL);
        }
    }
    for (int k = 0; k < c->p->ntextures; k++)
        add(c, c->p->textures[k]->name, K_VALUE, "texture", NULL);
    add(c, "terrain", K_MODULE, "terrain inputs: terrain.slope, terrain.height, …", NULL);
    add(c, "view", K_MODULE, "view inputs: view.distance, view.direction, view.shading_lod", NULL);
    static const char *const vecs[] = { "vec2", "vec3", "vec4", NULL };
    add_words(c, vecs, K_TYPE);
}

/* n.| : node n's outputs (n in shader si) */
static void outputs_of(ctx *c, int si, const char *node)
{
    if (si < 0)
        return;
    const sg_shader *s = c->p->shaders[si];
    for (int k = 0; k < s->nnodes; k++) {
        const sg_node *n = &s->nodes[k];
        if (strcmp(n->name, node))
            continue;
        if (n->kind == SG_NODE_INSTANCE) {
            const sg_shader *callee = c->p->shaders[n->shader];
            for (int j = 0; j < callee->nouts; j++) {
                char detail[400];
                lsp_port_text(&callee->outs[j], "out", detail, sizeof detail);
                char *eq = strstr(detail, " = ");
                if (eq)
                    *eq = 0;
                add(c, callee->outs[j].name, K_FIELD, detail, NULL);
            }
        } else {
            add(c, "out", K_FIELD, ir_type_name(n->out_type), NULL);
        }
    }
}

static void materials(ctx *c)
{
    for (int i = 0; i < c->p->nshaders; i++)
        if (c->p->shaders[i]->is_material) {
            char doc[4096];
            shader_doc(c, i, doc, sizeof doc);
            add(c, c->p->shaders[i]->name, K_STRUCT, "material", doc);
        }
}

/* The value of `key` in a settings block of kind k. */
static void setting_values(ctx *c, block_kind k, const sg_token *key)
{
    if (k == B_TEXTURE && (is_word(key, "filter") || is_word(key, "mip"))) {
        for (int i = 0; strcmp(ir_filter_name((ir_filter)i), "?"); i++)
            add(c, ir_filter_name((ir_filter)i), K_VALUE, NULL, NULL);
    } else if (k == B_TEXTURE && is_word(key, "wrap")) {
        for (int i = 0; strcmp(ir_wrap_name((ir_wrap)i), "?"); i++)
            add(c, ir_wrap_name((ir_wrap)i), K_VALUE, NULL, NULL);
    } else if (k == B_TEXTURE && is_word(key, "srgb")) {
        static const char *const tf[] = { "true", "false", NULL };
        add_words(c, tf, K_VALUE);
    } else if (k == B_UNDERGROWTH && is_word(key, "align")) {
        static const char *const al[] = { "normal", "upright", NULL };
        add_words(c, al, K_VALUE);
    } else if (k == B_SCENE && is_word(key, "compositor")) {
        for (int i = 0; i < c->p->nshaders; i++)
            if (!c->p->shaders[i]->is_material) {
                char doc[4096];
                shader_doc(c, i, doc, sizeof doc);
                add(c, c->p->shaders[i]->name, K_CLASS, "shader", doc);
            }
    }
}

static const char *const top_words[] = { "import", "texture", "shader", "material", "scene", NULL };
static const char *const type_words[] = { "float", "vec2", "vec3", "vec4", "texture", NULL };

/* ---- the place -------------------------------------------------------------------- */

json_t *lsp_completion(lsp_server *s, lsp_doc *doc, size_t at)
{
    ctx c = { s, doc->prog, NULL, json_array() };
    if (!c.p || !c.p->nfiles)
        return c.items;
    c.f = c.p->files[0];
    if (at > c.f->len || in_comment_or_string(c.f, at))
        return c.items;
    /* the last token before the cursor; a name the cursor ends is the word */
    int last = -1;
    for (int i = 0; i < c.f->ntoks && tok(&c, i)->kind != SG_TK_EOF &&
                    (size_t)(tok(&c, i)->start - c.f->text) < at; i++)
        last = i;
    int prev = last;
    if (last >= 0 && tok(&c, last)->kind == SG_TK_IDENT &&
        (size_t)(tok(&c, last)->start - c.f->text) + (size_t)tok(&c, last)->len >= at)
        prev = last - 1;
    const sg_token *pt = tok(&c, prev);

    block blocks[16];
    int bracket;
    int nb = open_blocks(&c, prev + 1, blocks, 16, &bracket);
    const block *in = nb ? &blocks[nb - 1] : NULL;
    int si = -1;                            /* the enclosing shader or material */
    for (int i = nb - 1; i >= 0 && si < 0; i--)
        if (blocks[i].kind == B_SHADER || blocks[i].kind == B_MATERIAL)
            si = shader_at(&c, blocks[i].head);

    if (pt->kind == SG_TK_DOT && tok(&c, prev - 1)->kind == SG_TK_IDENT &&
        tok(&c, prev - 2)->kind != SG_TK_DOT) {
        char word[128];
        text_of(tok(&c, prev - 1), word, sizeof word);
        if (!strcmp(word, "terrain") || !strcmp(word, "view"))
            inputs(&c, word);
        else
            outputs_of(&c, si, word);
    } else if (pt->kind == SG_TK_COLON && tok(&c, prev - 1)->kind == SG_TK_IDENT &&
               is_word(tok(&c, prev - 2), "node")) {
        node_types(&c);
    } else if (in && in->kind == B_SCENE && bracket >= 0 &&
               tok(&c, bracket - 1)->kind == SG_TK_EQ && is_word(tok(&c, bracket - 2), "materials")) {
        materials(&c);
    } else if (pt->kind == SG_TK_EQ && in) {
        if (in->kind == B_NODE || in->kind == B_SHADER || in->kind == B_MATERIAL)
            scope(&c, si);
        else
            setting_values(&c, in->kind, tok(&c, prev - 1));
    } else if (!in) {
        if (!is_word(pt, "import"))
            add_words(&c, top_words, K_KEYWORD);
    } else {
        /* a statement starts here: after `{`, `}` or on a later line */
        int line = 1;
        for (size_t i = 0; i < at; i++)
            line += c.f->text[i] == '\n';
        bool start = prev < 0 || pt->kind == SG_TK_LBRACE || pt->kind == SG_TK_RBRACE ||
                     pt->line < line;
        char type[160] = "";
        switch (in->kind) {
        case B_NODE:
            for (int j = in->head; j < in->open && strlen(type) < sizeof type - 64; j++)
                text_of(tok(&c, j), type + strlen(type), sizeof type - strlen(type));
            ports(&c, type, in, prev + 1);
            break;
        case B_SCENE:       add_words(&c, sg_scene_keys, K_PROPERTY); break;
        case B_TEXTURE:     add_words(&c, sg_texture_keys, K_PROPERTY); break;
        case B_CAMERA:      add_words(&c, sg_camera_keys, K_PROPERTY); break;
        case B_DESTRUCTION: add_words(&c, sg_destruction_keys, K_PROPERTY); break;
        case B_PAINTED:     add_words(&c, sg_painted_keys, K_PROPERTY); break;
        case B_UNDERGROWTH: add_words(&c, sg_ug_keys, K_PROPERTY); break;
        case B_LIGHT:
            for (int k = 0; k < SPLAT_LIGHT_COUNT; k++)
                add(&c, splat_light_keys[k].key, K_PROPERTY, NULL, NULL);
            break;
        case B_SHADER:
        case B_MATERIAL:
            if (is_word(pt, "out") && in->kind == B_MATERIAL) {
                for (int k = 0; k < SG_OUT_COUNT; k++)
                    add(&c, sg_output_names[k], K_FIELD, NULL, NULL);
            } else if (is_word(pt, "in") || is_word(pt, "param") || is_word(pt, "out")) {
                add_words(&c, type_words, K_TYPE);
            } else if (is_word(pt, "undergrowth")) {
                add_words(&c, splat_mesh_builtins, K_VALUE);
            } else if (start) {
                static const char *const sh[] = { "in", "node", "out", NULL };
                static const char *const mat[] = { "param", "node", "out", "undergrowth", NULL };
                add_words(&c, in->kind == B_MATERIAL ? mat : sh, K_KEYWORD);
            }
            break;
        default:
            break;
        }
    }
    return c.items;
}
