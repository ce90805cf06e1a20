/* compose_schedule.c — where each value of a composite is computed: the
 * region tree that mirrors the GLSL blocks (main, G_j for a layer's guard,
 * W_j for its surface), every node placed at the lowest common ancestor of
 * its users' regions, and the lazy branches (compose.c's header has the
 * picture; compiler/DESIGN.md §6). */
#include "compose_internal.h"

#include <assert.h>
#include <float.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "abi.h"
#include "sg_internal.h"
#include "util.h"

static int region_new(sched *s, int parent)
{
    if (s->nregions == s->capregions) {
        s->capregions = s->capregions ? 2 * s->capregions : 16;
        s->regions = xrealloc(s->regions, sizeof *s->regions * (size_t)s->capregions);
    }
    memset(&s->regions[s->nregions], 0, sizeof *s->regions);
    int r = s->nregions++;
    s->regions[r].parent = parent;
    s->regions[r].depth = parent < 0 ? 0 : s->regions[parent].depth + 1;
    return r;
}

static int lca(const sched *s, int a, int b)
{
    while (s->regions[a].depth > s->regions[b].depth)
        a = s->regions[a].parent;
    while (s->regions[b].depth > s->regions[a].depth)
        b = s->regions[b].parent;
    while (a != b) {
        a = s->regions[a].parent;
        b = s->regions[b].parent;
    }
    return a;
}

static void use_at(sched *s, ir_ref r, int region)
{
    if (!ir_ref_ok(r))
        return;
    int *p = &s->place[r.id];
    *p = *p < 0 ? region : lca(s, *p, region);
}

/* ---- lazy branches (an emission rule) -------------------------------------
 *
 * An operand side of a `mix`, `select` or `mul` whose weight can make it
 * not count is its own region, guarded by a quad-uniform branch, when the
 * work only that side needs (the nodes the scheduler places in its region,
 * in ir_cost units) is worth more than SPLAT_LAZY_MIN_COST
 * (compiler/DESIGN.md §6.1):
 *
 *     mix(a, b, t)     a when t can be 1, if (t < 1);  b when t can be 0, if (t > 0)
 *     select(c, a, b)  a if (c != 0);  b if (c == 0)
 *     mul(w, x)        x when w can be 0, if (w != 0)  (where both operands
 *                      can be 0, the side with more work of its own)
 *
 * The weight must be able to take that value over an area (plateau_of
 * below: clamps, steps, comparisons, painted masks, params and what they
 * flow through), within the interval evaluator's bounds over every input's
 * domain: a weight that cannot be 0 (or 1), or is so only at isolated
 * points (a noise's fade), gets no branch.  A skipped side reads 0,
 * so the result equals eager evaluation wherever the operands are finite:
 * mix(0, b, 1) = b, mix(a, 0, 0) = a, 0 * w = 0 when w = 0.  Before
 * (a tri-planar tap, eager):
 *
 *     vec4 v12 = texture(u_texa_0, vec3(v11, 0.0));            // x projection
 *     vec4 v20 = v19 * v12;                        // v19 = its weight
 *
 * after:
 *
 *     vec4 lz20_1 = vec4(0.0);
 *     if (splat_quad_any(v18 != 0.0)) {            // v19 = vec4(v18)
 *         vec2 v11 = ...;  vec4 v12 = texture(u_texa_0, vec3(v11, 0.0));
 *         lz20_1 = v12;
 *     }
 *     vec4 v20 = v19 * lz20_1;
 */

/* Whether some component of `iv` (w of them) can be exactly `x`. */
bool compose_can_be(const ir_iv *iv, int w, double x)
{
    for (int c = 0; c < w; c++)
        if (iv[c].lo <= x && x <= iv[c].hi)
            return true;
    return false;
}


/* Node `id` (placed at s->place[id]): open a lazy side region for each
 * operand that may be skipped (plat: plateau_of per node); its uses then
 * go there. */
static void lazy_sides(sched *s, uint32_t id, const uint8_t *plat)
{
    const ir *ir = s->ir;
    const ir_node *n = &ir->nodes[id];
    bool side[3] = {false, false, false};
    switch (n->op) {
    case IR_OP_MIX:
        side[0] = plat[n->arg[2].id] & PLAT_1;
        side[1] = plat[n->arg[2].id] & PLAT_0;
        break;
    case IR_OP_SELECT:   /* not folded: c is 0 somewhere, not everywhere */
        side[1] = side[2] = true;
        break;
    case IR_OP_MUL:   /* both may vanish: lazy_settle keeps the dearer side */
        side[1] = plat[n->arg[0].id] & PLAT_0;
        side[0] = plat[n->arg[1].id] & PLAT_0;
        break;
    default:
        return;
    }
    if (ir_ref_eq(n->arg[0], n->arg[1]))
        return;
    for (int a = 0; a < n->nargs; a++) {
        if (!side[a])
            continue;
        int r = region_new(s, s->place[id]);
        s->regions[r].owner = id;
        s->regions[r].side = a;
        s->lazy[id][a] = r;
    }
}

/* Keep the lazy regions worth SPLAT_LAZY_MIN_COST; every node placed in
 * one that is not moves to its nearest kept (or plain) ancestor. */
static void lazy_settle(sched *s)
{
    long *cost = xcalloc((size_t)s->nregions, sizeof *cost);
    for (uint32_t i = 1; i < s->ir->nnodes; i++)
        if (s->place[i] >= 0)
            cost[s->place[i]] += ir_node_cost(s->ir, (ir_ref){i});
    for (int r = s->nregions; r-- > 1;)   /* children after their parents */
        cost[s->regions[r].parent] += cost[r];
    for (int r = 0; r < s->nregions; r++) {
        region *g = &s->regions[r];
        g->kept = g->owner && cost[r] > SPLAT_LAZY_MIN_COST;
    }
    /* a mul of two operands that may vanish: one is the other's weight,
     * the side with more work of its own is skipped (a parallax step's
     * sample, not the chain of earlier steps its `alive` weight ends) */
    for (int r = 0; r < s->nregions; r++) {
        region *g = &s->regions[r];
        const ir_node *n = &s->ir->nodes[g->owner];
        if (!g->kept || n->op != IR_OP_MUL || g->side != 0)
            continue;
        int o = s->lazy[g->owner][1];
        if (o >= 0 && s->regions[o].kept) {
            if (cost[o] > cost[r])
                g->kept = false;
            else
                s->regions[o].kept = false;
        }
    }
    int *eff = xcalloc((size_t)s->nregions, sizeof *eff);
    for (int r = 0; r < s->nregions; r++) {
        region *g = &s->regions[r];
        eff[r] = !g->owner || g->kept ? r : eff[g->parent];
        if (g->owner && !g->kept)
            s->lazy[g->owner][g->side] = -1;
        s->nlazy += g->kept;
    }
    for (uint32_t i = 1; i < s->ir->nnodes; i++)
        if (s->place[i] >= 0)
            s->place[i] = eff[s->place[i]];
    free(eff);
    free(cost);
}

/* Regions and uses of a composite; `flat` puts everything at the root;
 * `lazy` adds the lazy side regions above. */
void compose_schedule(sched *s, const ir *ir, const splat_layer *layers, int n,
                     bool flat, const uint8_t *lazy)
{
    s->ir = ir;
    s->regions = NULL;
    s->nregions = s->capregions = 0;
    s->nlazy = 0;
    s->lazy = xcalloc(ir->nnodes, sizeof *s->lazy);
    for (uint32_t i = 0; i < ir->nnodes; i++)
        s->lazy[i][0] = s->lazy[i][1] = s->lazy[i][2] = s->lazy[i][3] = -1;
    s->guard = xcalloc((size_t)n, sizeof *s->guard);
    s->surface = xcalloc((size_t)n, sizeof *s->surface);
    s->place = xcalloc(ir->nnodes, sizeof *s->place);
    for (uint32_t i = 0; i < ir->nnodes; i++)
        s->place[i] = -1;
    int root = region_new(s, -1);
    int outer = root;
    for (int j = 0; j < n; j++) {
        s->guard[j] = flat ? root : region_new(s, outer);
        s->surface[j] = flat ? root : region_new(s, s->guard[j]);
        outer = s->guard[j];
    }
    for (int j = 0; j < n; j++) {
        const splat_layer *l = &layers[j];
        int parent = s->regions[s->guard[j]].parent;
        use_at(s, l->T, parent < 0 ? root : parent);
        use_at(s, l->mask, s->guard[j]);
        use_at(s, l->weight, s->guard[j]);
        use_at(s, l->T_next, s->guard[j]);
        use_at(s, l->weight, s->surface[j]);
        for (int o = 1; o < SG_OUT_COUNT; o++)
            use_at(s, l->out[o], s->surface[j]);
    }
    /* Users before operands: operands always have smaller ids. */
    for (uint32_t i = ir->nnodes; i-- > 1;) {
        if (s->place[i] < 0)
            continue;
        const ir_node *nd = &ir->nodes[i];
        if (lazy && !flat)
            lazy_sides(s, i, lazy);
        for (int a = 0; a < nd->nargs; a++)
            use_at(s, nd->arg[a], s->lazy[i][a] >= 0 ? s->lazy[i][a] : s->place[i]);
    }
    if (lazy && !flat)
        lazy_settle(s);
}

void compose_sched_free(sched *s)
{
    free(s->regions);
    free(s->lazy);
    free(s->guard);
    free(s->surface);
    free(s->place);
}
