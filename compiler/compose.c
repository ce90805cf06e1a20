/* compose.c — the compositor: one composite IR per material combination
 * (the layout: compose_layout.c; scheduling: compose_schedule.c; GLSL:
 * compose_glsl.c) and its GLSL, with every value scheduled into the region that needs it
 * (compiler/DESIGN.md §6, Andersson 2007 §5.3).
 *
 * Building: the combination's materials (top first) are imported into one
 * ir, so whatever two materials share — the terrain normal, a texture
 * sampled at the same uv — is one node; the compositor shader
 * (nodes/compositors.sg, `linear_alpha` by default) is inlined once per
 * layer with T (coverage left), m (the clamped mask) and h (the height):
 *
 *     T_0 = 1;  w_j, T_j+1 = compositor(T_j, m_j, h_j)
 *     composite.albedo = sum_j w_j * albedo_j     (same for the others)
 *
 * A normalised compositor (one with a `blend` output: nodes/height_softmax.sg)
 * adds blend_j in place of w_j and the sums are divided by sum_j blend_j at
 * the end (s_wsum in the GLSL); T still runs the alpha chain.
 *
 * The bottom layer's mask is 1: the analysis ends every combination at a
 * material that is opaque wherever the combination is used.
 *
 * Scheduling: a region tree mirrors the GLSL blocks,
 *
 *     main                        (root)
 *       G_0  if (T_0 > 0.0) {     mask, weight and T_next of layer 0
 *         W_0  if (w_0 > 0.0) {   its surface, S += w_0 * s_0
 *         G_1  if (T_1 > 0.0) {   layer 1 ...
 *
 * Each value is used at known regions (a mask in its G, a surface output in
 * its W, a T in its guard's parent); every other node is placed at the
 * lowest common ancestor of its users' regions, users before operands
 * (operands have smaller ids).  Emission walks the tree and, on entering a
 * region, emits the values placed there in id order; the emitter's scopes
 * make sure a value emitted inside a block is not reused outside it.
 * Lazy branches (below) add a child region per skippable operand side of
 * a mix/select/mul, emitted just before that node.  So
 * the terrain normal that two masks need sits in the outer guard, while a
 * texture only one surface reads stays inside that surface's `if`.
 *
 * Example (grass below cliff): the composite of [cliff, grass] reads
 *     float v4 = ...cliff mask...;            // G_0 (T_0 = 1: a plain block)
 *     if (v4 > 0.0) { v9 = texture(u_texa_0, vec3(..., 1.0)); s_albedo += v4 * v9.rgb; }
 *     float v5 = 1.0 - v4;
 *     if (v5 > 0.0) { ...grass surface...; s_albedo += v5 * ...; }
 */
#include "compose_internal.h"

#include <assert.h>
#include <float.h>
#include <stdlib.h>
#include <string.h>

#include "abi.h"
#include "sg_internal.h"
#include "util.h"

/* ---- building the composite IR -------------------------------------------- */

static void set_root(ir *ir, int layer, const char *what, ir_ref r)
{
    char name[64];
    if (layer < 0)
        snprintf(name, sizeof name, "composite.%s", what);
    else
        snprintf(name, sizeof name, "layer%d.%s", layer, what);
    if (ir_ref_ok(r))
        ir_set_root(ir, name, r);
}

static ir_ref get_root(const ir *ir, int layer, const char *what)
{
    char name[64];
    snprintf(name, sizeof name, "layer%d.%s", layer, what);
    return ir_find_root(ir, name);
}

/* w = T * m, T_next = T - w: the linear alpha compositor, used when no
 * program holds a compositor shader (tests building IR directly). */
static void builtin_alpha(ir *ir, ir_ref T, ir_ref m, ir_ref *w, ir_ref *T_next)
{
    *w = ir_op2(ir, IR_OP_MUL, T, m);
    *T_next = ir_op2(ir, IR_OP_SUB, T, *w);
}

/* Whether shader `name` of prog has an input port `port`. */
static bool has_input(const sg_program *prog, const char *name, const char *port)
{
    int si = sg_shader_find(prog, name);
    if (si < 0)
        return false;
    const sg_shader *s = prog->shaders[si];
    for (int i = 0; i < s->nins; i++)
        if (strcmp(s->ins[i].name, port) == 0)
            return true;
    return false;
}

/* Whether shader `name` of prog has an output port `port`. */
static bool has_output(const sg_program *prog, const char *name, const char *port)
{
    int si = sg_shader_find(prog, name);
    if (si < 0)
        return false;
    const sg_shader *s = prog->shaders[si];
    for (int i = 0; i < s->nouts; i++)
        if (strcmp(s->outs[i].name, port) == 0)
            return true;
    return false;
}

bool splat_compositor_normalised(const sg_program *prog, const char *name)
{
    return prog && has_output(prog, name ? name : "linear_alpha", "blend");
}

/* The compositor inlined for one layer: T, m, h, and the material's index
 * as `id` where the compositor declares that port (a per-material seed:
 * nodes/stochastic.sg).  A normalised compositor's `blend` output goes to
 * *blend (else IR_NONE). */
static bool lower_compositor(const splat_layout *L, ir *ir, ir_ref T, ir_ref m,
                             ir_ref h, int material, ir_ref *w, ir_ref *T_next,
                             ir_ref *blend, sg_diags *d)
{
    *blend = IR_NONE;
    if (!L->prog) {
        builtin_alpha(ir, T, m, w, T_next);
        return true;
    }
    static const char *const in_names[] = {"T", "m", "h", "id"};
    static const char *const out_names[] = {"weight", "T_next", "blend"};
    ir_ref in_vals[4] = {T, m, h, ir_constf(ir, material)};
    ir_ref outs[3];
    const char *name = L->compositor ? L->compositor : "linear_alpha";
    int nin = has_input(L->prog, name, "id") ? 4 : 3;
    int nout = splat_compositor_normalised(L->prog, name) ? 3 : 2;
    if (!sg_lower_shader(L->prog, name, ir, in_names, in_vals, nin, out_names,
                         outs, nout, d))
        return false;
    *w = outs[0];
    *T_next = outs[1];
    if (nout == 3)
        *blend = outs[2];
    return true;
}

/* Bounds of the compositor's output `out` (0 weight, 1 T_next) for m = m
 * and T, h given as intervals (a point where lo == hi), every other input
 * over its domain: the shader lowered, folded, and interval-evaluated. */
static bool compositor_bounds(sg_program *prog, const char *name, int out, double m,
                              ir_iv T, ir_iv h, ir_iv *b, sg_diags *d)
{
    static const char *const in_names[] = {"T", "m", "h"};
    static const char *const out_names[] = {"weight", "T_next", "blend"};
    ir ir;
    ir_init(&ir);
    ir_param pt = {.name = "T", .type = IR_T_FLOAT, .def = {T.lo}, .lo = T.lo, .hi = T.hi};
    ir_param ph = {.name = "h", .type = IR_T_FLOAT, .def = {h.lo}, .lo = h.lo, .hi = h.hi};
    ir_ref in[3] = {T.lo == T.hi ? ir_constf(&ir, T.lo) : ir_param_ref(&ir, ir_add_param(&ir, &pt)),
                    ir_constf(&ir, m),
                    h.lo == h.hi ? ir_constf(&ir, h.lo) : ir_param_ref(&ir, ir_add_param(&ir, &ph))};
    ir_ref outs[3];
    bool ok = sg_lower_shader(prog, name, &ir, in_names, in, 3, out_names, outs, out + 1, d);
    if (ok) {
        ir_set_root(&ir, "checked", outs[out]);
        ir_optimize(&ir, NULL);
        ir_ienv env;
        memset(&env, 0, sizeof env);
        ir_ienv_domain(&env);
        ir_iv v[4];
        ir_interval(&ir, ir_find_root(&ir, "checked"), &env, v);
        *b = v[0];
    }
    ir_free(&ir);
    return ok;
}

/* The compositor's soundness contract (compiler/DESIGN.md §6), which the analysis and
 * the front-to-back loop rely on: its weight is 0 where m = 0 and its
 * T_next is 0 where m = 1, for every T in [0, 1]; a normalised
 * compositor's blend is 0 where m = 0 too.  Checked with the
 * interval evaluator: first over the whole box (T and h in [0, 1], every
 * other input over its domain), which proves most compositors (bounds
 * within DBL_MIN of 0 count as 0: the evaluator's outward rounding of an
 * exact 0); where it cannot, at T = 1/8 … 1 and h = 0, 1/2, 1, an error if
 * the bounds there exclude 0, i.e. the contract is broken for every value
 * of the other inputs.  Interval slack alone (a correlated expression like
 * T - T * pow(1, e)) is never an error. */
bool splat_compositor_check(sg_program *prog, const char *name, sg_loc at, sg_diags *d)
{
    static const char *const what[] = {"weight", "T_next", "blend"};
    const ir_iv unit = {0, 1};
    int nout = splat_compositor_normalised(prog, name) ? 3 : 2;
    for (int out = 0; out < nout; out++) {
        int m = out == 1;   /* weight and blend at m = 0, T_next at m = 1 */
        ir_iv b;
        if (!compositor_bounds(prog, name, out, m, unit, unit, &b, d))
            return false;
        if (b.lo >= -DBL_MIN && b.hi <= DBL_MIN)
            continue;                                   /* proved */
        for (int k = 1; k <= 8; k++)
            for (int j = 0; j <= 2; j++) {
                ir_iv T = {k / 8.0, k / 8.0}, h = {j / 2.0, j / 2.0};
                if (!compositor_bounds(prog, name, out, m, T, h, &b, d))
                    return false;
                if (b.lo > DBL_MIN || b.hi < -DBL_MIN) {
                    sg_error(d, at, SG_E_COMPOSITOR_CONTRACT, name, what[out], m, T.lo,
                             h.lo, b.lo, b.hi);
                    return false;
                }
            }
    }
    return true;
}

static void collect_used(const splat_layout *L, splat_composite *c, sg_diags *d)
{
    const ir *ir = &c->ir;
    bool *tex = xcalloc((size_t)L->ntextures, sizeof *tex);
    bool *par = xcalloc((size_t)L->nparams, sizeof *par);
    for (uint32_t i = 1; i < ir->nnodes; i++) {
        const ir_node *n = &ir->nodes[i];
        if (n->op == IR_OP_TEXTURE) {
            int t = splat_layout_texture(L, &ir->textures[n->imm]);
            assert(t >= 0 && "composite texture missing from the layout");
            tex[t] = true;
        } else if (n->op == IR_OP_PARAM) {
            for (int p = 0; p < L->src->nparams; p++)
                if (strcmp(L->src->params[p].name, ir->params[n->imm].name) == 0)
                    par[p] = true;
        } else if (n->op == IR_OP_PAINTED) {
            bool found = false, across;
            for (int p = 0; p < L->npainted; p++)
                found |= strcmp(L->painted[p], ir->painted[n->imm].name) == 0;
            found |= compose_layout_vector(L, ir->painted[n->imm].name, &across) >= 0;
            if (!found)
                sg_error(d, (sg_loc){0}, SG_E_UNDECLARED, "unknown painted mask");
        }
    }
    c->textures = xcalloc((size_t)L->ntextures, sizeof *c->textures);
    for (int t = 0; t < L->ntextures; t++)
        if (tex[t])
            c->textures[c->ntextures++] = t;
    c->params = xcalloc((size_t)L->nparams, sizeof *c->params);
    for (int p = 0; p < L->nparams; p++)
        if (par[p])
            c->params[c->nparams++] = p;
    free(tex);
    free(par);
}

static const char *const layer_fields[] = {"T", "mask", "weight", "T_next", "view_mask"};

/* The layers' values, found by their root names ("layer<j>.T" …). */
void compose_layers_from_roots(const ir *ir, splat_layer *layers, int n)
{
    for (int j = 0; j < n; j++) {
        splat_layer *l = &layers[j];
        l->T = get_root(ir, j, "T");
        l->mask = get_root(ir, j, "mask");
        l->weight = get_root(ir, j, "weight");
        l->T_next = get_root(ir, j, "T_next");
        l->view_mask = get_root(ir, j, "view_mask");
        l->out[SG_OUT_MASK] = l->mask;
        for (int o = 1; o < SG_OUT_COUNT; o++)
            l->out[o] = get_root(ir, j, sg_output_names[o]);
    }
}

bool splat_compose(const splat_layout *L, const splat_compose_desc *desc,
                   splat_composite *c, sg_diags *d)
{
    memset(c, 0, sizeof *c);
    ir_init(&c->ir);
    int n = desc->nmaterials;
    assert(n >= 1 && (!desc->reference || n == 1));
    c->reference = desc->reference;
    c->nlayers = n;
    c->layers = xcalloc((size_t)n, sizeof *c->layers);

    ir *dst = &c->ir;
    int errors = d->nerrors;
    ir_import_map *map = ir_import_begin(dst, L->src);
    ir_ref one = ir_constf(dst, 1.0);
    ir_ref T = one;
    ir_ref acc[SG_OUT_COUNT] = {{0}};
    ir_ref wsum = IR_NONE;        /* normalised compositor: sum of the blends */
    for (int j = 0; j < n; j++) {
        int k = desc->materials[j];
        assert(k >= 0 && k < L->nmaterials);
        ir_ref s[SG_OUT_COUNT];
        for (int o = 0; o < SG_OUT_COUNT; o++) {
            char name[512];
            snprintf(name, sizeof name, "%s.%s", L->materials[k], sg_output_names[o]);
            ir_ref r = ir_find_root(L->src, name);
            if (!ir_ref_ok(r)) {
                sg_error(d, (sg_loc){0}, SG_E_INTERNAL, "material output not lowered");
                ir_import_end(map);
                splat_composite_free(c);
                return false;
            }
            s[o] = ir_import(map, r);
        }
        ir_ref view_mask = k == 0 ? one : ir_op1(dst, IR_OP_SATURATE, s[SG_OUT_MASK]);
        bool bottom = desc->reference ? k == 0 : j == n - 1;
        ir_ref m = bottom ? one : view_mask;
        ir_ref w, T_next = IR_NONE, blend = IR_NONE;
        if (desc->reference) {
            w = m;
        } else {
            if (!lower_compositor(L, dst, T, m, s[SG_OUT_HEIGHT], k, &w, &T_next, &blend, d))
                break;
            if (j == n - 1)
                T_next = IR_NONE;  /* nothing below the bottom layer */
            if (ir_ref_ok(blend)) {
                /* normalised: the layer adds blend * s, divided by the
                 * sum of the blends at the end */
                w = blend;
                wsum = ir_ref_ok(wsum) ? ir_op2(dst, IR_OP_ADD, wsum, w) : w;
            }
        }
        ir_ref f[] = {T, m, w, T_next, view_mask};
        for (int i = 0; i < 5; i++)
            set_root(dst, j, layer_fields[i], f[i]);
        for (int o = 1; o < SG_OUT_COUNT; o++) {
            set_root(dst, j, sg_output_names[o], s[o]);
            ir_ref ws = ir_splat(dst, w, ir_typeof(dst, s[o]));
            ir_ref term = ir_op2(dst, IR_OP_MUL, ws, s[o]);
            acc[o] = ir_ref_ok(acc[o]) ? ir_op2(dst, IR_OP_ADD, acc[o], term) : term;
        }
        T = T_next;
    }
    ir_import_end(map);
    if (d->nerrors > errors) {
        splat_composite_free(c);
        return false;
    }
    if (ir_ref_ok(wsum)) {
        set_root(dst, -1, "wsum", wsum);
        for (int o = 1; o < SG_OUT_COUNT; o++)
            acc[o] = ir_op2(dst, IR_OP_DIV, acc[o], ir_splat(dst, wsum, ir_typeof(dst, acc[o])));
    }
    for (int o = 1; o < SG_OUT_COUNT; o++)
        set_root(dst, -1, sg_output_names[o], acc[o]);

    ir_optimize(dst, NULL);

    for (int j = 0; j < n; j++)
        c->layers[j].material = desc->materials[j];
    compose_layers_from_roots(dst, c->layers, n);
    collect_used(L, c, d);
    if (d->nerrors > errors) {
        splat_composite_free(c);
        return false;
    }
    return true;
}

void splat_composite_free(splat_composite *c)
{
    ir_free(&c->ir);
    free(c->layers);
    free(c->textures);
    free(c->params);
    memset(c, 0, sizeof *c);
}

/* Whether `r` is view.shading_lod (or a splat of it). */
static bool is_shading_lod(const ir *ir, ir_ref r)
{
    const ir_node *n = ir_get(ir, r);
    if (n->op == IR_OP_SPLAT && n->nargs == 1)
        n = ir_get(ir, n->arg[0]);
    return n->op == IR_OP_INPUT && n->imm == IR_IN_SHADING_LOD;
}

/* ir_cost over the values a GPU computes (compose.h): a mix whose t, or a
 * select whose c, is view.shading_lod is its side for 0, at no cost (the
 * driver folds it once the constant is known). */
double splat_composite_cost(const splat_composite *c)
{
    const ir *ir = &c->ir;
    bool *live = xcalloc(ir->nnodes, sizeof *live);
    for (int i = 0; i < ir->nroots; i++)
        live[ir->roots[i].ref.id] = ir_ref_ok(ir->roots[i].ref);
    long total = 0;
    for (uint32_t id = ir->nnodes; id-- > 1;) {   /* ids are topological */
        if (!live[id])
            continue;
        const ir_node *n = &ir->nodes[id];
        if (n->op == IR_OP_MIX && is_shading_lod(ir, n->arg[2])) {
            live[n->arg[0].id] = true;   /* mix(a, b, 0) = a: folded, free */
            continue;
        }
        if (n->op == IR_OP_SELECT && is_shading_lod(ir, n->arg[0])) {
            live[n->arg[2].id] = true;   /* 0 != 0 ? a : b = b */
            continue;
        }
        for (int a = 0; a < n->nargs; a++)
            live[n->arg[a].id] = true;
        total += ir_node_cost(ir, (ir_ref){id});
    }
    free(live);
    return (double)total;
}



void splat_composite_refresh(const splat_layout *L, splat_composite *c, sg_diags *d)
{
    compose_layers_from_roots(&c->ir, c->layers, c->nlayers);
    free(c->textures);
    free(c->params);
    c->textures = c->params = NULL;
    c->ntextures = c->nparams = 0;
    collect_used(L, c, d);
}
