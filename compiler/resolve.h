/* resolve.h — the resolver's internals, shared by its files (sg_resolve,
 * the entry point, is in sg_internal.h):
 *
 *   resolve_names.c  scopes' names and paths: what a value's path names,
 *                    "did you mean" for the unknown ones, swizzles
 *   resolve_types.c  type checking of op nodes (the op table's rule with
 *                    splatting), instances and painted masks
 *   resolve_order.c  the iterative DFS: dependency order and cycles
 *   resolve.c        per shader and for the whole program, in order
 */
#ifndef SPLAT_RESOLVE_H
#define SPLAT_RESOLVE_H

#include "sg_internal.h"

typedef struct checker {
    sg_program *p;
    sg_diags   *d;
    sg_shader  *s;        /* current scope                                */
    sg_map      locals;   /* name -> (index << 2) | local kind            */
    int         suppressed; /* unknown names left unreported in this scope:
                               an import failed, they may be its (parse.c) */
} checker;

enum { L_NODE, L_IN, L_PARAM };   /* a local's kind (checker.locals) */

/* ---- names and paths (resolve_names.c) ----------------------------------- */

/* An unknown global name after a failed import: counted, not reported. */
bool rs_after_failed_import(checker *c);
void rs_duplicate(checker *c, sg_loc loc, const char *what, const char *name, sg_loc first);
ir_type rs_apply_swizzle(checker *c, sg_value *v, ir_type base);
/* "did you mean" candidates, or NULL */
const char *rs_near_node_type(checker *c, const char *word);
const char *rs_near_port(const sg_port *ports, int n, const char *word);
void rs_hint_swizzle(checker *c, const sg_value *v, ir_type want);
/* What the value's path names (locals only where allow_locals); false
 * after reporting why not. */
bool rs_resolve_path(checker *c, sg_value *v, bool allow_locals);

/* ---- types (resolve_types.c) ---------------------------------------------- */

void rs_check_op(checker *c, sg_node *n);
/* A value of `want` type (a float literal splats: *splat set)? */
bool rs_assignable(const sg_value *v, ir_type want, ir_type *splat);
void rs_check_instance(checker *c, sg_node *n);
void rs_check_painted(checker *c, sg_node *n);

/* ---- dependency order (resolve_order.c) ----------------------------------- */

typedef struct graph {
    int  n;
    int *start;   /* n + 1 offsets into adj */
    int *adj;
} graph;

typedef void (*cycle_fn)(void *user, const int *path, int len);

/* Post-order (dependencies first) of every vertex; each back edge found
 * calls on_cycle with the path v0 -> ... -> vk (-> v0).  Iterative.
 * malloc'd. */
int *rs_dfs_order(const graph *g, cycle_fn on_cycle, void *user);

#endif
