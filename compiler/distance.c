/* distance.c — distance classes: variants of a composite for ranges of
 * view.distance in which the graphs' distance-gated detail is provably
 * constant (e.g. nodes/parallax.sg's offset, 0 beyond `fade` metres).
 *
 * Boundaries come from the composite itself, not from a fixed near / mid /
 * far split.  With every other input at its domain (so a class holds on
 * any terrain), let
 *     far(b)  = how many values are one point over view.distance [b, inf]
 *     near(b) = the same over [0, b].
 * Interval evaluation is inclusion-monotone, so far() never falls as b
 * grows and near() never rises.  Each step of far() is a distance beyond
 * which something more is constant: found on a doubling grid from 1/4 m to
 * 2^22 m, each step then bisected (geometric, to 1e-4 relative) to the
 * smallest b at which the count has risen; that b itself is proven (it is
 * the bracket's upper end).  near() likewise, from above.  The candidate
 * classes are [b, inf] per far step and [0, b] per near step; each is the
 * composite with opt_pin over its interval, then ir_optimize.  A class is
 * kept only if ir_cost says it is cheaper than the composite and than the
 * kept class before it in its direction by SPLAT_DCLASS_MIN_SAVING of the
 * composite's cost (compose.h; a class nested in another is worth its
 * shader only if it saves more); at most SPLAT_MAX_DCLASSES.
 *
 * The runtime uses a class for a quadtree node or screen tile only when
 * the node's or tile's whole distance range lies inside the interval
 * (runtime/DESIGN.md "Distance classes").
 */
#include "compose.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "util.h"

static bool is_point(const ir_node *n, const ir_iv *v)
{
    int w = ir_type_width((ir_type)n->type);
    if (w == 0 || n->op == IR_OP_CONST || n->op == IR_OP_DINPUT)
        return false;
    for (int c = 0; c < w; c++)
        if (!(v[c].lo == v[c].hi) || !isfinite(v[c].lo))
            return false;
    return true;
}

static void region(ir_ienv *env, double lo, double hi)
{
    memset(env, 0, sizeof *env);
    ir_ienv_domain(env);
    env->view_distance = (ir_iv){lo, hi};
}

/* Values that are one point with view.distance in [lo, hi]. */
static int npinned(const ir *ir, ir_iv (*vals)[4], double lo, double hi)
{
    ir_ienv env;
    region(&env, lo, hi);
    ir_interval_all(ir, &env, vals);
    int n = 0;
    for (uint32_t id = 1; id < ir->nnodes; id++)
        n += is_point(&ir->nodes[id], vals[id]);
    return n;
}

enum { GRID_LO = -2, GRID_HI = 22 };   /* 2^k metres */

/* The far steps, ascending, into b[] (at most max). */
static int far_steps(const ir *ir, ir_iv (*vals)[4], double *b, int max)
{
    int n = 0;
    double cur = 0;
    int fcur = npinned(ir, vals, 0, INFINITY);
    for (int k = GRID_LO; k <= GRID_HI && n < max; k++) {
        double g = ldexp(1.0, k);
        int fg = npinned(ir, vals, g, INFINITY);
        while (fg > fcur && n < max) {
            double lo = cur, hi = g;   /* f(lo) == fcur < f(hi) */
            for (int it = 0; it < 60 && hi > lo * (1 + 1e-4); it++) {
                double mid = lo > 0 ? sqrt(lo * hi) : hi / 2;
                if (npinned(ir, vals, mid, INFINITY) > fcur)
                    hi = mid;
                else
                    lo = mid;
            }
            b[n++] = hi;
            cur = hi;
            fcur = npinned(ir, vals, hi, INFINITY);
        }
    }
    return n;
}

/* The near steps, descending, into b[]. */
static int near_steps(const ir *ir, ir_iv (*vals)[4], double *b, int max)
{
    int n = 0;
    double top = ldexp(1.0, GRID_HI + 1), cur = top;
    int gcur = npinned(ir, vals, 0, top);
    for (int k = GRID_HI; k >= GRID_LO && n < max; k--) {
        double g = ldexp(1.0, k);
        int gg = npinned(ir, vals, 0, g);
        while (gg > gcur && n < max) {
            double lo = g, hi = cur;   /* near(lo) > gcur == near(hi) */
            for (int it = 0; it < 60 && hi > lo * (1 + 1e-4); it++) {
                double mid = sqrt(lo * hi);
                if (npinned(ir, vals, 0, mid) > gcur)
                    lo = mid;
                else
                    hi = mid;
            }
            b[n++] = lo;
            cur = lo;
            gcur = npinned(ir, vals, 0, lo);
        }
    }
    return n;
}

/* The composite with view.distance in [lo, hi]: pinned, optimised. */
static void make_class(const splat_layout *L, const splat_composite *c, double lo, double hi,
                       splat_dclass *out, sg_diags *d)
{
    memset(out, 0, sizeof *out);
    out->lo = lo;
    out->hi = hi;
    splat_composite *v = &out->comp;
    ir_clone(&v->ir, &c->ir);
    v->nlayers = c->nlayers;
    v->layers = xcalloc((size_t)c->nlayers, sizeof *v->layers);
    memcpy(v->layers, c->layers, (size_t)c->nlayers * sizeof *v->layers);
    v->reference = c->reference;
    ir_ienv env;
    region(&env, lo, hi);
    ir_pass_run(&v->ir, "pin", &env);
    ir_optimize(&v->ir, NULL);
    splat_composite_refresh(L, v, d);
    out->cost = splat_composite_cost(v);
}

int splat_distance_classes(const splat_layout *L, const splat_composite *c,
                           splat_dclass **out, sg_diags *d)
{
    *out = NULL;
    const ir *ir = &c->ir;
    bool reads = false;
    for (uint32_t id = 1; id < ir->nnodes && !reads; id++)
        reads = ir->nodes[id].op == IR_OP_INPUT && ir->nodes[id].imm == IR_IN_VIEW_DISTANCE;
    if (!reads || c->reference)
        return 0;
    ir_iv (*vals)[4] = xcalloc(ir->nnodes, sizeof *vals);
    enum { MAXB = 16 };
    double fb[MAXB], nb[MAXB];
    int nf = far_steps(ir, vals, fb, MAXB);
    int nn = near_steps(ir, vals, nb, MAXB);
    free(vals);
    double full = splat_composite_cost(c);
    double need = fmax(SPLAT_LAZY_MIN_COST, SPLAT_DCLASS_MIN_SAVING * full);
    splat_dclass *v = xcalloc(SPLAT_MAX_DCLASSES, sizeof *v);
    double fcost[MAXB], ncost[MAXB];   /* each step's class, kept or not */
    int n = 0;
    for (int dir = 0; dir < 2; dir++) {
        double best = full;
        int m = dir == 0 ? nf : nn;
        for (int i = 0; i < m; i++) {
            splat_dclass t;
            double lo = dir == 0 ? fb[i] : 0, hi = dir == 0 ? INFINITY : nb[i];
            make_class(L, c, lo, hi, &t, d);
            (dir == 0 ? fcost : ncost)[i] = t.cost;
            if (n < SPLAT_MAX_DCLASSES && t.cost <= best - need) {
                best = t.cost;
                v[n++] = t;
            } else {
                splat_composite_free(&t.comp);
            }
        }
    }
    /* mid classes [fb[i], nb[j]]: what fades out nearer than fb[i] and
     * what fades in farther than nb[j] both pinned; worth their shader
     * only if cheaper than either side's class and every kept class
     * holding their interval */
    for (int i = 0; i < nf; i++)
        for (int j = 0; j < nn && n < SPLAT_MAX_DCLASSES; j++) {
            if (!(fb[i] < nb[j]))
                continue;
            double bound = fmin(full, fmin(fcost[i], ncost[j]));
            for (int k = 0; k < n; k++)
                if (v[k].lo <= fb[i] && nb[j] <= v[k].hi)
                    bound = fmin(bound, v[k].cost);
            make_class(L, c, fb[i], nb[j], &v[n], d);
            if (v[n].cost <= bound - need)
                n++;
            else
                splat_composite_free(&v[n].comp);
        }
    if (n == 0) {
        free(v);
        return 0;
    }
    *out = v;
    return n;
}

void splat_dclasses_free(splat_dclass *v, int n)
{
    for (int i = 0; i < n; i++)
        splat_composite_free(&v[i].comp);
    free(v);
}
