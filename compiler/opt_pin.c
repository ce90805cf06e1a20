/* opt_pin.c — pin the values an input region makes constant.
 *
 * The interval evaluator bounds every node over a region of inputs
 * (ir_interval_all); a value whose bounds are one finite point in every
 * component takes that value at every input of the region, so it is
 * replaced by the constant.  Then fold and DCE (ir_optimize, run by the
 * caller) remove what only fed it.  Sound by the evaluator's contract
 * (ir_interval.c: every ir_eval value lies inside the bounds; a possible
 * NaN widens to [-inf, inf], so a point excludes it).  -0 and +0 are one
 * point: a pinned zero is +0, which no output tells apart (opt_fold's
 * x + 0 does the same).  Leaves that are already constants, handles and
 * DINPUT leaves stay.
 *
 * Not part of ir_optimize's pipeline: it needs a region.  Distance classes
 * (distance.c) run it with view.distance restricted, every other input at
 * its domain.
 *
 * Before (view.distance in [301, inf]):   After opt_pin, then fold and DCE:
 *   node n1 : view.distance                  out r = 0.0
 *   node n2 : div { a = n1.out, b = 300.0 }
 *   node n3 : sub { a = 1.0, b = n2.out }
 *   node n4 : saturate { x = n3.out }
 *   node n5 : view.direction
 *   node n6 : mul { a = n4.out, b = n5.x }
 *   out r = n6.out
 * (n4 is [0, 0] there, and so is n6, as view.direction is bounded: both
 * are pinned; fold alone could not drop mul(0, x) for an x that might be
 * NaN.)  That is nodes/parallax.sg's offset: 0 beyond `fade` metres, so
 * its eight taps fold onto one sample (tests/unit/test_distance.c).
 */
#include "ir.h"

#include <math.h>
#include <stdlib.h>

#include "util.h"

typedef struct pin {
    const ir *src;
    ir_iv   (*vals)[4];
    uint8_t  *reach;     /* what ir_rebuild visits, in the same order */
    uint32_t  cursor;    /* the source id of the node being rebuilt   */
    bool      pinned;
} pin;

static bool is_point(const ir_node *n, const ir_iv *v)
{
    int w = ir_type_width((ir_type)n->type);
    if (w == 0)
        return false;
    for (int c = 0; c < w; c++)
        if (!(v[c].lo == v[c].hi) || !isfinite(v[c].lo))
            return false;
    return true;
}

/* ir_rebuild visits the nodes the roots reach in ascending id order (opt.c
 * rebuild_once); the cursor walks the same set to know the source id. */
static ir_ref rewrite(ir *dst, const ir_node *n, void *user)
{
    pin *p = user;
    do
        p->cursor++;
    while (!p->reach[p->cursor]);
    uint32_t id = p->cursor;
    const ir_node *src = &p->src->nodes[id];
    bool leaf = src->op == IR_OP_CONST || src->op == IR_OP_TEXTURE ||
                src->op == IR_OP_DINPUT;
    if (!leaf && is_point(src, p->vals[id])) {
        double v[4] = {0, 0, 0, 0};
        for (int c = 0; c < ir_type_width((ir_type)src->type); c++)
            v[c] = p->vals[id][c].lo == 0 ? 0.0 : p->vals[id][c].lo;   /* +0 */
        p->pinned = true;
        return ir_const(dst, (ir_type)src->type, v);
    }
    return ir_node_add(dst, n);
}

bool opt_pin(ir *ir, const ir_ienv *env)
{
    pin p = {.src = ir};
    p.vals = xcalloc(ir->nnodes, sizeof *p.vals);
    p.reach = xcalloc(ir->nnodes + 1, 1);
    ir_interval_all(ir, env, p.vals);
    for (int i = 0; i < ir->nroots; i++)
        p.reach[ir->roots[i].ref.id] = 1;
    for (uint32_t id = ir->nnodes - 1; id > 0; id--)
        if (p.reach[id])
            for (int i = 0; i < ir->nodes[id].nargs; i++)
                p.reach[ir->nodes[id].arg[i].id] = 1;
    p.reach[ir->nnodes] = 1;   /* a sentinel: the cursor never runs past */
    /* ir_rebuild frees the source nodes: keep a copy for the cursor */
    struct ir copy = *ir;
    copy.nodes = xcalloc(ir->nnodes, sizeof *copy.nodes);
    for (uint32_t id = 0; id < ir->nnodes; id++)
        copy.nodes[id] = ir->nodes[id];
    p.src = &copy;
    ir_rebuild(ir, rewrite, &p);
    free(copy.nodes);
    free(p.vals);
    free(p.reach);
    return p.pinned;
}
