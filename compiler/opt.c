/* opt.c — the pass pipeline and the rebuild step every pass shares.
 *
 * The whole pipeline (ir_optimize), to a fixed point:
 *     dedup   merge texture resources with equal file + sampler state
 *     fold    constant folding and safe algebraic identities
 *     dce     drop unreachable nodes and unused params/textures/painted
 * CSE needs no pass: the builder hash-conses every node, so a rebuild
 * merges whatever the other passes made identical.  The table also names
 * the passes run on their own (ir_pass_run): differentiate and pin.
 */
#include "ir.h"

#include <assert.h>
#include <stdlib.h>
#include <string.h>

static bool run_dedup(ir *ir, const void *arg) { (void)arg; return opt_dedup(ir); }
static bool run_fold(ir *ir, const void *arg) { (void)arg; return opt_fold(ir); }
static bool run_dce(ir *ir, const void *arg) { (void)arg; return opt_dce(ir); }
static bool run_differentiate(ir *ir, const void *arg) { (void)arg; return ir_differentiate(ir); }
static bool run_pin(ir *ir, const void *arg) { return opt_pin(ir, arg); }

const ir_pass ir_passes[] = {
    {"dedup", run_dedup, true},
    {"fold", run_fold, true},
    {"dce", run_dce, true},
    {"differentiate", run_differentiate, false},
    {"pin", run_pin, false},
    {NULL, NULL, false},
};

const ir_pass *ir_pass_find(const char *name)
{
    for (const ir_pass *p = ir_passes; p->name; p++)
        if (!strcmp(p->name, name))
            return p;
    return NULL;
}

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

#ifdef SPLAT_VALIDATE_IR
static void validate_after(const ir *ir, const char *pass)
{
    if (!ir_validate(ir, stderr)) {
        fprintf(stderr, "splatc: internal compiler error: invalid IR after pass '%s'\n", pass);
        abort();   /* a compiler bug, never a user error */
    }
}
#endif

static bool run_validated(ir *ir, const ir_pass *p, const void *arg)
{
    bool progress = p->run(ir, arg);
#ifdef SPLAT_VALIDATE_IR
    validate_after(ir, p->name);
#endif
    return progress;
}

bool ir_pass_run(ir *ir, const char *name, const void *arg)
{
    const ir_pass *p = ir_pass_find(name);
    if (!p) {
        fprintf(stderr, "splatc: internal compiler error: no pass '%s'\n", name);
        abort();
    }
#ifdef SPLAT_VALIDATE_IR
    validate_after(ir, "(input)");
#endif
    return run_validated(ir, p, arg);
}

void ir_optimize(ir *ir, const char *stop_after)
{
#ifdef SPLAT_VALIDATE_IR
    validate_after(ir, "(input)");
#endif
    for (int round = 0;; round++) {
        bool progress = false;
        for (const ir_pass *p = ir_passes; p->name; p++) {
            if (!p->pipeline)
                continue;
            progress |= run_validated(ir, p, NULL);
            if (stop_after && strcmp(stop_after, p->name) == 0)
                return;
        }
        if (!progress)
            return;
        /* Every pass only shrinks or simplifies; a long loop is a bug. */
        assert(round < 1000);
    }
}
