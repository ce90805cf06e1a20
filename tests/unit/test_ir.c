/* test_ir.c — the IR core: hash-consing, type rules, tables, roots,
 * import, and that the validator catches broken IR. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ir.h"

static void test_same_expression_same_ref(void **state)
{
    ir ir;
    ir_init(&ir);
    ir_ref h = ir_input(&ir, IR_IN_HEIGHT);
    ir_ref e1 = ir_op3(&ir, IR_OP_SMOOTHSTEP, ir_constf(&ir, 10), ir_constf(&ir, 20), h);
    uint32_t n = ir.nnodes;
    ir_ref e2 = ir_op3(&ir, IR_OP_SMOOTHSTEP, ir_constf(&ir, 10), ir_constf(&ir, 20),
                       ir_input(&ir, IR_IN_HEIGHT));
    assert_true(ir_ref_eq(e1, e2));
    assert_int_equal(ir.nnodes, n);            /* nothing new was added */
    /* a different constant is a different node */
    ir_ref e3 = ir_op3(&ir, IR_OP_SMOOTHSTEP, ir_constf(&ir, 10), ir_constf(&ir, 21), h);
    assert_false(ir_ref_eq(e1, e3));
    assert_true(ir_validate(&ir, stderr));
    ir_free(&ir);
}

static void test_commutative_canonical(void **state)
{
    ir ir;
    ir_init(&ir);
    ir_ref a = ir_input(&ir, IR_IN_SLOPE), b = ir_input(&ir, IR_IN_HEIGHT);
    static const ir_op comm[] = {IR_OP_ADD, IR_OP_MUL, IR_OP_MIN, IR_OP_MAX};
    for (int i = 0; i < 4; i++) {
        ir_ref ab = ir_op2(&ir, comm[i], a, b), ba = ir_op2(&ir, comm[i], b, a);
        assert_true(ir_ref_eq(ab, ba));
        /* operands in ascending id order */
        assert_true(ir_get(&ir, ab)->arg[0].id < ir_get(&ir, ab)->arg[1].id);
    }
    ir_ref n = ir_input(&ir, IR_IN_NORMAL), p = ir_input(&ir, IR_IN_POSITION);
    assert_true(ir_ref_eq(ir_op2(&ir, IR_OP_DOT, n, p), ir_op2(&ir, IR_OP_DOT, p, n)));
    /* not commutative: order matters */
    static const ir_op ordered[] = {IR_OP_SUB, IR_OP_DIV, IR_OP_POW, IR_OP_STEP, IR_OP_LESS};
    for (int i = 0; i < 5; i++)
        assert_false(ir_ref_eq(ir_op2(&ir, ordered[i], a, b), ir_op2(&ir, ordered[i], b, a)));
    assert_false(ir_ref_eq(ir_op2(&ir, IR_OP_CROSS, n, p), ir_op2(&ir, IR_OP_CROSS, p, n)));
    assert_true(ir_validate(&ir, stderr));
    ir_free(&ir);
}

/* x + x for many x: equal operands must not all collide (XOR hashing
 * would send every one to the same bucket); each is its own node. */
static void test_equal_operands_distinct(void **state)
{
    ir ir;
    ir_init(&ir);
    ir_ref prev[2000];
    for (int i = 0; i < 2000; i++) {
        ir_ref c = ir_constf(&ir, i);
        prev[i] = ir_op2(&ir, IR_OP_ADD, c, c);
    }
    for (int i = 0; i < 2000; i++)
        assert_true(ir_ref_eq(ir_op2(&ir, IR_OP_ADD, ir_constf(&ir, i), ir_constf(&ir, i)),
                              prev[i]));
    assert_int_equal(ir.nnodes, 1 + 2 * 2000);
    assert_true(ir_validate(&ir, stderr));
    ir_free(&ir);
}

static void test_constants_bitwise(void **state)
{
    ir ir;
    ir_init(&ir);
    assert_false(ir_ref_eq(ir_constf(&ir, 0.0), ir_constf(&ir, -0.0)));
    assert_true(ir_ref_eq(ir_constf(&ir, NAN), ir_constf(&ir, NAN)));
    assert_false(ir_ref_eq(ir_constf(&ir, 1.0), ir_constf(&ir, nextafter(1.0, 2.0))));
    double v3[3] = {1, 2, 3}, v3b[3] = {1, 2, 3};
    assert_true(ir_ref_eq(ir_const(&ir, IR_T_VEC3, v3), ir_const(&ir, IR_T_VEC3, v3b)));
    double v2[2] = {1, 2};
    /* same leading values, other type: another node */
    assert_false(ir_ref_eq(ir_const(&ir, IR_T_VEC3, v3), ir_const(&ir, IR_T_VEC2, v2)));
    assert_true(ir_validate(&ir, stderr));
    ir_free(&ir);
}

static ir_type rule(ir_op op, ir_type a, ir_type b, ir_type c, int n)
{
    ir_type t[3] = {a, b, c};
    return ir_opinfo_get(op)->type(t, n);
}

static void test_type_rules(void **state)
{
    const ir_type F = IR_T_FLOAT, V2 = IR_T_VEC2, V3 = IR_T_VEC3, V4 = IR_T_VEC4;
    assert_int_equal(rule(IR_OP_ADD, V3, V3, 0, 2), V3);
    assert_int_equal(rule(IR_OP_ADD, V3, F, 0, 2), IR_T_ERROR);   /* lowering splats */
    assert_int_equal(rule(IR_OP_MIX, V2, V2, V2, 3), V2);
    assert_int_equal(rule(IR_OP_MIX, V2, V2, F, 3), IR_T_ERROR);
    assert_int_equal(rule(IR_OP_LESS, F, F, 0, 2), F);
    assert_int_equal(rule(IR_OP_SELECT, V3, V3, V3, 3), V3);
    assert_int_equal(rule(IR_OP_SELECT, F, V3, V3, 3), IR_T_ERROR);
    assert_int_equal(rule(IR_OP_SAMPLE, IR_T_TEX, V2, 0, 2), V4);
    assert_int_equal(rule(IR_OP_SAMPLE, IR_T_TEX, V3, 0, 2), IR_T_ERROR);
    assert_int_equal(rule(IR_OP_SAMPLE, V2, V2, 0, 2), IR_T_ERROR);
    assert_int_equal(rule(IR_OP_DOT, V3, V3, 0, 2), F);
    assert_int_equal(rule(IR_OP_DOT, V3, V2, 0, 2), IR_T_ERROR);
    assert_int_equal(rule(IR_OP_LENGTH, V4, 0, 0, 1), F);
    assert_int_equal(rule(IR_OP_NORMALIZE, V3, 0, 0, 1), V3);
    assert_int_equal(rule(IR_OP_CROSS, V3, V3, 0, 2), V3);
    assert_int_equal(rule(IR_OP_CROSS, V4, V4, 0, 2), IR_T_ERROR);
    assert_int_equal(rule(IR_OP_CONSTRUCT, V2, F, 0, 2), V3);
    assert_int_equal(rule(IR_OP_CONSTRUCT, F, F, F, 3), V3);
    assert_int_equal(rule(IR_OP_CONSTRUCT, V3, V2, 0, 2), IR_T_ERROR);   /* width 5 */
    assert_int_equal(rule(IR_OP_CONSTRUCT, IR_T_TEX, F, 0, 2), IR_T_ERROR);
    assert_int_equal(rule(IR_OP_ADD, IR_T_TEX, IR_T_TEX, 0, 2), IR_T_ERROR);
}

/* The op table's rows are complete and their columns agree with each other:
 * names round-trip, evaluators exist where the semantics column says so,
 * and the finiteness column matches what the interval evaluator proves. */
static void test_op_table_rows(void **state)
{
    const ir_iv full = {-INFINITY, INFINITY}, lo = {-2, -1}, hi = {1, 2};
    for (int op = 0; op < IR_OP_COUNT; op++) {
        const ir_opinfo *i = ir_opinfo_get((ir_op)op);
        if (i->name)
            assert_int_equal(ir_op_by_name(i->name), op);
        assert_non_null(i->type);
        assert_non_null(i->glsl);
        assert_true(i->fp32 >= 0 && i->fp32 < IR_FP32_COUNT);
        bool leaf = op <= IR_OP_PAINTED || op == IR_OP_DINPUT;
        bool sample = op == IR_OP_SAMPLE || op == IR_OP_SAMPLE_GRAD;
        /* every non-leaf op but the samples has both evaluators */
        if (!leaf && !sample)
            assert_true(i->eval && i->interval);
        /* scalar functions exactly for the componentwise ops */
        bool cw = i->flags & IR_COMPONENTWISE;
        assert_int_equal(i->scalar_eval != NULL, cw);
        assert_int_equal(i->scalar_interval != NULL, cw);
        assert_true(!(i->flags & IR_NAN_PROPAGATES) || cw);
        for (int p = 0; p < i->nargs; p++)
            assert_non_null(i->ports[p]);
        /* cost: leaves and register moves are free, real work is not */
        bool moves = leaf || op == IR_OP_SPLAT || op == IR_OP_SWIZZLE || op == IR_OP_CONSTRUCT;
        assert_int_equal(i->cost == 0, moves);
        assert_true(i->finite == IR_FIN_DATA ? leaf || sample : true);
        /* a derivative rule wherever the result can move with an operand
         * (D0 only for leaves that never move and piecewise-constant ops) */
        /* (fwidth never reaches the IR: lowering expands it) */
        bool constant = op == IR_OP_FLOOR || op == IR_OP_STEP || op == IR_OP_LESS ||
                        op == IR_OP_FWIDTH;
        if (!leaf)
            assert_int_equal(ir_deriv_rule(op) != NULL, !constant);
        if (!cw)
            continue;
        /* finiteness vs intervals: operands the column needs finite get a
         * finite interval (lo <= hi for clamp), the others anything */
        ir_node n = {.op = (uint8_t)op, .type = IR_T_FLOAT, .nargs = (uint8_t)i->nargs};
        ir_type at[4] = {IR_T_FLOAT, IR_T_FLOAT, IR_T_FLOAT, IR_T_FLOAT};
        ir_iv a[16], out[4];
        for (int k = 0; k < 16; k++)
            a[k] = full;
        bool need_args = i->finite & IR_FIN_ARGS_BIT;
        for (int k = 0; k < i->nargs; k++)
            if (need_args && (i->finite >> k & 1))
                a[4 * k] = k == 1 ? lo : hi;
        i->interval(&n, at, a, out);
        bool finite = isfinite(out[0].lo) && isfinite(out[0].hi);
        if (finite != (i->finite != IR_FIN_NO))
            fail_msg("op %d: finiteness column %#x, interval [%g, %g]", op, i->finite,
                     out[0].lo, out[0].hi);
    }
    assert_int_equal(ir_op_by_name("no_such_op"), -1);
}

/* The input table: names round-trip, env slots are the fields, and
 * ir_ienv_domain sets what the domain column says. */
static void test_input_table_rows(void **state)
{
    ir_env env;
    ir_ienv ienv;
    memset(&ienv, 0, sizeof ienv);
    ir_ienv_domain(&ienv);
    for (int k = 0; k < IR_IN_COUNT; k++) {
        const ir_input_info *in = ir_input_get((ir_input_kind)k);
        assert_int_equal(ir_input_by_name(in->name), k);
        int w = ir_type_width(in->type);
        assert_true(w >= 1 && w <= 3);
        assert_true(in->env_off + (size_t)w * sizeof(double) <= sizeof env);
        assert_true(strncmp(in->local, "in_", 3) == 0);
        for (int c = 0; c < w; c++)
            assert_true(in->domain[c].lo <= in->domain[c].hi);
        ir_iv *slot = ir_ienv_slot(&ienv, (ir_input_kind)k);
        for (int c = 0; slot && c < w; c++)
            assert_true(slot[c].lo == in->domain[c].lo && slot[c].hi == in->domain[c].hi);
    }
    assert_ptr_equal(ir_env_slot(&env, IR_IN_VIEW_DISTANCE), &env.view_distance);
    assert_ptr_equal(ir_env_slot(&env, IR_IN_NORMAL), env.normal);
    assert_ptr_equal(ir_ienv_slot(&ienv, IR_IN_UV), ienv.uv);
    assert_null(ir_ienv_slot(&ienv, IR_IN_VIEW_DIRECTION));
    assert_true(ienv.slope.lo == 0 && ienv.slope.hi == 1);
    assert_true(ienv.view_distance.lo == 0 && isinf(ienv.view_distance.hi));
    assert_int_equal(ir_input_by_name("terrain.nope"), -1);
}

/* Cost: per component of the widest value, shared subtrees paid once. */
static void test_cost(void **state)
{
    ir ir;
    ir_init(&ir);
    ir_ref h = ir_input(&ir, IR_IN_HEIGHT), n = ir_input(&ir, IR_IN_NORMAL);
    ir_ref add = ir_op2(&ir, IR_OP_ADD, h, h);                       /* 1 x 1 */
    ir_ref nadd = ir_op2(&ir, IR_OP_ADD, n, n);                      /* 1 x 3 */
    ir_ref d = ir_op2(&ir, IR_OP_DOT, nadd, n);                      /* 2 x 3 */
    ir_ref s = ir_op1(&ir, IR_OP_SIN, add);                          /* 8 x 1 */
    assert_int_equal(ir_node_cost(&ir, h), 0);
    assert_int_equal(ir_node_cost(&ir, add), 1);
    assert_int_equal(ir_node_cost(&ir, nadd), 3);
    assert_int_equal(ir_node_cost(&ir, d), 6);
    ir_ref roots[3] = {d, s, ir_op2(&ir, IR_OP_MUL, d, s)};          /* + 1 */
    assert_int_equal(ir_cost(&ir, roots, 1), 9);
    assert_int_equal(ir_cost(&ir, roots, 2), 9 + 9);
    assert_int_equal(ir_cost(&ir, roots, 3), 9 + 9 + 1);             /* shared once */
    ir_free(&ir);
}

static void test_types(void **state)
{
    for (int w = 1; w <= 4; w++)
        assert_int_equal(ir_type_width(ir_type_vec(w)), w);
    assert_int_equal(ir_type_width(IR_T_TEX), 0);
    assert_int_equal(ir_type_vec(5), IR_T_ERROR);
    assert_string_equal(ir_type_name(IR_T_VEC3), "vec3");
    assert_int_equal(ir_type_from_name("vec2"), IR_T_VEC2);
    assert_int_equal(ir_type_from_name("texture"), IR_T_TEX);
    assert_int_equal(ir_type_from_name("vec5"), IR_T_ERROR);
}

static void test_shape_builders(void **state)
{
    ir ir;
    ir_init(&ir);
    ir_ref n = ir_input(&ir, IR_IN_NORMAL);
    assert_true(ir_ref_eq(ir_swizzle(&ir, n, "xyz"), n));   /* identity */
    assert_true(ir_ref_eq(ir_swizzle(&ir, n, "rgb"), n));
    ir_ref y = ir_swizzle(&ir, n, "g");
    assert_int_equal(ir_typeof(&ir, y), IR_T_FLOAT);
    assert_true(ir_ref_eq(y, ir_swizzle(&ir, n, "y")));     /* rgba = xyzw */
    ir_ref zx = ir_swizzle(&ir, n, "zx");
    assert_int_equal(ir_typeof(&ir, zx), IR_T_VEC2);
    assert_int_equal(IR_SWZ_N(ir_get(&ir, zx)->imm), 2);
    assert_int_equal(IR_SWZ_C(ir_get(&ir, zx)->imm, 0), 2);
    assert_int_equal(IR_SWZ_C(ir_get(&ir, zx)->imm, 1), 0);
    ir_ref h = ir_input(&ir, IR_IN_HEIGHT);
    assert_true(ir_ref_eq(ir_splat(&ir, h, IR_T_FLOAT), h));
    ir_ref s = ir_splat(&ir, h, IR_T_VEC3);
    assert_int_equal(ir_typeof(&ir, s), IR_T_VEC3);
    ir_ref args[2] = {zx, h};
    ir_ref c = ir_construct(&ir, IR_T_VEC3, args, 2);
    assert_int_equal(ir_get(&ir, c)->nargs, 2);
    assert_true(ir_validate(&ir, stderr));
    ir_free(&ir);
}

static void test_tables_and_roots(void **state)
{
    ir ir;
    ir_init(&ir);
    ir_param p = {.name = "cliff.wetness", .type = IR_T_FLOAT, .def = {0.2}, .lo = 0, .hi = 1};
    int i0 = ir_add_param(&ir, &p);
    assert_int_equal(ir_add_param(&ir, &p), i0);             /* interned by name */
    ir_param q = {.name = "cliff.tint", .type = IR_T_VEC3, .lo = 0, .hi = 1};
    assert_int_equal(ir_add_param(&ir, &q), 1);
    assert_ptr_not_equal(ir.params[0].name, p.name);          /* a copy */
    ir_texture t = {.file = "rock.png", .lo = 0, .hi = 1};
    assert_int_equal(ir_add_texture(&ir, &t), 0);
    assert_int_equal(ir_add_texture(&ir, &t), 1);             /* appends */
    assert_int_equal(ir_add_painted(&ir, "fields"), 0);
    assert_int_equal(ir_add_painted(&ir, "road"), 1);
    assert_int_equal(ir_add_painted(&ir, "fields"), 0);
    ir_ref a = ir_param_ref(&ir, 1);
    assert_int_equal(ir_typeof(&ir, a), IR_T_VEC3);
    ir_set_root(&ir, "cliff.albedo", a);
    ir_ref m = ir_painted_ref(&ir, 1);
    ir_set_root(&ir, "cliff.mask", m);
    assert_true(ir_ref_eq(ir_find_root(&ir, "cliff.albedo"), a));
    ir_ref m2 = ir_op1(&ir, IR_OP_SATURATE, m);
    ir_set_root(&ir, "cliff.mask", m2);                       /* replaces */
    assert_int_equal(ir.nroots, 2);
    assert_true(ir_ref_eq(ir_find_root(&ir, "cliff.mask"), m2));
    assert_false(ir_ref_ok(ir_find_root(&ir, "cliff.height")));
    assert_true(ir_validate(&ir, stderr));
    ir_free(&ir);
}

/* Two materials imported into one ir share their common subtrees. */
static void test_import_shares(void **state)
{
    ir a, b, dst;
    ir_init(&a);
    ir_init(&b);
    ir_init(&dst);
    ir_texture tex = {.file = "rock.png", .lo = 0, .hi = 1};
    ir_param p = {.name = "shared.k", .type = IR_T_FLOAT, .def = {2}, .lo = 0, .hi = 4};
    /* a: saturate(slope * k) + sample(rock, uv).x */
    int pa = ir_add_param(&a, &p), ta = ir_add_texture(&a, &tex);
    ir_ref sa = ir_op1(&a, IR_OP_SATURATE, ir_op2(&a, IR_OP_MUL, ir_input(&a, IR_IN_SLOPE),
                                                   ir_param_ref(&a, pa)));
    ir_ref xa = ir_swizzle(&a, ir_op2(&a, IR_OP_SAMPLE, ir_texture_ref(&a, ta),
                                      ir_input(&a, IR_IN_UV)), "x");
    ir_set_root(&a, "a.mask", ir_op2(&a, IR_OP_ADD, sa, xa));
    /* b: an unrelated painted mask first, then the same saturate */
    ir_add_painted(&b, "fields");
    ir_ref m = ir_painted_ref(&b, 0);
    int pb = ir_add_param(&b, &p);
    ir_ref sb = ir_op1(&b, IR_OP_SATURATE, ir_op2(&b, IR_OP_MUL, ir_param_ref(&b, pb),
                                                   ir_input(&b, IR_IN_SLOPE)));
    ir_set_root(&b, "b.mask", ir_op2(&b, IR_OP_MUL, sb, m));

    ir_import_map *ma = ir_import_begin(&dst, &a);
    ir_ref ra = ir_import(ma, ir_find_root(&a, "a.mask"));
    assert_true(ir_ref_eq(ir_import(ma, ir_find_root(&a, "a.mask")), ra));   /* memo */
    ir_import_end(ma);
    ir_import_map *mb = ir_import_begin(&dst, &b);
    ir_ref rb = ir_import(mb, ir_find_root(&b, "b.mask"));
    ir_import_end(mb);
    ir_set_root(&dst, "a.mask", ra);
    ir_set_root(&dst, "b.mask", rb);

    assert_int_equal(dst.nparams, 1);          /* re-interned by name */
    assert_int_equal(dst.ntextures, 1);
    assert_int_equal(dst.npainted, 1);
    /* the saturate is one node, the first operand of both sums */
    const ir_node *na = ir_get(&dst, ra), *nb = ir_get(&dst, rb);
    bool shared = false;
    for (int i = 0; i < 2; i++)
        for (int j = 0; j < 2; j++)
            shared = shared || (ir_ref_eq(na->arg[i], nb->arg[j]) &&
                                ir_get(&dst, na->arg[i])->op == IR_OP_SATURATE);
    assert_true(shared);
    assert_true(ir_validate(&dst, stderr));
    ir_free(&a);
    ir_free(&b);
    ir_free(&dst);
}

static void test_validator_catches_broken_ir(void **state)
{
    ir ir;
    ir_init(&ir);
    ir_ref h = ir_input(&ir, IR_IN_HEIGHT), s = ir_input(&ir, IR_IN_SLOPE);
    ir_ref sum = ir_op2(&ir, IR_OP_ADD, h, s);
    ir_set_root(&ir, "r", sum);
    assert_true(ir_validate(&ir, NULL));

    char *text = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&text, &len);
    ir.nodes[sum.id].type = IR_T_VEC3;           /* wrong type */
    assert_false(ir_validate(&ir, f));
    fflush(f);
    assert_non_null(strstr(text, "n->type == rule"));
    assert_non_null(strstr(text, "(node 3)"));
    assert_non_null(strstr(text, "ir_validate.c:"));
    ir.nodes[sum.id].type = IR_T_FLOAT;

    ir_ref t = ir.nodes[sum.id].arg[0];          /* non-canonical operands */
    ir.nodes[sum.id].arg[0] = ir.nodes[sum.id].arg[1];
    ir.nodes[sum.id].arg[1] = t;
    assert_false(ir_validate(&ir, NULL));
    ir.nodes[sum.id].arg[1] = ir.nodes[sum.id].arg[0];
    ir.nodes[sum.id].arg[0] = t;
    assert_true(ir_validate(&ir, NULL));

    ir.nodes[sum.id].arg[1].id = sum.id;         /* not topological */
    assert_false(ir_validate(&ir, NULL));
    ir.nodes[sum.id].arg[1] = s.id > h.id ? s : h;
    assert_true(ir_validate(&ir, NULL));

    ir.roots[0].ref.id = 99;                     /* root out of range */
    assert_false(ir_validate(&ir, NULL));
    ir.roots[0].ref = sum;
    fclose(f);
    free(text);
    ir_free(&ir);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_same_expression_same_ref),
        cmocka_unit_test(test_commutative_canonical),
        cmocka_unit_test(test_equal_operands_distinct),
        cmocka_unit_test(test_constants_bitwise),
        cmocka_unit_test(test_type_rules),
        cmocka_unit_test(test_op_table_rows),
        cmocka_unit_test(test_input_table_rows),
        cmocka_unit_test(test_cost),
        cmocka_unit_test(test_types),
        cmocka_unit_test(test_shape_builders),
        cmocka_unit_test(test_tables_and_roots),
        cmocka_unit_test(test_import_shares),
        cmocka_unit_test(test_validator_catches_broken_ir),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
