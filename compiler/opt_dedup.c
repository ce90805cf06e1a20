/* opt_dedup.c — merge duplicate texture resources.
 *
 * Two textures with the same file and sampler state (filter, mip filter,
 * wrap, sRGB) are one resource: every TEXTURE node is renumbered to the
 * first of its group (its [lo, hi] becomes the union of the group's, which
 * stays sound).  The rebuild then hash-conses the now equal TEXTURE nodes
 * and, through them, the equal SAMPLE nodes: two materials sampling the same
 * file at the same uv sample it once.  opt_dce drops the orphaned entries.
 *
 * Before:                                      After:
 *   texture t0 { file = "rock.png", … }          texture t0 { file = "rock.png", … }
 *   texture t1 { file = "rock.png", … }          texture t1 { file = "rock.png", … }
 *   node n1 : terrain.uv                         node n1 : terrain.uv
 *   node n2 : sample { tex = t0, uv = n1.out }   node n2 : sample { tex = t0, uv = n1.out }
 *   node n3 : sample { tex = t1, uv = n1.out }   node n3 : add { a = n2.out, b = n2.out }
 *   node n4 : add { a = n2.out, b = n3.out }
 *   (t1 is now unused; the next opt_dce removes it)
 */
#include "ir.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static ir_ref retarget(ir *dst, const ir_node *n, void *user)
{
    const int *to = user;
    ir_node c = *n;
    if (c.op == IR_OP_TEXTURE)
        c.imm = (uint32_t)to[c.imm];
    return ir_node_add(dst, &c);
}

bool opt_dedup(ir *ir)
{
    int n = ir->ntextures;
    int *to = malloc(sizeof(int) * ((size_t)n + 1));
    if (!to) {
        fprintf(stderr, "splatc: out of memory\n");
        abort();
    }
    bool merged = false;
    for (int i = 0; i < n; i++) {
        to[i] = i;
        for (int j = 0; j < i; j++)
            if (to[j] == j && ir_texture_same(&ir->textures[j], &ir->textures[i])) {
                to[i] = j;
                ir_texture *keep = &ir->textures[j];
                keep->lo = fmin(keep->lo, ir->textures[i].lo);
                keep->hi = fmax(keep->hi, ir->textures[i].hi);
                break;
            }
    }
    /* Only a texture some node reads is worth a rebuild. */
    for (uint32_t id = 1; id < ir->nnodes; id++)
        if (ir->nodes[id].op == IR_OP_TEXTURE && to[ir->nodes[id].imm] != (int)ir->nodes[id].imm)
            merged = true;
    bool changed = merged && ir_rebuild(ir, retarget, to);
    free(to);
    return changed;
}
