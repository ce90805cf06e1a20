/* opt.c — the pass manager: the pass table, one pass run with the
 * validator after it, and the pipeline.  It sits above the passes; the
 * rebuild step every pass shares is ir_rebuild.c, below them.
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
