/* test_random_agree.c — the CPU back ends agree on random graphs.
 *
 * Random well-typed graphs over every op (random_ir.h, seeded): for many
 * random input regions the interval evaluator's bounds must contain the
 * double-precision reference at many random points of the region (a NaN
 * value only inside [-inf, +inf]); and the optimiser must not change any
 * value (folding evaluates with the same op table).  The GPU third of the
 * check (emitted GLSL on lavapipe against this reference) is
 * tests/harness/test_gpu_agree.c; random_ir.h is header-only so that
 * harness (or any other test) can draw the same graphs.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>

#include "ir.h"
#include "random_ir.h"

#ifndef GRAPHS
#define GRAPHS 1000
#endif
enum { BOXES = 12, POINTS = 40, DEPTH = 6 };

static bool contains(ir_iv b, double v)
{
    if (isnan(v))
        return b.lo == -INFINITY && b.hi == INFINITY;
    return b.lo <= v && v <= b.hi;
}

static ir_iv shrink(random_ir_rng *rng, ir_iv x, int mode)
{
    double p = random_ir_in(rng, x);
    if (mode == 1)
        return (ir_iv){p, p};
    /* a box a few ulps wide: rounding is all that varies */
    return (ir_iv){p, fmin(x.hi, p + 1e-12 * fabs(p) + 1e-300)};
}

/* mode 0: the region as generated; 1: one point; 2: a sliver. */
static void shrink_box(random_ir_rng *rng, ir_ienv *box, ir_iv *piv, ir_iv *miv, int mode)
{
    if (mode == 0)
        return;
    box->height = shrink(rng, box->height, mode);
    box->slope = shrink(rng, box->slope, mode);
    box->view_distance = shrink(rng, box->view_distance, mode);
    box->destruction = shrink(rng, box->destruction, mode);
    for (int c = 0; c < 3; c++) {
        box->normal[c] = shrink(rng, box->normal[c], mode);
        box->position[c] = shrink(rng, box->position[c], mode);
    }
    for (int c = 0; c < 2; c++)
        box->uv[c] = shrink(rng, box->uv[c], mode);
    for (int i = 0; i < RANDOM_IR_NPARAMS; i++)
        piv[i] = shrink(rng, piv[i], mode);
    for (int i = 0; i < RANDOM_IR_NPAINTED; i++)
        miv[i] = shrink(rng, miv[i], mode);
}

/* Name the first node (in id order) whose value escapes its bounds: the
 * op whose interval rule is wrong. */
static void report(const ir *ir, int graph, const ir_ienv *box, const ir_env *env)
{
    for (uint32_t id = 1; id < ir->nnodes; id++) {
        const ir_node *n = &ir->nodes[id];
        if (n->type == IR_T_TEX)
            continue;
        ir_iv b[4];
        double v[4];
        ir_interval(ir, (ir_ref){id}, box, b);
        ir_eval(ir, (ir_ref){id}, env, v);
        for (int c = 0; c < ir_type_width((ir_type)n->type); c++)
            if (!contains(b[c], v[c])) {
                const ir_opinfo *info = ir_opinfo_get((ir_op)n->op);
                fprintf(stderr, "graph %d: node n%u (%s) component %d: %.17g outside "
                        "[%.17g, %.17g]; operands:\n", graph, id,
                        info->name ? info->name : "internal", c, v[c], b[c].lo, b[c].hi);
                for (int i = 0; i < n->nargs; i++) {
                    ir_iv ab[4];
                    double av[4];
                    ir_interval(ir, n->arg[i], box, ab);
                    ir_eval(ir, n->arg[i], env, av);
                    for (int k = 0; k < ir_type_width(ir_typeof(ir, n->arg[i])); k++)
                        fprintf(stderr, "  arg %d.%d = %.17g in [%.17g, %.17g]\n", i, k,
                                av[k], ab[k].lo, ab[k].hi);
                }
                return;
            }
    }
}

static void test_eval_inside_interval(void **state)
{
    random_ir_rng rng = {12345};
    long checks = 0, finite_bounds = 0, nbounds = 0;
    for (int g = 0; g < GRAPHS; g++) {
        ir ir;
        ir_init(&ir);
        random_ir_setup(&ir);
        ir_type t = ir_type_vec(1 + random_ir_int(&rng, 4));
        ir_ref r = random_ir_expr(&ir, &rng, t, DEPTH, NULL);
        ir_set_root(&ir, "root", r);
        assert_true(ir_validate(&ir, stderr));
        for (int b = 0; b < BOXES; b++) {
            ir_iv piv[RANDOM_IR_NPARAMS], miv[RANDOM_IR_NPAINTED];
            ir_ienv box;
            random_ir_box(&ir, &rng, &box, piv, miv);
            shrink_box(&rng, &box, piv, miv, b % 3);
            ir_iv bounds[4];
            ir_interval(&ir, r, &box, bounds);
            for (int c = 0; c < ir_type_width(t); c++) {
                assert_false(isnan(bounds[c].lo) || isnan(bounds[c].hi));
                assert_true(bounds[c].lo <= bounds[c].hi);
                finite_bounds += isfinite(bounds[c].lo) && isfinite(bounds[c].hi);
                nbounds++;
            }
            for (int p = 0; p < POINTS; p++) {
                double pv[4 * RANDOM_IR_NPARAMS], mv[RANDOM_IR_NPAINTED], v[4];
                ir_env env;
                random_ir_point(&ir, &rng, &box, &env, pv, mv);
                ir_eval(&ir, r, &env, v);
                for (int c = 0; c < ir_type_width(t); c++) {
                    if (!contains(bounds[c], v[c])) {
                        report(&ir, g, &box, &env);
                        fail();
                    }
                    checks++;
                }
            }
        }
        ir_free(&ir);
    }
    printf("random agree: %ld point checks, %ld of %ld component bounds finite\n", checks,
           finite_bounds, nbounds);
    /* the bounds must be informative, not all [-inf, inf] */
    assert_true(finite_bounds > nbounds / 2);
}

static bool same_value(double a, double b)
{
    return a == b || (isnan(a) && isnan(b));
}

static void test_optimiser_keeps_values(void **state)
{
    random_ir_rng rng = {777};
    int changed = 0;
    for (int g = 0; g < GRAPHS; g++) {
        ir before, after;
        ir_init(&before);
        random_ir_setup(&before);
        ir_type t = ir_type_vec(1 + random_ir_int(&rng, 4));
        ir_set_root(&before, "root", random_ir_expr(&before, &rng, t, DEPTH, NULL));
        /* the same graph again, to optimise */
        ir_init(&after);
        ir_import_map *m = ir_import_begin(&after, &before);
        ir_set_root(&after, "root", ir_import(m, ir_find_root(&before, "root")));
        ir_import_end(m);
        ir_optimize(&after, NULL);
        assert_true(ir_validate(&after, stderr));
        changed += after.nnodes != before.nnodes;
        for (int p = 0; p < 20; p++) {
            ir_iv piv[RANDOM_IR_NPARAMS], miv[RANDOM_IR_NPAINTED];
            ir_ienv box;
            random_ir_box(&before, &rng, &box, piv, miv);
            double pv[4 * RANDOM_IR_NPARAMS], mv[RANDOM_IR_NPAINTED], a[4], b[4];
            ir_env env;
            random_ir_point(&before, &rng, &box, &env, pv, mv);
            /* params are looked up by index: keep them aligned */
            double pa[4 * RANDOM_IR_NPARAMS] = {0};
            for (int i = 0; i < after.nparams; i++)
                for (int j = 0; j < before.nparams; j++)
                    if (strcmp(after.params[i].name, before.params[j].name) == 0)
                        memcpy(&pa[4 * i], &pv[4 * j], 4 * sizeof(double));
            ir_eval(&before, ir_find_root(&before, "root"), &env, a);
            env.params = pa;
            ir_eval(&after, ir_find_root(&after, "root"), &env, b);
            for (int c = 0; c < ir_type_width(t); c++)
                if (!same_value(a[c], b[c])) {
                    fprintf(stderr, "graph %d: %.17g became %.17g\n", g, a[c], b[c]);
                    ir_dump(&before, stderr);
                    ir_dump(&after, stderr);
                    fail();
                }
        }
        ir_free(&before);
        ir_free(&after);
    }
    assert_true(changed > GRAPHS / 10);   /* the optimiser had work to do */
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_eval_inside_interval),
        cmocka_unit_test(test_optimiser_keeps_values),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
