/* ir_rebuild.c — the rebuild step every pass shares (ir_rebuild, ir.h):
 * the reachable nodes copied into a fresh node array in id order, each
 * through the pass's rewrite (or as it is), hash-consed again on the way,
 * so a rebuild also merges whatever the rewrite made identical and drops
 * what nothing reaches.  The passes (opt_*.c, ir_differentiate.c) call it;
 * it calls only the builder (ir.c).
 */
#include "ir.h"

#include <assert.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static bool rebuild_once(ir *ir, ir_rewrite_fn fn, void *user, bool *dead_left)
{
    uint32_t n = ir->nnodes;
    uint8_t *reach = calloc(n, 1);
    uint32_t *map = calloc(n, sizeof *map);
    if (!reach || !map) {
        fprintf(stderr, "splatc: out of memory\n");
        abort();
    }
    for (int i = 0; i < ir->nroots; i++)
        reach[ir->roots[i].ref.id] = 1;
    for (uint32_t id = n - 1; id > 0; id--)
        if (reach[id])
            for (int i = 0; i < ir->nodes[id].nargs; i++)
                reach[ir->nodes[id].arg[i].id] = 1;

    /* A fresh node array; the tables move over unchanged. */
    struct ir dst;
    ir_init(&dst);
    dst.params = ir->params;     dst.nparams = ir->nparams;     dst.capparams = ir->capparams;
    dst.textures = ir->textures; dst.ntextures = ir->ntextures; dst.captextures = ir->captextures;
    dst.painted = ir->painted;   dst.npainted = ir->npainted;   dst.cappainted = ir->cappainted;
    dst.roots = ir->roots;       dst.nroots = ir->nroots;       dst.caproots = ir->caproots;

    for (uint32_t id = 1; id < n; id++) {
        if (!reach[id])
            continue;
        ir_node node = ir->nodes[id];
        for (int i = 0; i < node.nargs; i++)
            node.arg[i].id = map[node.arg[i].id];
        map[id] = (fn ? fn(&dst, &node, user) : ir_node_add(&dst, &node)).id;
        assert(map[id] != 0);
    }

    bool changed = dst.nnodes != ir->nnodes ||
                   memcmp(dst.nodes, ir->nodes, sizeof(ir_node) * n) != 0;
    for (int i = 0; i < dst.nroots; i++) {
        uint32_t to = map[dst.roots[i].ref.id];
        changed = changed || to != dst.roots[i].ref.id;
        dst.roots[i].ref.id = to;
    }
    free(ir->nodes);
    free(ir->table);
    *ir = dst;

    /* A rewrite may leave nodes behind that nothing uses any more (the
     * operands of a folded constant): report them for a second sweep. */
    free(reach);
    reach = calloc(ir->nnodes, 1);
    if (!reach) {
        fprintf(stderr, "splatc: out of memory\n");
        abort();
    }
    for (int i = 0; i < ir->nroots; i++)
        reach[ir->roots[i].ref.id] = 1;
    *dead_left = false;
    for (uint32_t id = ir->nnodes - 1; id > 0; id--) {
        if (!reach[id]) {
            *dead_left = true;
            continue;
        }
        for (int i = 0; i < ir->nodes[id].nargs; i++)
            reach[ir->nodes[id].arg[i].id] = 1;
    }
    free(reach);
    free(map);
    return changed;
}

bool ir_rebuild(ir *ir, ir_rewrite_fn fn, void *user)
{
    bool dead;
    bool changed = rebuild_once(ir, fn, user, &dead);
    if (dead)
        changed |= rebuild_once(ir, NULL, NULL, &dead);
    return changed;
}
