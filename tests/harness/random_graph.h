/* random_graph.h — random well-typed IR graphs and random inputs for them,
 * for tests that check the back ends against each other.
 *
 * rg_setup declares the leaves a graph may use (two params, a painted mask,
 * a texture); rg_expr builds a random expression of a given type through
 * the IR builder, over every op of IR_OPS and every input.  Deterministic
 * for a given seed. */
#ifndef SPLAT_RANDOM_GRAPH_H
#define SPLAT_RANDOM_GRAPH_H

#include <stdint.h>

#include "ir.h"

typedef struct rg_rng { uint64_t s; } rg_rng;

uint64_t rg_next(rg_rng *r);               /* splitmix64                  */
double   rg_uniform(rg_rng *r, double lo, double hi); /* fp32-representable */
int      rg_int(rg_rng *r, int n);         /* 0 .. n-1                    */

/* Add the leaves rg_expr draws from to an empty ir. */
void   rg_setup(ir *ir);
/* A random expression of type t (float or vecN), at most `depth` ops deep. */
ir_ref rg_expr(ir *ir, rg_rng *r, ir_type t, int depth);
ir_type rg_type(rg_rng *r);                /* float, vec2, vec3 or vec4   */

/* Random inputs in terrain-like ranges, all fp32-representable: heights
 * 0..1000 m, slope 0..1, a unit-ish normal, positions 0..4096 m, uv 0..1,
 * view distance 0..3000 m, destruction 0 or 0..1, params -2..2, painted
 * 0..1.  `params` holds 4 * ir->nparams doubles, `painted` ir->npainted. */
void rg_env(const ir *ir, rg_rng *r, ir_env *env, double *params, double *painted);

#endif
