/* ir.c — the node array and its hash-cons table, the builder, the
 * resource tables (params, textures, painted masks), roots, import between
 * irs, and the growable string ir_buf.
 *
 * Hash-consing: every node goes through ir_node_add, which canonicalises it
 * (commutative operands sorted by ascending id, unused fields zeroed) and
 * then looks it up with the can_cse / node_hash / node_equal triple below.
 */
#include "ir.h"
#include "util.h"

#include <assert.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>

#define GROW(ptr, n, cap)                                                  \
    do {                                                                   \
        if ((n) >= (cap)) {                                                \
            (cap) = (cap) ? 2 * (cap) : 16;                                \
            (ptr) = xrealloc((ptr), sizeof(*(ptr)) * (size_t)(cap));       \
        }                                                                  \
    } while (0)

/* ---- init / free -------------------------------------------------------- */

void ir_init(ir *ir)
{
    memset(ir, 0, sizeof *ir);
    ir->capnodes = 64;
    ir->nodes = xrealloc(NULL, sizeof(ir_node) * ir->capnodes);
    memset(&ir->nodes[0], 0, sizeof(ir_node));   /* the "none" node */
    ir->nnodes = 1;
    ir->captable = 128;
    ir->table = xrealloc(NULL, sizeof(uint32_t) * ir->captable);
    memset(ir->table, 0, sizeof(uint32_t) * ir->captable);
}

void ir_free(ir *ir)
{
    for (int i = 0; i < ir->nparams; i++)
        free(ir->params[i].name);
    for (int i = 0; i < ir->ntextures; i++)
        free(ir->textures[i].file);
    for (int i = 0; i < ir->npainted; i++)
        free(ir->painted[i].name);
    for (int i = 0; i < ir->nroots; i++)
        free(ir->roots[i].name);
    free(ir->params);
    free(ir->textures);
    free(ir->painted);
    free(ir->roots);
    free(ir->nodes);
    free(ir->table);
    memset(ir, 0, sizeof *ir);
}

/* ---- hash-consing ------------------------------------------------------- */

/* can_cse, node_hash and node_equal must agree: two nodes that node_equal
 * calls equal must hash alike, and every field node_equal reads must be
 * canonical (ir_node_add zeroes the unused ones and sorts commutative
 * operands first).  Every op is pure, so every node can be CSE'd; the
 * predicate stays as the one place to say otherwise (e.g. a future raw
 * GLSL node with side effects). */
static bool can_cse(const ir_node *n)
{
    (void)n;
    return true;
}

static uint64_t mix64(uint64_t h, uint64_t v)
{
    /* order-sensitive combine (boost-style with a 64-bit multiplier) */
    h ^= v + 0x9e3779b97f4a7c15ull + (h << 12) + (h >> 4);
    h *= 0xff51afd7ed558ccdull;
    return h ^ (h >> 32);
}

static uint64_t node_hash(const ir_node *n)
{
    uint64_t h = mix64(0x243f6a8885a308d3ull,
                       (uint64_t)n->op | (uint64_t)n->type << 8 | (uint64_t)n->nargs << 16);
    h = mix64(h, n->imm);
    /* Commutative operands are already sorted, so hashing them in order is
     * commutative without XOR (which would send a+a to the same bucket as
     * every other x+x). */
    for (int i = 0; i < n->nargs; i++)
        h = mix64(h, n->arg[i].id);
    if (n->op == IR_OP_CONST) {
        for (int i = 0; i < 4; i++) {
            uint64_t bits;
            memcpy(&bits, &n->val[i], sizeof bits);   /* bitwise: -0.0 != 0.0 */
            h = mix64(h, bits);
        }
    }
    return h;
}

static bool node_equal(const ir_node *a, const ir_node *b)
{
    if (a->op != b->op || a->type != b->type || a->nargs != b->nargs || a->imm != b->imm)
        return false;
    for (int i = 0; i < a->nargs; i++)
        if (a->arg[i].id != b->arg[i].id)
            return false;
    if (a->op == IR_OP_CONST && memcmp(a->val, b->val, sizeof a->val) != 0)
        return false;
    return true;
}

static void table_insert(ir *ir, uint32_t id)
{
    uint32_t mask = ir->captable - 1;
    uint32_t i = (uint32_t)node_hash(&ir->nodes[id]) & mask;
    while (ir->table[i])
        i = (i + 1) & mask;
    ir->table[i] = id;
}

static void table_grow(ir *ir)
{
    free(ir->table);
    ir->captable *= 2;
    ir->table = xrealloc(NULL, sizeof(uint32_t) * ir->captable);
    memset(ir->table, 0, sizeof(uint32_t) * ir->captable);
    for (uint32_t id = 1; id < ir->nnodes; id++)
        if (can_cse(&ir->nodes[id]))
            table_insert(ir, id);
}

/* Put `n` in canonical form (see the comment above can_cse). */
static void canonicalise(ir_node *n)
{
    n->pad = 0;
    for (int i = n->nargs; i < 4; i++)
        n->arg[i] = IR_NONE;
    if (n->op != IR_OP_CONST)
        memset(n->val, 0, sizeof n->val);
    else
        for (int i = ir_type_width((ir_type)n->type); i < 4; i++)
            n->val[i] = 0.0;
    if ((ir_opinfo_get((ir_op)n->op)->flags & IR_COMMUTATIVE) && n->nargs == 2 &&
        n->arg[1].id < n->arg[0].id) {
        ir_ref t = n->arg[0];
        n->arg[0] = n->arg[1];
        n->arg[1] = t;
    }
}

ir_ref ir_lookup(const ir *ir, const ir_node *given)
{
    ir_node n = *given;
    canonicalise(&n);
    if (!can_cse(&n))
        return IR_NONE;
    uint32_t mask = ir->captable - 1;
    for (uint32_t i = (uint32_t)node_hash(&n) & mask; ir->table[i]; i = (i + 1) & mask)
        if (node_equal(&ir->nodes[ir->table[i]], &n))
            return (ir_ref){ir->table[i]};
    return IR_NONE;
}

ir_ref ir_node_add(ir *ir, const ir_node *given)
{
    ir_node n = *given;
    assert(n.op < IR_OP_COUNT);
    assert(n.nargs <= 4);
    for (int i = 0; i < n.nargs; i++)
        assert(n.arg[i].id > 0 && n.arg[i].id < ir->nnodes);
    canonicalise(&n);
    ir_ref found = ir_lookup(ir, &n);
    if (ir_ref_ok(found))
        return found;
    GROW(ir->nodes, ir->nnodes, ir->capnodes);
    uint32_t id = ir->nnodes++;
    ir->nodes[id] = n;
    if (can_cse(&n)) {
        if (2 * ir->nnodes > ir->captable)
            table_grow(ir);          /* re-inserts every node, `id` too */
        else
            table_insert(ir, id);
    }
    return (ir_ref){id};
}

/* ---- builder ------------------------------------------------------------ */

ir_ref ir_const(ir *ir, ir_type t, const double *v)
{
    assert(ir_type_width(t) > 0);
    ir_node n = {.op = IR_OP_CONST, .type = (uint8_t)t};
    for (int i = 0; i < ir_type_width(t); i++)
        n.val[i] = v[i];
    return ir_node_add(ir, &n);
}

ir_ref ir_constf(ir *ir, double v)
{
    return ir_const(ir, IR_T_FLOAT, &v);
}

ir_ref ir_input(ir *ir, ir_input_kind which)
{
    assert((unsigned)which < IR_IN_COUNT);
    ir_node n = {.op = IR_OP_INPUT, .type = (uint8_t)ir_input_get(which)->type, .imm = which};
    return ir_node_add(ir, &n);
}

ir_ref ir_param_ref(ir *ir, int param)
{
    assert(param >= 0 && param < ir->nparams);
    ir_node n = {.op = IR_OP_PARAM, .type = (uint8_t)ir->params[param].type,
                 .imm = (uint32_t)param};
    return ir_node_add(ir, &n);
}

ir_ref ir_texture_ref(ir *ir, int texture)
{
    assert(texture >= 0 && texture < ir->ntextures);
    ir_node n = {.op = IR_OP_TEXTURE, .type = IR_T_TEX, .imm = (uint32_t)texture};
    return ir_node_add(ir, &n);
}

ir_ref ir_painted_ref(ir *ir, int painted)
{
    assert(painted >= 0 && painted < ir->npainted);
    ir_node n = {.op = IR_OP_PAINTED, .type = IR_T_FLOAT, .imm = (uint32_t)painted};
    return ir_node_add(ir, &n);
}

ir_ref ir_opn(ir *ir, ir_op op, const ir_ref *args, int nargs)
{
    const ir_opinfo *info = ir_opinfo_get(op);
    assert(op != IR_OP_SPLAT && op != IR_OP_SWIZZLE);    /* need a type / imm */
    assert(op == IR_OP_CONSTRUCT ? nargs >= 1 && nargs <= 4 : nargs == info->nargs);
    ir_type types[4];
    for (int i = 0; i < nargs; i++)
        types[i] = ir_typeof(ir, args[i]);
    ir_node n = {.op = (uint8_t)op, .nargs = (uint8_t)nargs};
    n.type = (uint8_t)info->type(types, nargs);
    assert(n.type != IR_T_ERROR && "operand types violate the op's type rule");
    for (int i = 0; i < nargs; i++)
        n.arg[i] = args[i];
    return ir_node_add(ir, &n);
}

ir_ref ir_op1(ir *ir, ir_op op, ir_ref a)
{
    return ir_opn(ir, op, &a, 1);
}

ir_ref ir_op2(ir *ir, ir_op op, ir_ref a, ir_ref b)
{
    ir_ref args[2] = {a, b};
    return ir_opn(ir, op, args, 2);
}

ir_ref ir_op3(ir *ir, ir_op op, ir_ref a, ir_ref b, ir_ref c)
{
    ir_ref args[3] = {a, b, c};
    return ir_opn(ir, op, args, 3);
}

ir_ref ir_splat(ir *ir, ir_ref a, ir_type to)
{
    ir_type from = ir_typeof(ir, a);
    if (from == to)
        return a;
    assert(from == IR_T_FLOAT && ir_type_width(to) > 1);
    ir_node n = {.op = IR_OP_SPLAT, .type = (uint8_t)to, .nargs = 1, .arg = {a}};
    return ir_node_add(ir, &n);
}

static int swizzle_comp(char c)
{
    switch (c) {
    case 'x': case 'r': case 's': return 0;
    case 'y': case 'g': case 't': return 1;
    case 'z': case 'b': case 'p': return 2;
    case 'w': case 'a': case 'q': return 3;
    default:  return -1;
    }
}

ir_ref ir_swizzle(ir *ir, ir_ref a, const char *comps)
{
    int n = (int)strlen(comps);
    int w = ir_type_width(ir_typeof(ir, a));
    assert(n >= 1 && n <= 4 && w >= 1);
    int c[4] = {0, 0, 0, 0};
    bool identity = n == w;
    for (int i = 0; i < n; i++) {
        c[i] = swizzle_comp(comps[i]);
        assert(c[i] >= 0 && c[i] < w && "swizzle component out of range");
        identity = identity && c[i] == i;
    }
    if (identity)
        return a;
    ir_node node = {.op = IR_OP_SWIZZLE, .type = (uint8_t)ir_type_vec(n), .nargs = 1,
                    .imm = IR_SWZ(n, c[0], c[1], c[2], c[3]), .arg = {a}};
    return ir_node_add(ir, &node);
}

ir_ref ir_construct(ir *ir, ir_type t, const ir_ref *args, int nargs)
{
    ir_ref r = ir_opn(ir, IR_OP_CONSTRUCT, args, nargs);
    assert(ir_typeof(ir, r) == t);
    (void)t;
    return r;
}

/* ---- tables ------------------------------------------------------------- */

int ir_add_param(ir *ir, const ir_param *p)
{
    for (int i = 0; i < ir->nparams; i++)
        if (strcmp(ir->params[i].name, p->name) == 0)
            return i;
    GROW(ir->params, ir->nparams, ir->capparams);
    ir_param *q = &ir->params[ir->nparams];
    *q = *p;
    q->name = xstrdup(p->name);
    return ir->nparams++;
}

int ir_add_texture(ir *ir, const ir_texture *t)
{
    GROW(ir->textures, ir->ntextures, ir->captextures);
    ir_texture *q = &ir->textures[ir->ntextures];
    *q = *t;
    q->file = xstrdup(t->file);
    return ir->ntextures++;
}

bool ir_texture_same(const ir_texture *a, const ir_texture *b)
{
    return strcmp(a->file, b->file) == 0 && a->filter == b->filter && a->mip == b->mip &&
           a->wrap == b->wrap && a->srgb == b->srgb;
}

int ir_add_painted(ir *ir, const char *name)
{
    for (int i = 0; i < ir->npainted; i++)
        if (strcmp(ir->painted[i].name, name) == 0)
            return i;
    GROW(ir->painted, ir->npainted, ir->cappainted);
    ir->painted[ir->npainted].name = xstrdup(name);
    return ir->npainted++;
}

void ir_set_root(ir *ir, const char *name, ir_ref r)
{
    assert(r.id < ir->nnodes);
    for (int i = 0; i < ir->nroots; i++)
        if (strcmp(ir->roots[i].name, name) == 0) {
            ir->roots[i].ref = r;
            return;
        }
    GROW(ir->roots, ir->nroots, ir->caproots);
    ir->roots[ir->nroots].name = xstrdup(name);
    ir->roots[ir->nroots].ref = r;
    ir->nroots++;
}

ir_ref ir_find_root(const ir *ir, const char *name)
{
    for (int i = 0; i < ir->nroots; i++)
        if (strcmp(ir->roots[i].name, name) == 0)
            return ir->roots[i].ref;
    return IR_NONE;
}

/* ---- import ------------------------------------------------------------- */

struct ir_import_map {
    ir       *dst;
    const ir *src;
    uint32_t *node;      /* src id -> dst id, 0 = not yet imported */
    uint8_t  *reach;     /* scratch: marks of one import            */
    int      *texture;   /* src texture -> dst texture, -1 = not yet */
};

ir_import_map *ir_import_begin(ir *dst, const ir *src)
{
    ir_import_map *m = xrealloc(NULL, sizeof *m);
    m->dst = dst;
    m->src = src;
    m->node = xrealloc(NULL, sizeof(uint32_t) * src->nnodes);
    memset(m->node, 0, sizeof(uint32_t) * src->nnodes);
    m->reach = xrealloc(NULL, src->nnodes);
    m->texture = xrealloc(NULL, sizeof(int) * (size_t)(src->ntextures + 1));
    for (int i = 0; i < src->ntextures; i++)
        m->texture[i] = -1;
    return m;
}

static uint32_t import_leaf_imm(ir_import_map *m, const ir_node *n)
{
    switch (n->op) {
    case IR_OP_PARAM:
        return (uint32_t)ir_add_param(m->dst, &m->src->params[n->imm]);
    case IR_OP_TEXTURE:
        if (m->texture[n->imm] < 0)
            m->texture[n->imm] = ir_add_texture(m->dst, &m->src->textures[n->imm]);
        return (uint32_t)m->texture[n->imm];
    case IR_OP_PAINTED:
        return (uint32_t)ir_add_painted(m->dst, m->src->painted[n->imm].name);
    default:
        return n->imm;
    }
}

ir_ref ir_import(ir_import_map *m, ir_ref r)
{
    if (!ir_ref_ok(r) || m->node[r.id])
        return (ir_ref){m->node[r.id]};
    /* Nodes are topologically ordered: mark what r reaches walking ids
     * downwards, then import the marked ones upwards (no recursion). */
    memset(m->reach, 0, r.id + 1);
    m->reach[r.id] = 1;
    for (uint32_t id = r.id; id > 0; id--) {
        if (!m->reach[id] || m->node[id])
            continue;
        const ir_node *n = &m->src->nodes[id];
        for (int i = 0; i < n->nargs; i++)
            m->reach[n->arg[i].id] = 1;
    }
    for (uint32_t id = 1; id <= r.id; id++) {
        if (!m->reach[id] || m->node[id])
            continue;
        ir_node n = m->src->nodes[id];
        for (int i = 0; i < n.nargs; i++)
            n.arg[i].id = m->node[n.arg[i].id];
        n.imm = import_leaf_imm(m, &n);
        m->node[id] = ir_node_add(m->dst, &n).id;
    }
    return (ir_ref){m->node[r.id]};
}

void ir_import_end(ir_import_map *m)
{
    if (!m)
        return;
    free(m->node);
    free(m->reach);
    free(m->texture);
    free(m);
}

/* ---- ir_buf (declared with the GLSL emitter, used by every writer) ------ */

static void buf_reserve(ir_buf *b, size_t more)
{
    if (b->len + more + 1 > b->cap) {
        size_t cap = b->cap ? b->cap : 256;
        while (cap < b->len + more + 1)
            cap *= 2;
        b->s = xrealloc(b->s, cap);
        b->cap = cap;
    }
}

/* Formatted once into the room left where it fits (the common case: the
 * GLSL writer appends short pieces), else again after growing. */
void ir_buf_printf(ir_buf *b, const char *fmt, ...)
{
    va_list ap;
    size_t room = b->cap > b->len ? b->cap - b->len : 0;
    va_start(ap, fmt);
    int n = vsnprintf(room ? b->s + b->len : NULL, room, fmt, ap);
    va_end(ap);
    assert(n >= 0);
    if ((size_t)n >= room) {
        buf_reserve(b, (size_t)n);
        va_start(ap, fmt);
        vsnprintf(b->s + b->len, (size_t)n + 1, fmt, ap);
        va_end(ap);
    }
    b->len += (size_t)n;
}

void ir_buf_put(ir_buf *b, const char *s, size_t n)
{
    buf_reserve(b, n);
    memcpy(b->s + b->len, s, n);
    b->len += n;
    b->s[b->len] = 0;
}

void ir_buf_free(ir_buf *b)
{
    free(b->s);
    b->s = NULL;
    b->len = b->cap = 0;
}

void ir_clone(ir *dst, const ir *src)
{
    ir_init(dst);
    ir_import_map *m = ir_import_begin(dst, src);
    for (int i = 0; i < src->nroots; i++)
        ir_set_root(dst, src->roots[i].name, ir_import(m, src->roots[i].ref));
    ir_import_end(m);
}
