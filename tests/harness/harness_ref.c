/* harness_ref.c — the CPU reference of a root and its sensitivity to fp32
 * rounding (harness.h, harness_reference).
 *
 * How: the DAG under the root is walked in id order (ids are topological),
 * each node evaluated by ir_eval's own step (ir_eval_node: the op table's
 * eval functions of ir_ops.c, the leaves read from the environment; the
 * walk checks that it agrees with ir_eval).  The walk runs once exactly, then
 * `samples` times with every node's result moved by +-b, where b is the
 * fp32 error bound of that op at the exact operands (below); the spread is
 * the largest deviation of the root.  A discontinuity within rounding
 * distance shows as a jump, cancellation followed by amplification as a
 * large spread: both are ill-conditioned points that no fp32 evaluation can
 * be held to.
 *
 * Error bounds per op (the op table's fp32 column, IR_FP32_CLASSES in
 * ir.h, names each op's class), u = 2^-24 (fp32 unit roundoff); after the Vulkan
 * spec's "Precision and Operation of SPIR-V Instructions", generously:
 *   exact in fp32 (0):  neg abs floor min max clamp saturate step less
 *                       select splat swizzle construct; inputs, params,
 *                       painted (the harness passes them as fp32)
 *   const               u|v|        (the GLSL literal is rounded to fp32)
 *   add sub mul         u|r|        (correctly rounded; fma contraction
 *                                    moves a product by at most u|ab|)
 *   div sqrt            3u|r|       (2.5 ulp; sqrt via inversesqrt)
 *   fract               u           (x - floor(x) rounds only for x < 0)
 *   mod                 4u(|x|+|y|)   and ill-conditioned when x/y is within
 *                                     8u(1+|x/y|) of an integer (floor may flip)
 *   exp2                (3+2|x|)u|r|
 *   pow                 (8 + 16|y|(1+|log2 x|))u|r|  (exp2(y*log2(x)))
 *   sin cos             32u + 8u|x|  (absolute; 2^-19 near 0, range
 *                                     reduction error growing with |x|)
 *   mix                 2u(|a|+|b|)(1+|t|) + u|r|  (a+t(b-a) or a(1-t)+bt)
 *   smoothstep          1.5 e_t + 4u, e_t = (2u(|x|+|e0|) + u|e1-e0|)/|e1-e0|
 *   dot                 (n+1)u sum|a_i b_i|
 *   length              4u|r|
 *   normalize           6u per component
 *   cross               2u(|a_j b_k| + |a_k b_j|)
 *   sample              (undefined where uv is NaN, Inf or beyond 1e9)
 *                       0 with the default (constant) texture; with a
 *                       sampler step (2^-8 + 4u size (1 + max(|u|, |v|))):
 *                       8-bit sub-texel weights (lavapipe; Vulkan allows
 *                       4) and the texel coordinate's fp32 rounding, each
 *                       times the largest neighbouring-texel difference
 */
#include "harness.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define U (1.0 / 16777216.0)   /* 2^-24 */

/* splitmix64: the sign of sample s at node id, component c. */
static double sign_of(uint64_t seed, int s, uint32_t id, int c)
{
    if (s == 0)
        return 1.0;
    if (s == 1)
        return -1.0;
    uint64_t z = seed + 0x9e3779b97f4a7c15ull * ((uint64_t)s * 1000003u + id * 4u + (uint64_t)c + 1);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    z ^= z >> 31;
    return (z & 1) ? 1.0 : -1.0;
}

/* The fp32 error bound of node `id`'s component c (see the table above),
 * from exact operand values; sets *ill when rounding may flip a
 * discontinuity inside the op, *undef when GLSL leaves it undefined. */
static double bound(const ir *ir, uint32_t id, const ir_env *env,
                    const harness_ref_opts *o, const double (*v)[4], int c,
                    bool *ill, bool *undef)
{
    const ir_node *n = &ir->nodes[id];
    const double *a = n->nargs > 0 ? v[n->arg[0].id] : NULL;
    const double *b = n->nargs > 1 ? v[n->arg[1].id] : NULL;
    const double *t = n->nargs > 2 ? v[n->arg[2].id] : NULL;
    double r = fabs(v[id][c]);
    int w = n->nargs > 0 ? ir_type_width(ir_typeof(ir, n->arg[0])) : 0;
    /* No default: a class added to IR_FP32_CLASSES without a bound here is
     * a compile error (-Werror=switch), and every op row names a class. */
    switch (ir_opinfo_get((ir_op)n->op)->fp32) {
    case IR_FP32_LITERAL:
    case IR_FP32_ROUNDED:
        return U * r;
    case IR_FP32_ULP3:
        return 3 * U * r;
    case IR_FP32_FRACT:
        return U;
    case IR_FP32_MOD: {
        double x = a[c], y = b[c], q = x / y;
        double f = q - floor(q);
        double near = 8 * U * (1 + fabs(q));
        if (f < near || 1 - f < near)
            *ill = true;
        return 4 * U * (fabs(x) + fabs(y));
    }
    case IR_FP32_EXP2:
        return (3 + 2 * fabs(a[c])) * U * r;
    case IR_FP32_POW:
        if (a[c] < 0 || (a[c] == 0 && b[c] <= 0))
            *undef = true;
        return (8 + 16 * fabs(b[c]) * (1 + fabs(log2(fabs(a[c]) + 1e-300)))) * U * r;
    case IR_FP32_TRIG:
        return 32 * U + 8 * U * fabs(a[c]);
    case IR_FP32_MIX:
        return 2 * U * (fabs(a[c]) + fabs(b[c])) * (1 + fabs(t[c])) + U * r;
    case IR_FP32_CLAMP:
        if (b[c] > t[c])
            *undef = true;
        return 0;
    case IR_FP32_SMOOTHSTEP: {
        double e0 = a[c], e1 = b[c], x = t[c];
        if (e0 >= e1) {
            *undef = true;
            return 0;
        }
        double et = (2 * U * (fabs(x) + fabs(e0)) + U * fabs(e1 - e0)) / fabs(e1 - e0);
        return 1.5 * et + 4 * U;
    }
    case IR_FP32_DOT: {
        double s = 0;
        for (int i = 0; i < w; i++)
            s += fabs(a[i] * b[i]);
        return (w + 1) * U * s;
    }
    case IR_FP32_LENGTH:
        return 4 * U * r;
    case IR_FP32_NORMALIZE:
        return 6 * U;
    case IR_FP32_CROSS: {
        int j = (c + 1) % 3, k = (c + 2) % 3;
        return 2 * U * (fabs(a[j] * b[k]) + fabs(a[k] * b[j]));
    }
    case IR_FP32_SAMPLE:
        /* NaN, Inf or huge coordinates: which texel is read is undefined */
        if (!isfinite(b[0]) || !isfinite(b[1]) || fmax(fabs(b[0]), fabs(b[1])) > 1e9)
            *undef = true;
        if (!env->sample)
            return 0;
        return o->texel_step * (1.0 / 256 + 4 * U * o->texels *
                                (1 + fmax(fabs(b[0]), fabs(b[1]))));
    case IR_FP32_EXACT:
        return 0;
    case IR_FP32_COUNT:
        break;
    }
    abort();   /* not a class */
}

/* ---- the sampler's CPU twin -------------------------------------------- */

static const float *texel(const harness_image *im, int x, int y)
{
    x = ir_wrap_index(x, im->width, im->wrap);
    y = ir_wrap_index(y, im->height, im->wrap);
    return im->rgba + ((size_t)y * (size_t)im->width + (size_t)x) * 4;
}

void harness_image_sample(const harness_image *im, double u, double v, double rgba[4])
{
    if (!isfinite(u) || !isfinite(v) || fabs(u) > 1e9 || fabs(v) > 1e9) {
        for (int c = 0; c < 4; c++)     /* some texel, as a device would */
            rgba[c] = im->rgba[c];
        return;
    }
    double x = u * im->width, y = v * im->height;
    if (im->filter == IR_FILTER_NEAREST) {
        const float *t = texel(im, (int)floor(x), (int)floor(y));
        for (int c = 0; c < 4; c++)
            rgba[c] = t[c];
        return;
    }
    x -= 0.5;
    y -= 0.5;
    double fx = floor(x), fy = floor(y);
    double a = x - fx, b = y - fy;
    int i = (int)fx, j = (int)fy;
    const float *t00 = texel(im, i, j), *t10 = texel(im, i + 1, j);
    const float *t01 = texel(im, i, j + 1), *t11 = texel(im, i + 1, j + 1);
    for (int c = 0; c < 4; c++)
        rgba[c] = (1 - a) * (1 - b) * t00[c] + a * (1 - b) * t10[c] +
                  (1 - a) * b * t01[c] + a * b * t11[c];
}

void harness_sample_images(void *user, int texture, double u, double v, double rgba[4])
{
    harness_image_sample((const harness_image *)user + texture, u, v, rgba);
}

static bool same(double x, double y)
{
    return x == y || (isnan(x) && isnan(y));
}

/* Evaluate the nodes under the root (need[]) into vals, in id order.
 * Components with poison[id][c] & mask take the value `garbage` instead;
 * with bounds, every component moves by its bound times the sample's sign. */
static void walk(const ir *ir, uint32_t n, const uint8_t *need, const ir_env *env,
                 const uint8_t (*poison)[4], unsigned mask, double garbage,
                 const double (*bnd)[4], uint64_t seed, int sample, double (*vals)[4])
{
    for (uint32_t id = 1; id < n; id++) {
        if (!need[id])
            continue;
        ir_eval_node(ir, id, env, vals);
        int w = ir_type_width(ir_typeof(ir, (ir_ref){id}));
        for (int c = 0; c < w; c++) {
            if (poison[id][c] & mask)
                vals[id][c] = garbage;
            else if (bnd)
                vals[id][c] += sign_of(seed, sample, id, c) * bnd[id][c];
        }
    }
}

double harness_image_max_step(const harness_image *im)
{
    double m = 0;
    for (int y = 0; y < im->height; y++)
        for (int x = 0; x < im->width; x++) {
            const float *t = texel(im, x, y), *r = texel(im, x + 1, y),
                        *d = texel(im, x, y + 1);
            for (int c = 0; c < 4; c++)
                m = fmax(m, fmax(fabs((double)r[c] - t[c]), fabs((double)d[c] - t[c])));
        }
    return m;
}

void harness_reference(const ir *ir, ir_ref root, const ir_env *env,
                       const harness_ref_opts *opts, harness_refval *out)
{
    harness_ref_opts o = opts ? *opts : (harness_ref_opts){0};
    if (o.samples <= 0)
        o.samples = 16;
    if (o.texel_step <= 0)
        o.texel_step = 1;
    if (o.texels <= 0)
        o.texels = 4096;
    memset(out, 0, sizeof *out);
    for (int c = 0; c < 4; c++)
        out->spread[c] = INFINITY;      /* until shown otherwise */
    if (!ir_ref_ok(root))
        return;
    const uint32_t n = root.id + 1;
    const int rw = ir_type_width(ir_typeof(ir, root));
    double (*exact)[4] = calloc(n, sizeof *exact);
    double (*bnd)[4] = calloc(n, sizeof *bnd);
    double (*other)[4] = calloc(n, sizeof *other);
    uint8_t *need = calloc(n, 1);
    uint8_t (*poison)[4] = calloc(n, sizeof *poison);
    if (!exact || !bnd || !other || !need || !poison) {
        for (int c = 0; c < 4; c++)           /* no memory: compare nothing */
            out->flags[c] = HARNESS_REF_NONFINITE;
        goto done;
    }
    need[root.id] = 1;
    for (uint32_t id = root.id; id > 0; id--)
        if (need[id])
            for (int i = 0; i < ir->nodes[id].nargs; i++)
                need[ir->nodes[id].arg[i].id] = 1;

    /* Exact values, error bounds, and the nodes whose fp32 value is not
     * held to the reference ("poisoned"): NaN/Inf, out of comfortable fp32
     * range, or undefined in GLSL. */
    bool ill = false;
    unsigned kinds = 0;
    for (uint32_t id = 1; id < n; id++) {
        if (!need[id])
            continue;
        ir_eval_node(ir, id, env, exact);
        int w = ir_type_width(ir_typeof(ir, (ir_ref){id}));
        for (int c = 0; c < w; c++) {
            double x = exact[id][c];
            bool undef = false;
            if (!isfinite(x))
                poison[id][c] |= HARNESS_REF_NONFINITE;
            else if (fabs(x) > 1e30 || (x != 0 && fabs(x) < 1e-30))
                poison[id][c] |= HARNESS_REF_RANGE;
            bnd[id][c] = bound(ir, id, env, &o, (const double (*)[4])exact, c, &ill, &undef);
            if (undef)
                poison[id][c] |= HARNESS_REF_UNDEFINED;
            kinds |= poison[id][c];
        }
    }

    /* The walk must agree with ir_eval bit for bit (it mirrors its leaves). */
    double ref[4];
    ir_eval(ir, root, env, ref);
    for (int c = 0; c < 4; c++) {
        out->value[c] = ref[c];
        if (c < rw && !same(ref[c], exact[root.id][c]))
            out->flags[c] |= HARNESS_REF_MISMATCH;
        if (c < rw && !isfinite(ref[c]))
            out->flags[c] |= HARNESS_REF_NONFINITE;
    }

    /* A poisoned node matters to a component when replacing its value
     * changes it (a select that does not pick it, a step far from it: no). */
    static const double garbage[] = { NAN, INFINITY, -INFINITY, 0.0, 1.2345e7 };
    for (unsigned kind = 1; kind <= HARNESS_REF_UNDEFINED; kind <<= 1) {
        if (!(kinds & kind))
            continue;
        for (size_t g = 0; g < sizeof garbage / sizeof garbage[0]; g++) {
            walk(ir, n, need, env, (const uint8_t (*)[4])poison, kind, garbage[g],
                 NULL, 0, 0, other);
            for (int c = 0; c < rw; c++)
                if (!same(other[root.id][c], exact[root.id][c]))
                    out->flags[c] |= kind;
        }
    }

    if (ill)
        goto done;
    for (int c = 0; c < rw; c++)
        out->spread[c] = out->flags[c] ? INFINITY : 0.0;
    for (int s = 0; s < o.samples; s++) {
        /* poisoned nodes that do not matter keep their exact values */
        walk(ir, n, need, env, (const uint8_t (*)[4])poison, 0, 0.0,
             (const double (*)[4])bnd, o.seed, s, other);
        for (int c = 0; c < rw; c++) {
            double d = fabs(other[root.id][c] - exact[root.id][c]);
            if (isnan(d))
                d = INFINITY;
            if (d > out->spread[c])
                out->spread[c] = d;
        }
    }
done:
    free(exact);
    free(bnd);
    free(other);
    free(need);
    free(poison);
}
