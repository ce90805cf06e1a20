/* lint.c — warnings about graphs that build but cannot be what was meant,
 * from the front end's facts and the interval analysis's sound bounds
 * (ir_interval.c):
 *
 *   - a material's mask whose bounds leave [0, 1] (it is clamped there,
 *     so `out mask = terrain.height` covers everything above 1 m), and
 *     which a point of the region, found by ir_eval, confirms (the bounds
 *     of overlay's formula are wider than its values);
 *   - an output that can be NaN or infinite: the first op, in the
 *     output's graph, whose bounds are unbounded although its operands'
 *     are not (a division by a range holding 0, a sqrt of a negative…);
 *   - a node whose constant lo/hi (ramp, remap, slope_ramp …: inputs
 *     `lo`/`hi` or `in_lo`/`in_hi`; smoothstep's e0/e1; clamp's lo/hi)
 *     has lo >= hi.
 *
 * Bounds are over a region: the scene's terrain when building, else every
 * input's domain (IR_INPUTS).  The NaN search clamps inputs to
 * +-1e7 first, so an unbounded input alone (terrain.height with no
 * terrain) is not taken for a NaN.  Warnings only: the input is accepted.
 *
 * Example: `out mask = terrain.height` over a 0-500 m terrain warns
 *   scene.sg:7:9: warning: the mask of material 'm' takes values in
 *   [0, 500], outside [0, 1]: … */
#include "sg_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define LINT_FAR 1e7    /* the NaN search's stand-in for an unbounded input */

static int root_of(const ir *ir, const char *material, const char *output)
{
    size_t n = strlen(material);
    for (int r = 0; r < ir->nroots; r++) {
        const char *name = ir->roots[r].name;
        if (!strncmp(name, material, n) && name[n] == '.' && !strcmp(name + n + 1, output))
            return r;
    }
    return -1;
}

static bool finite_iv(const ir_iv *v, int w)
{
    for (int c = 0; c < w; c++)
        if (!isfinite(v[c].lo) || !isfinite(v[c].hi))
            return false;
    return true;
}

static int width_of(const ir_node *n)
{
    int w = ir_type_width((ir_type)n->type);
    return w < 1 ? 1 : w;
}

/* ---- witnesses: the bounds are sound but may be wide (overlay's formula
 * reads its operands twice), so a mask warning needs a point whose value
 * really lies outside [0, 1]: ir_eval at pseudo-random points of the
 * region, textures and painted masks random in [0, 1], params in their
 * range.  A fixed seed: the same warnings every run. */

typedef struct witness_rng { uint64_t s; } witness_rng;

static double rnd(witness_rng *r)
{
    r->s = r->s * 6364136223846793005ull + 1442695040888963407ull;
    return (double)(r->s >> 11) / 9007199254740992.0;
}

static double in_iv(witness_rng *r, ir_iv v)
{
    double lo = fmax(v.lo, -LINT_FAR), hi = fmin(v.hi, LINT_FAR);
    return lo >= hi ? lo : lo + (hi - lo) * rnd(r);
}

static void random_texel(void *user, int texture, double u, double v, double rgba[4])
{
    (void)texture; (void)u; (void)v;
    for (int c = 0; c < 4; c++)
        rgba[c] = rnd(user);
}

/* A value of `root` outside [0, 1] at some point of `env`, if one is found
 * in `tries` points. */
static bool mask_witness(const ir *ir, ir_ref root, const ir_ienv *env, double *value)
{
    witness_rng rng = { 0x9e3779b97f4a7c15ull };
    double *params = calloc((size_t)ir->nparams * 4 + 4, sizeof *params);
    double painted[64];
    if (!params)
        abort();
    for (int t = 0; t < 4096; t++) {
        ir_env e;
        memset(&e, 0, sizeof e);
        for (int k = 0; k < IR_IN_COUNT; k++) {
            const ir_input_info *in = ir_input_get((ir_input_kind)k);
            const ir_iv *b = in->ienv_off < 0 ? in->domain
                           : (const ir_iv *)((const char *)env + in->ienv_off);
            double *slot = (double *)((char *)&e + in->env_off);
            for (int c = 0; c < ir_type_width(in->type); c++)
                slot[c] = in_iv(&rng, b[c]);
        }
        for (int i = 0; i < ir->nparams; i++)
            for (int c = 0; c < 4; c++)
                params[4 * i + c] = ir->params[i].lo < ir->params[i].hi
                                  ? in_iv(&rng, (ir_iv){ ir->params[i].lo, ir->params[i].hi })
                                  : ir->params[i].def[c];
        for (int i = 0; i < 64; i++)
            painted[i] = rnd(&rng);
        e.params = params;
        e.painted = painted;
        e.sample = random_texel;
        e.sample_user = &rng;
        double out[4];
        ir_eval(ir, root, &e, out);
        if (out[0] < -1e-6 || out[0] > 1 + 1e-6) {
            *value = out[0];
            free(params);
            return true;
        }
    }
    free(params);
    return false;
}

/* The first node under `root` (nodes come after their operands) that is
 * unbounded while its operands are bounded, or 0. */
static uint32_t nan_origin(const ir *ir, ir_ref root, ir_iv (*vals)[4])
{
    uint8_t *live = calloc(ir->nnodes + 1, 1);
    uint32_t *stack = calloc(ir->nnodes + 1, sizeof *stack);
    if (!live || !stack)
        abort();
    int sp = 0;
    live[root.id] = 1;
    stack[sp++] = root.id;
    while (sp) {
        const ir_node *u = &ir->nodes[stack[--sp]];
        for (int k = 0; k < u->nargs; k++)
            if (!live[u->arg[k].id]) {
                live[u->arg[k].id] = 1;
                stack[sp++] = u->arg[k].id;
            }
    }
    uint32_t found = 0;
    for (uint32_t i = 1; i < ir->nnodes && !found; i++) {
        const ir_node *n = &ir->nodes[i];
        if (!live[i] || n->nargs == 0 || ir_type_width((ir_type)n->type) < 1 ||
            finite_iv(vals[i], width_of(n)))
            continue;
        bool args_finite = true;
        for (int k = 0; k < n->nargs; k++) {
            const ir_node *a = ir_get(ir, n->arg[k]);
            if (ir_type_width((ir_type)a->type) >= 1 &&
                !finite_iv(vals[n->arg[k].id], width_of(a)))
                args_finite = false;
        }
        if (args_finite)
            found = i;
    }
    free(live);
    free(stack);
    return found;
}

static void lint_outputs(sg_program *p, const sg_shader *s, const ir_ienv *region,
                         sg_diags *d)
{
    ir ir;
    ir_init(&ir);
    sg_diags quiet;              /* lowering a checked program: no news */
    sg_diags_init(&quiet);
    if (!sg_lower_material(p, s->name, &ir, &quiet)) {
        sg_diags_free(&quiet);
        ir_free(&ir);
        return;
    }
    sg_diags_free(&quiet);
    ir_ienv env;
    if (region) {
        env = *region;
    } else {
        memset(&env, 0, sizeof env);
        ir_ienv_domain(&env);
    }
    ir_iv (*vals)[4] = calloc(ir.nnodes + 1, sizeof *vals);
    if (!vals)
        abort();
    ir_interval_all(&ir, &env, vals);
    /* the mask: its bounds over the region */
    for (int i = 0; i < s->nouts; i++) {
        const sg_port *o = &s->outs[i];
        if (o->output != SG_OUT_MASK)
            continue;
        int r = root_of(&ir, s->name, "mask");
        if (r < 0)
            break;
        ir_iv b = vals[ir.roots[r].ref.id][0];
        double w;
        if ((b.lo < -1e-6 || b.hi > 1 + 1e-6) && ir.npainted <= 64 &&
            mask_witness(&ir, ir.roots[r].ref, &env, &w))
            sg_warning_id(d, o->loc, SG_E_W_MASK_RANGE, "the mask of material '%s' takes values in [%g, %g] "
                       "(%g at one point), outside [0, 1]: it is clamped there (bring it "
                       "into [0, 1] with ramp, remap or saturate)", s->name, b.lo, b.hi, w);
    }
    /* NaN or infinity: over a finite stand-in for the region */
    for (int k = 0; k < IR_IN_COUNT; k++) {
        ir_iv *slot = ir_ienv_slot(&env, (ir_input_kind)k);
        for (int c = 0; slot && c < ir_type_width(ir_input_get((ir_input_kind)k)->type); c++) {
            slot[c].lo = fmax(slot[c].lo, -LINT_FAR);
            slot[c].hi = fmin(slot[c].hi, LINT_FAR);
        }
    }
    ir_interval_all(&ir, &env, vals);
    for (int i = 0; i < s->nouts; i++) {
        const sg_port *o = &s->outs[i];
        if (o->output < 0)
            continue;
        int r = root_of(&ir, s->name, o->name);
        if (r < 0)
            continue;
        uint32_t bad = nan_origin(&ir, ir.roots[r].ref, vals);
        if (!bad)
            continue;
        const ir_node *n = &ir.nodes[bad];
        const char *op = ir_opinfo_get((ir_op)n->op)->name;
        char ops[256] = "";
        size_t len = 0;
        for (int k = 0; k < n->nargs && len < sizeof ops; k++) {
            const ir_iv *a = vals[n->arg[k].id];
            len += (size_t)snprintf(ops + len, sizeof ops - len, "%s[%g, %g]", k ? ", " : "",
                                    a[0].lo, a[0].hi);
        }
        sg_warning_id(d, o->loc, SG_E_W_NAN, "output '%s' of material '%s' can be NaN or infinite: its "
                   "'%s' can make one from operands in %s", o->name, s->name,
                   op ? op : "internal op", ops);
    }
    free(vals);
    ir_free(&ir);
}

/* The constant a node gives input `port` of its callee: the binding's
 * number, else the callee's default number. */
static bool const_input(const sg_program *p, const sg_node *n, const char *port, double *v)
{
    for (int a = 0; a < n->nargs; a++)
        if (!strcmp(n->args[a].port, port)) {
            if (n->args[a].val.kind != SG_V_NUMBER)
                return false;
            *v = n->args[a].val.num[0];
            return true;
        }
    if (n->kind != SG_NODE_INSTANCE)
        return false;
    const sg_shader *c = p->shaders[n->shader];
    for (int k = 0; k < c->nins; k++)
        if (!strcmp(c->ins[k].name, port)) {
            if (!c->ins[k].has_value || c->ins[k].value.kind != SG_V_NUMBER)
                return false;
            *v = c->ins[k].value.num[0];
            return true;
        }
    return false;
}

static void lint_ranges(const sg_program *p, const sg_shader *s, sg_diags *d)
{
    static const char *const pairs[][2] = {
        { "lo", "hi" }, { "in_lo", "in_hi" }, { "e0", "e1" },
    };
    for (int i = 0; i < s->nnodes; i++) {
        const sg_node *n = &s->nodes[i];
        if (n->kind != SG_NODE_INSTANCE && n->kind != SG_NODE_OP)
            continue;
        for (size_t k = 0; k < sizeof pairs / sizeof *pairs; k++) {
            double lo, hi;
            if (!const_input(p, n, pairs[k][0], &lo) || !const_input(p, n, pairs[k][1], &hi))
                continue;
            if (lo >= hi)
                sg_warning_id(d, n->loc, SG_E_W_LO_HI, "'%s' (%s) has %s = %g >= %s = %g: no ramp between "
                           "them, at most a hard step (for a falling ramp, swap them and "
                           "take 1 - the result)", n->name, n->type, pairs[k][0], lo,
                           pairs[k][1], hi);
        }
    }
}

void sg_lint(sg_program *p, const ir_ienv *region, sg_diags *d)
{
    if (p->load_errors)
        return;
    for (int i = 0; i < p->nshaders; i++)
        lint_ranges(p, p->shaders[i], d);
    for (int i = 0; i < p->nmaterials; i++)
        lint_outputs(p, p->shaders[p->materials[i]], region, d);
}

/* ---- the node behind an IR fact ------------------------------------------- */

/* Does value v read terrain input `input` ("terrain.position")? */
static bool reads_input(const sg_value *v, int input)
{
    return v->kind == SG_V_PATH && v->ref == SG_REF_INPUT && v->index == input;
}

static bool find_reader(const sg_program *p, const sg_shader *s, const char *op, int input,
                        int depth, sg_loc *loc, char *what, size_t n)
{
    if (depth > SG_MAX_DEPTH)
        return false;
    for (int pass = 0; pass < 2; pass++)   /* op nodes here first, then inside instances */
        for (int i = 0; i < s->nnodes; i++) {
            const sg_node *nd = &s->nodes[i];
            if (pass == 0 && (!op || (nd->kind == SG_NODE_OP && !strcmp(nd->type, op)))) {
                for (int a = 0; a < nd->nargs; a++)
                    if (reads_input(&nd->args[a].val, input)) {
                        *loc = nd->loc;
                        snprintf(what, n, "node '%s' (%s)%s%s", nd->name, nd->type,
                                 s->is_material ? "" : " of shader ",
                                 s->is_material ? "" : s->name);
                        return true;
                    }
            } else if (pass == 1 && nd->kind == SG_NODE_INSTANCE &&
                       find_reader(p, p->shaders[nd->shader], op, input, depth + 1, loc,
                                   what, n)) {
                return true;
            }
        }
    return false;
}

bool sg_node_reading_input(const sg_program *p, const char *material, const char *op,
                           int input, sg_loc *loc, char *what, size_t n)
{
    int mi = sg_material_find(p, material);
    if (mi < 0)
        return false;
    const sg_shader *s = p->shaders[p->materials[mi]];
    return find_reader(p, s, op, input, 0, loc, what, n) ||
           (op && find_reader(p, s, NULL, input, 0, loc, what, n));
}
