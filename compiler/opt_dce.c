/* opt_dce.c — dead code elimination.
 *
 * Keeps only what a root reaches: unreached nodes disappear (ir_rebuild
 * drops them) and params, textures and painted masks no reached node
 * reads are removed from their tables, the survivors renumbered in their
 * old order (so the uniform block and bindings stay in declaration order).
 *
 * Before:                                   After:
 *   param float m.unused = 1                  param float m.wet = 0.2
 *   param float m.wet = 0.2                   node n1 : param { name = "m.wet" }
 *   node n1 : param { name = "m.unused" }     node n2 : terrain.slope
 *   node n2 : param { name = "m.wet" }        node n3 : mul { a = n1.out, b = n2.out }
 *   node n3 : terrain.slope                   out m.mask = n3.out
 *   node n4 : add { a = n1.out, b = n3.out }
 *   node n5 : mul { a = n2.out, b = n3.out }
 *   out m.mask = n5.out
 */
#include "ir.h"

#include <stdlib.h>
#include <string.h>

typedef struct remap {
    int *param, *texture, *painted;   /* old index -> new index, -1 = dropped */
} remap;

static ir_ref renumber(ir *dst, const ir_node *n, void *user)
{
    const remap *m = user;
    ir_node c = *n;
    if (c.op == IR_OP_PARAM)
        c.imm = (uint32_t)m->param[c.imm];
    else if (c.op == IR_OP_TEXTURE)
        c.imm = (uint32_t)m->texture[c.imm];
    else if (c.op == IR_OP_PAINTED)
        c.imm = (uint32_t)m->painted[c.imm];
    return ir_node_add(dst, &c);
}

/* Compact one table: keep[i] -> new index in map[i], frees dropped names. */
#define COMPACT(arr, count, map, keep, field)                              \
    do {                                                                   \
        int k_ = 0;                                                        \
        for (int i_ = 0; i_ < (count); i_++) {                             \
            if (keep[i_]) {                                                \
                map[i_] = k_;                                              \
                (arr)[k_++] = (arr)[i_];                                   \
            } else {                                                       \
                map[i_] = -1;                                              \
                free((arr)[i_].field);                                     \
            }                                                              \
        }                                                                  \
        (count) = k_;                                                      \
    } while (0)

bool opt_dce(ir *ir)
{
    bool changed = ir_rebuild(ir, NULL, NULL);   /* drops unreached nodes */

    /* Every node left is reached: mark the table entries they read. */
    int np = ir->nparams, nt = ir->ntextures, nm = ir->npainted;
    uint8_t *used = calloc((size_t)(np + nt + nm) + 1, 1);
    int *map = malloc(sizeof(int) * ((size_t)(np + nt + nm) + 1));
    if (!used || !map) {
        fprintf(stderr, "splatc: out of memory\n");
        abort();
    }
    uint8_t *up = used, *ut = used + np, *um = used + np + nt;
    for (uint32_t id = 1; id < ir->nnodes; id++) {
        const ir_node *n = &ir->nodes[id];
        if (n->op == IR_OP_PARAM) up[n->imm] = 1;
        if (n->op == IR_OP_TEXTURE) ut[n->imm] = 1;
        if (n->op == IR_OP_PAINTED) um[n->imm] = 1;
    }
    bool all = true;
    for (int i = 0; i < np + nt + nm; i++)
        all = all && used[i];
    if (!all) {
        remap m = {map, map + np, map + np + nt};
        COMPACT(ir->params, ir->nparams, m.param, up, name);
        COMPACT(ir->textures, ir->ntextures, m.texture, ut, file);
        COMPACT(ir->painted, ir->npainted, m.painted, um, name);
        ir_rebuild(ir, renumber, &m);
        changed = true;
    }
    free(used);
    free(map);
    return changed;
}
