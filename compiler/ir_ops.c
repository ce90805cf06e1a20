/* ir_ops.c — the IR's types and its op and input tables: IR_OPS and
 * IR_INPUTS (ir.h) expanded
 * into rows, and the functions their rows name: each op's type rule,
 * double-precision evaluation and interval evaluation, written once, side
 * by side.  ir_eval, ir_interval, opt_fold, the GLSL emitter, the front
 * end's type checker and the GPU-agreement harness all read these tables,
 * so the back ends cannot drift apart.
 *
 * Semantics (the CPU reference; GLSL agrees up to float precision):
 *   min/max/clamp/saturate ignore a NaN operand (IEEE minNum/maxNum, what
 *     GPUs do), so saturate(NaN) = 0;  mix(a, b, t) = a + t * (b - a);
 *   smoothstep = t*t*(3-2t), t = clamp((x-e0)/(e1-e0), 0, 1);
 *   step(e, x) = x < e ? 0 : 1;  less(a, b) = a < b;  select(c, a, b) =
 *     c != 0 ? a : b (so a NaN condition selects a);
 *   fract(x) = x - floor(x);  mod(x, y) = x - y * floor(x / y);
 *   pow(x, y) = NaN where GLSL leaves it undefined (x < 0, or x = 0, y <= 0);
 *   normalize(0) = NaN (0/0);  sqrt of a negative = NaN.
 *
 * Intervals are sound for those double computations: monotone ops use
 * their endpoints (IEEE rounding is monotone, so no widening is needed
 * when the interval code performs the very same operations), non-monotone
 * ops their critical points, and results built from several roundings or
 * from libm are widened outwards by a few ulps.  An interval that may hold
 * a NaN is written [-inf, +inf] ("full"); every op whose result is NaN for
 * a NaN operand returns full when an operand is full.
 */
#include "ir.h"
#include "util.h"

#include <assert.h>
#include <float.h>
#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

/* ---- types (ir_type) ------------------------------------------------------------ */

int ir_type_width(ir_type t)
{
    switch (t) {
    case IR_T_FLOAT: return 1;
    case IR_T_VEC2:  return 2;
    case IR_T_VEC3:  return 3;
    case IR_T_VEC4:  return 4;
    default:         return 0;
    }
}

ir_type ir_type_vec(int width)
{
    static const ir_type t[] = {IR_T_ERROR, IR_T_FLOAT, IR_T_VEC2, IR_T_VEC3, IR_T_VEC4};
    return width >= 1 && width <= 4 ? t[width] : IR_T_ERROR;
}

static const char *const type_names[IR_T_COUNT] = {
    [IR_T_ERROR] = "error", [IR_T_FLOAT] = "float", [IR_T_VEC2] = "vec2",
    [IR_T_VEC3] = "vec3",   [IR_T_VEC4] = "vec4",   [IR_T_TEX] = "texture",
};

const char *ir_type_name(ir_type t)
{
    return (unsigned)t < IR_T_COUNT ? type_names[t] : "?";
}

ir_type ir_type_from_name(const char *s)
{
    for (int t = IR_T_FLOAT; t < IR_T_COUNT; t++)
        if (strcmp(s, type_names[t]) == 0)
            return (ir_type)t;
    return IR_T_ERROR;
}

/* ---- type rules --------------------------------------------------------- */

static bool is_num(ir_type t) { return t >= IR_T_FLOAT && t <= IR_T_VEC4; }

/* Componentwise: every operand of one numeric type. */
static ir_type ty_same(const ir_type *a, int n)
{
    for (int i = 0; i < n; i++)
        if (!is_num(a[i]) || a[i] != a[0])
            return IR_T_ERROR;
    return n > 0 ? a[0] : IR_T_ERROR;
}

static ir_type ty_leaf(const ir_type *a, int n) { return IR_T_ERROR; }

/* SPLAT's width is the node's own type; the rule checks the operand. */
static ir_type ty_splat(const ir_type *a, int n)
{
    return n == 1 && a[0] == IR_T_FLOAT ? IR_T_FLOAT : IR_T_ERROR;
}

/* SWIZZLE's width comes from its immediate; the rule checks the operand. */
static ir_type ty_swizzle(const ir_type *a, int n)
{
    return n == 1 && is_num(a[0]) ? a[0] : IR_T_ERROR;
}

static ir_type ty_construct(const ir_type *a, int n)
{
    int w = 0;
    for (int i = 0; i < n; i++) {
        if (!is_num(a[i]))
            return IR_T_ERROR;
        w += ir_type_width(a[i]);
    }
    return w >= 2 && w <= 4 ? ir_type_vec(w) : IR_T_ERROR;
}

static ir_type ty_sample(const ir_type *a, int n)
{
    return n == 2 && a[0] == IR_T_TEX && a[1] == IR_T_VEC2 ? IR_T_VEC4 : IR_T_ERROR;
}

static ir_type ty_sample_grad(const ir_type *a, int n)
{
    return n == 4 && a[0] == IR_T_TEX && a[1] == IR_T_VEC2 && a[2] == IR_T_VEC2 &&
                   a[3] == IR_T_VEC2
               ? IR_T_VEC4 : IR_T_ERROR;
}

static ir_type ty_dot(const ir_type *a, int n)
{
    return ty_same(a, n) != IR_T_ERROR ? IR_T_FLOAT : IR_T_ERROR;
}

static ir_type ty_length(const ir_type *a, int n)
{
    return n == 1 && is_num(a[0]) ? IR_T_FLOAT : IR_T_ERROR;
}

static ir_type ty_cross(const ir_type *a, int n)
{
    return n == 2 && a[0] == IR_T_VEC3 && a[1] == IR_T_VEC3 ? IR_T_VEC3 : IR_T_ERROR;
}

/* ---- intervals: helpers ------------------------------------------------- */

static const ir_iv FULL = {-INFINITY, INFINITY};

static bool iv_full(ir_iv x) { return x.lo == -INFINITY && x.hi == INFINITY; }

/* An interval from computed endpoints; a NaN endpoint means "anything". */
static ir_iv iv(double lo, double hi)
{
    if (isnan(lo) || isnan(hi))
        return FULL;
    return (ir_iv){lo, hi};
}

static ir_iv iv_point(double v) { return iv(v, v); }

static double down(double x, int ulps)
{
    while (ulps-- > 0)
        x = nextafter(x, -INFINITY);
    return x;
}

static double up(double x, int ulps)
{
    while (ulps-- > 0)
        x = nextafter(x, INFINITY);
    return x;
}

/* Outward by `ulps` ulps and by an absolute `abs` (rounding error bound). */
static ir_iv widen(ir_iv x, int ulps, double abs)
{
    if (iv_full(x))
        return x;
    return iv(down(x.lo - abs, ulps), up(x.hi + abs, ulps));
}

static ir_iv hull(ir_iv a, ir_iv b)
{
    return (ir_iv){fmin(a.lo, b.lo), fmax(a.hi, b.hi)};
}

static ir_iv meet(ir_iv a, ir_iv b)
{
    ir_iv r = {fmax(a.lo, b.lo), fmin(a.hi, b.hi)};
    assert(r.lo <= r.hi);   /* both enclose the same values */
    return r;
}

static double min4(double a, double b, double c, double d)
{
    return fmin(fmin(a, b), fmin(c, d));
}

static double max4(double a, double b, double c, double d)
{
    return fmax(fmax(a, b), fmax(c, d));
}

static bool any_nan4(double a, double b, double c, double d)
{
    return isnan(a) || isnan(b) || isnan(c) || isnan(d);
}

static double mag(ir_iv x) { return fmax(fabs(x.lo), fabs(x.hi)); }

/* The interval arithmetic the scalar ops share.  Each performs exactly the
 * rounding the evaluator performs, so endpoints need no widening. */
static ir_iv iv_add(ir_iv a, ir_iv b) { return iv(a.lo + b.lo, a.hi + b.hi); }
static ir_iv iv_sub(ir_iv a, ir_iv b) { return iv(a.lo - b.hi, a.hi - b.lo); }

static ir_iv iv_mul(ir_iv a, ir_iv b)
{
    double p0 = a.lo * b.lo, p1 = a.lo * b.hi, p2 = a.hi * b.lo, p3 = a.hi * b.hi;
    if (any_nan4(p0, p1, p2, p3))
        return FULL;                           /* 0 * inf */
    return iv(min4(p0, p1, p2, p3), max4(p0, p1, p2, p3));
}

static ir_iv iv_div(ir_iv a, ir_iv b)
{
    if (b.lo <= 0 && b.hi >= 0)
        return FULL;                           /* divisor may be 0 */
    double q0 = a.lo / b.lo, q1 = a.lo / b.hi, q2 = a.hi / b.lo, q3 = a.hi / b.hi;
    if (any_nan4(q0, q1, q2, q3))
        return FULL;                           /* inf / inf */
    return iv(min4(q0, q1, q2, q3), max4(q0, q1, q2, q3));
}

static ir_iv iv_sq(ir_iv a)
{
    if (a.lo >= 0)
        return iv(a.lo * a.lo, a.hi * a.hi);
    if (a.hi <= 0)
        return iv(a.hi * a.hi, a.lo * a.lo);
    return iv(0, fmax(a.lo * a.lo, a.hi * a.hi));
}

/* minNum/maxNum never produce NaN from one NaN operand. */
static ir_iv iv_min(ir_iv a, ir_iv b) { return (ir_iv){fmin(a.lo, b.lo), fmin(a.hi, b.hi)}; }
static ir_iv iv_max(ir_iv a, ir_iv b) { return (ir_iv){fmax(a.lo, b.lo), fmax(a.hi, b.hi)}; }

static ir_iv iv_clamp(ir_iv x, ir_iv lo, ir_iv hi) { return iv_min(iv_max(x, lo), hi); }

/* ---- scalar ops: value and interval, side by side ----------------------- */

static double e_add(const double *x) { return x[0] + x[1]; }
static ir_iv  i_add(const ir_iv *x)  { return iv_add(x[0], x[1]); }

static double e_sub(const double *x) { return x[0] - x[1]; }
static ir_iv  i_sub(const ir_iv *x)  { return iv_sub(x[0], x[1]); }

static double e_mul(const double *x) { return x[0] * x[1]; }
static ir_iv  i_mul(const ir_iv *x)  { return iv_mul(x[0], x[1]); }

static double e_div(const double *x) { return x[0] / x[1]; }
static ir_iv  i_div(const ir_iv *x)  { return iv_div(x[0], x[1]); }

static double e_neg(const double *x) { return -x[0]; }
static ir_iv  i_neg(const ir_iv *x)  { return iv(-x[0].hi, -x[0].lo); }

static double e_min(const double *x) { return fmin(x[0], x[1]); }
static ir_iv  i_min(const ir_iv *x)  { return iv_min(x[0], x[1]); }

static double e_max(const double *x) { return fmax(x[0], x[1]); }
static ir_iv  i_max(const ir_iv *x)  { return iv_max(x[0], x[1]); }

static double e_abs(const double *x) { return fabs(x[0]); }
static ir_iv  i_abs(const ir_iv *x)
{
    ir_iv a = x[0];
    if (a.lo >= 0)
        return a;
    if (a.hi <= 0)
        return iv(-a.hi, -a.lo);
    return iv(0, fmax(-a.lo, a.hi));           /* critical point 0 */
}

static double e_floor(const double *x) { return floor(x[0]); }
static ir_iv  i_floor(const ir_iv *x)  { return iv(floor(x[0].lo), floor(x[0].hi)); }

/* x - floor(x) is in [0, 1] (1 itself by rounding: fract(-1e-20) == 1). */
static double e_fract(const double *x) { return x[0] - floor(x[0]); }
static ir_iv  i_fract(const ir_iv *x)
{
    ir_iv a = x[0];
    if (isinf(a.lo) || isinf(a.hi))
        return FULL;                           /* fract(inf) = NaN */
    double f = floor(a.lo);
    if (f == floor(a.hi))
        return iv(a.lo - f, a.hi - f);         /* one integer step: monotone */
    return iv(0, 1);
}

static double e_mod(const double *x) { return x[0] - x[1] * floor(x[0] / x[1]); }
static ir_iv  i_mod(const ir_iv *x)
{
    ir_iv a = x[0], b = x[1];
    if (isinf(a.lo) || isinf(a.hi) || isinf(b.lo) || isinf(b.hi) || (b.lo <= 0 && b.hi >= 0))
        return FULL;
    if (b.lo == b.hi) {
        double k = floor(a.lo / b.lo);
        if (k == floor(a.hi / b.lo)) {         /* one period: x - c, monotone */
            double c = b.lo * k;
            return iv(a.lo - c, a.hi - c);
        }
    }
    /* Mathematically in [0, y) (y > 0) or (y, 0] (y < 0); x / y rounding to
     * the next integer can land a few ulps of |x| outside. */
    double err = 8 * DBL_EPSILON * fmax(mag(a), mag(b)) + 4 * DBL_TRUE_MIN;
    if (b.lo > 0)
        return iv(-err, b.hi + err);
    return iv(b.lo - err, err);
}

static double e_sqrt(const double *x) { return sqrt(x[0]); }
static ir_iv  i_sqrt(const ir_iv *x)
{
    if (x[0].lo < 0)
        return FULL;                           /* sqrt(negative) = NaN */
    return iv(sqrt(x[0].lo), sqrt(x[0].hi));   /* correctly rounded */
}

static double e_pow(const double *x)
{
    if (x[0] < 0 || (x[0] == 0 && x[1] <= 0))
        return NAN;                            /* undefined in GLSL */
    return pow(x[0], x[1]);
}
static ir_iv i_pow(const ir_iv *x)
{
    ir_iv a = x[0], b = x[1];
    if (a.lo < 0 || (a.lo == 0 && b.lo <= 0))
        return FULL;
    /* Monotone in x for fixed y and in y for fixed x: extremes at corners. */
    double c0 = pow(a.lo, b.lo), c1 = pow(a.lo, b.hi), c2 = pow(a.hi, b.lo), c3 = pow(a.hi, b.hi);
    if (a.lo == b.lo && a.hi == b.hi && a.lo == a.hi)
        return iv_point(c0);
    ir_iv r = widen(iv(min4(c0, c1, c2, c3), max4(c0, c1, c2, c3)), 2, 0); /* libm */
    return iv(fmax(r.lo, 0), r.hi);
}

static double e_exp2(const double *x) { return exp2(x[0]); }
static ir_iv  i_exp2(const ir_iv *x)
{
    if (x[0].lo == x[0].hi)
        return iv_point(exp2(x[0].lo));
    ir_iv r = widen(iv(exp2(x[0].lo), exp2(x[0].hi)), 2, 0);
    return iv(fmax(r.lo, 0), r.hi);
}

/* Bounds of sin(x + phase) over [lo, hi] (cos is phase pi/2). */
static ir_iv periodic_bounds(ir_iv a, double (*f)(double), double peak)
{
    if (isinf(a.lo) || isinf(a.hi))
        return FULL;                           /* sin(inf) = NaN */
    if (a.lo == a.hi)
        return iv_point(f(a.lo));
    if (a.hi - a.lo >= 2 * M_PI || fmax(fabs(a.lo), fabs(a.hi)) > 1e6)
        return iv(-1, 1);
    ir_iv r = hull(iv_point(f(a.lo)), iv_point(f(a.hi)));
    /* Critical points: maxima at peak + 2k pi, minima at peak + pi + 2k pi.
     * The test is generous (slack), which only costs tightness. */
    double slack = 1e-9;
    for (int m = 0; m < 2; m++) {
        double c = peak + m * M_PI;
        double k = ceil((a.lo - c) / (2 * M_PI) - slack);
        if (c + 2 * M_PI * k <= a.hi + slack) {
            if (m == 0)
                r.hi = 1;
            else
                r.lo = -1;
        }
    }
    r = widen(r, 2, 0);
    return iv(fmax(r.lo, -1), fmin(r.hi, 1));
}

/* log2: NaN below 0, -inf at 0 (the derivative pass's pow rule) */
static double e_log2(const double *x) { return log2(x[0]); }
static ir_iv  i_log2(const ir_iv *x)
{
    if (x[0].lo < 0)
        return FULL;
    if (x[0].lo == x[0].hi)
        return iv_point(log2(x[0].lo));
    return widen(iv(log2(x[0].lo), log2(x[0].hi)), 2, 0);   /* libm */
}

/* fwidth: lowering expands it (ir_footprint), so these are never read;
 * what they say is still true of any footprint: 0 for a value that does
 * not move, within [0, inf] */
static double e_fwidth(const double *x) { (void)x; return 0.0; }
static ir_iv  i_fwidth(const ir_iv *x)  { (void)x; return iv(0, INFINITY); }

static double e_sin(const double *x) { return sin(x[0]); }
static ir_iv  i_sin(const ir_iv *x)  { return periodic_bounds(x[0], sin, M_PI / 2); }

static double e_cos(const double *x) { return cos(x[0]); }
static ir_iv  i_cos(const ir_iv *x)  { return periodic_bounds(x[0], cos, 0); }

static double e_mix(const double *x) { return x[0] + x[2] * (x[1] - x[0]); }
static ir_iv  i_mix(const ir_iv *x)
{
    ir_iv a = x[0], b = x[1], t = x[2];
    /* Plain interval arithmetic on a + t * (b - a): sound, exact for
     * constant a and b, loose when a varies (a appears twice). */
    ir_iv ia = iv_add(a, iv_mul(t, iv_sub(b, a)));
    if (iv_full(ia))
        return ia;
    /* mix is linear in each operand, so its extremes are at the corners of
     * the box; three roundings separate the computed values from it. */
    double lo = INFINITY, hi = -INFINITY;
    for (int k = 0; k < 8; k++) {
        double p[3] = {k & 1 ? a.hi : a.lo, k & 2 ? b.hi : b.lo, k & 4 ? t.hi : t.lo};
        double v = e_mix(p);
        if (isnan(v))
            return ia;
        lo = fmin(lo, v);
        hi = fmax(hi, v);
    }
    double err = 4 * DBL_EPSILON * (mag(a) + mag(t) * (mag(a) + mag(b))) + 4 * DBL_TRUE_MIN;
    ir_iv corners = widen(iv(lo, hi), 1, err);
    return meet(ia, corners);
}

static double e_clamp(const double *x) { return fmin(fmax(x[0], x[1]), x[2]); }
static ir_iv  i_clamp(const ir_iv *x)  { return iv_clamp(x[0], x[1], x[2]); }

static double e_saturate(const double *x) { return fmin(fmax(x[0], 0.0), 1.0); }
static ir_iv  i_saturate(const ir_iv *x)
{
    return iv_clamp(x[0], iv_point(0), iv_point(1));
}

static double e_step(const double *x) { return x[1] < x[0] ? 0.0 : 1.0; }
static ir_iv  i_step(const ir_iv *x)
{
    ir_iv e = x[0], v = x[1];
    if (v.hi < e.lo)
        return iv_point(0);
    if (v.lo >= e.hi)
        return iv_point(1);
    return iv(0, 1);
}

static double hermite(double t) { return t * t * (3.0 - 2.0 * t); }

static double e_smoothstep(const double *x)
{
    double t = fmin(fmax((x[2] - x[0]) / (x[1] - x[0]), 0.0), 1.0);
    return hermite(t);
}
static ir_iv i_smoothstep(const ir_iv *x)
{
    /* t by interval arithmetic (the same operations, so sound); a divisor
     * that may be 0 gives full, which the clamp turns into [0, 1]. */
    ir_iv t = iv_clamp(iv_div(iv_sub(x[2], x[0]), iv_sub(x[1], x[0])),
                       iv_point(0), iv_point(1));
    if (t.lo == t.hi)
        return iv_point(hermite(t.lo));
    /* The Hermite is increasing on [0, 1] and >= 0 there; the computed one
     * may differ by a few roundings of values <= 3. */
    ir_iv r = widen(iv(hermite(t.lo), hermite(t.hi)), 1, 8 * DBL_EPSILON);
    return iv(fmax(r.lo, 0), r.hi);
}

static double e_less(const double *x) { return x[0] < x[1] ? 1.0 : 0.0; }
static ir_iv  i_less(const ir_iv *x)
{
    if (x[0].hi < x[1].lo)
        return iv_point(1);
    if (x[0].lo >= x[1].hi)
        return iv_point(0);                    /* also when a NaN is possible */
    return iv(0, 1);
}

static double e_select(const double *x) { return x[0] != 0 ? x[1] : x[2]; }
static ir_iv  i_select(const ir_iv *x)
{
    ir_iv c = x[0];
    if (c.lo > 0 || c.hi < 0)
        return x[1];
    if (c.lo == 0 && c.hi == 0)
        return x[2];
    return hull(x[1], x[2]);                   /* a NaN condition selects a */
}

static void cw_eval(const ir_node *n, const ir_type *atype, const double *a, double out[4])
{
    const ir_opinfo *s = ir_opinfo_get((ir_op)n->op);
    for (int c = 0; c < ir_type_width((ir_type)n->type); c++) {
        double x[4];
        for (int i = 0; i < n->nargs; i++)
            x[i] = a[4 * i + c];
        out[c] = s->scalar_eval(x);
    }
}

static void cw_interval(const ir_node *n, const ir_type *atype, const ir_iv *a, ir_iv *out)
{
    const ir_opinfo *s = ir_opinfo_get((ir_op)n->op);
    bool nan_in_nan_out = s->flags & IR_NAN_PROPAGATES;
    for (int c = 0; c < ir_type_width((ir_type)n->type); c++) {
        ir_iv x[4];
        bool nan = false;
        for (int i = 0; i < n->nargs; i++) {
            x[i] = a[4 * i + c];
            nan = nan || iv_full(x[i]);
        }
        out[c] = nan && nan_in_nan_out ? FULL : s->scalar_interval(x);
    }
}

/* ---- shape ops ---------------------------------------------------------- */

static void e_splat(const ir_node *n, const ir_type *atype, const double *a, double out[4])
{
    for (int c = 0; c < ir_type_width((ir_type)n->type); c++)
        out[c] = a[0];
}
static void i_splat(const ir_node *n, const ir_type *atype, const ir_iv *a, ir_iv *out)
{
    for (int c = 0; c < ir_type_width((ir_type)n->type); c++)
        out[c] = a[0];
}

static void e_swizzle(const ir_node *n, const ir_type *atype, const double *a, double out[4])
{
    for (int c = 0; c < IR_SWZ_N(n->imm); c++)
        out[c] = a[IR_SWZ_C(n->imm, c)];
}
static void i_swizzle(const ir_node *n, const ir_type *atype, const ir_iv *a, ir_iv *out)
{
    for (int c = 0; c < IR_SWZ_N(n->imm); c++)
        out[c] = a[IR_SWZ_C(n->imm, c)];
}

static void e_construct(const ir_node *n, const ir_type *atype, const double *a, double out[4])
{
    int k = 0;
    for (int i = 0; i < n->nargs; i++)
        for (int c = 0; c < ir_type_width(atype[i]) && k < 4; c++)
            out[k++] = a[4 * i + c];
}
static void i_construct(const ir_node *n, const ir_type *atype, const ir_iv *a, ir_iv *out)
{
    int k = 0;
    for (int i = 0; i < n->nargs; i++)
        for (int c = 0; c < ir_type_width(atype[i]) && k < 4; c++)
            out[k++] = a[4 * i + c];
}

/* ---- vector ops --------------------------------------------------------- */

/* True if some component of some operand may be NaN: the vector ops then
 * give full everywhere (a NaN reaches every component of the result). */
static bool vec_nan(const ir_node *n, const ir_type *atype, const ir_iv *a, ir_iv *out)
{
    for (int i = 0; i < n->nargs; i++)
        for (int c = 0; c < ir_type_width(atype[i]); c++)
            if (iv_full(a[4 * i + c])) {
                for (int k = 0; k < 4; k++)
                    out[k] = FULL;
                return true;
            }
    return false;
}

static double dot_w(const double *a, const double *b, int w)
{
    double s = a[0] * b[0];
    for (int c = 1; c < w; c++)
        s += a[c] * b[c];
    return s;
}

/* Same operations as dot_w; squares when both operands are one node. */
static ir_iv dot_iv(const ir_iv *a, const ir_iv *b, int w, bool same)
{
    ir_iv s = same ? iv_sq(a[0]) : iv_mul(a[0], b[0]);
    for (int c = 1; c < w; c++)
        s = iv_add(s, same ? iv_sq(a[c]) : iv_mul(a[c], b[c]));
    return s;
}

static void e_dot(const ir_node *n, const ir_type *atype, const double *a, double out[4])
{
    out[0] = dot_w(a, a + 4, ir_type_width(atype[0]));
}
static void i_dot(const ir_node *n, const ir_type *atype, const ir_iv *a, ir_iv *out)
{
    if (vec_nan(n, atype, a, out))
        return;
    out[0] = dot_iv(a, a + 4, ir_type_width(atype[0]), ir_ref_eq(n->arg[0], n->arg[1]));
}

static void e_length(const ir_node *n, const ir_type *atype, const double *a, double out[4])
{
    out[0] = sqrt(dot_w(a, a, ir_type_width(atype[0])));
}
static void i_length(const ir_node *n, const ir_type *atype, const ir_iv *a, ir_iv *out)
{
    if (vec_nan(n, atype, a, out))
        return;
    ir_iv s = dot_iv(a, a, ir_type_width(atype[0]), true);
    out[0] = iv(sqrt(s.lo), sqrt(s.hi));
}

static void e_normalize(const ir_node *n, const ir_type *atype, const double *a, double out[4])
{
    int w = ir_type_width(atype[0]);
    double len = sqrt(dot_w(a, a, w));
    for (int c = 0; c < w; c++)
        out[c] = a[c] / len;
}

/* x / sqrt(x^2 + s): increasing in x, shrinking towards 0 as s grows. */
static double norm_g(double x, double s) { return x / sqrt(x * x + s); }

static void i_normalize(const ir_node *n, const ir_type *atype, const ir_iv *a, ir_iv *out)
{
    if (vec_nan(n, atype, a, out))
        return;
    int w = ir_type_width(atype[0]);
    ir_iv sq[4];
    double total_lo = 0;
    bool huge = false;
    for (int c = 0; c < w; c++) {
        sq[c] = iv_sq(a[c]);
        total_lo += sq[c].lo;
        huge = huge || mag(a[c]) > 1e150;
    }
    /* A zero vector is 0/0; tiny ones underflow to x/0, huge ones overflow
     * to inf/inf or x/inf: give up there. */
    if (total_lo < 1e-280 || huge) {
        for (int c = 0; c < 4; c++)
            out[c] = FULL;
        return;
    }
    for (int c = 0; c < w; c++) {
        ir_iv s = iv(0, 0);
        for (int k = 0; k < w; k++)
            if (k != c)
                s = iv_add(s, sq[k]);
        double hi = norm_g(a[c].hi, a[c].hi >= 0 ? s.lo : s.hi);
        double lo = norm_g(a[c].lo, a[c].lo >= 0 ? s.hi : s.lo);
        /* several roundings (the sum order differs from the evaluator's) */
        ir_iv r = iv(lo - 8 * DBL_EPSILON * fabs(lo), hi + 8 * DBL_EPSILON * fabs(hi));
        out[c] = widen(r, 1, 0);
    }
}

static void e_cross(const ir_node *n, const ir_type *atype, const double *a, double out[4])
{
    const double *x = a, *y = a + 4;
    out[0] = x[1] * y[2] - x[2] * y[1];
    out[1] = x[2] * y[0] - x[0] * y[2];
    out[2] = x[0] * y[1] - x[1] * y[0];
}
static void i_cross(const ir_node *n, const ir_type *atype, const ir_iv *a, ir_iv *out)
{
    if (vec_nan(n, atype, a, out))
        return;
    const ir_iv *x = a, *y = a + 4;
    out[0] = iv_sub(iv_mul(x[1], y[2]), iv_mul(x[2], y[1]));
    out[1] = iv_sub(iv_mul(x[2], y[0]), iv_mul(x[0], y[2]));
    out[2] = iv_sub(iv_mul(x[0], y[1]), iv_mul(x[1], y[0]));
}

/* ---- sampler names ------------------------------------------------------- */

static const char *const filter_names[] = {
#define X(id, name) name,
    IR_FILTERS(X)
#undef X
};
static const char *const wrap_names[] = {
#define X(id, name) name,
    IR_WRAPS(X)
#undef X
};
enum { NFILTERS = sizeof filter_names / sizeof *filter_names,
       NWRAPS = sizeof wrap_names / sizeof *wrap_names };

const char *ir_filter_name(ir_filter f) { return (unsigned)f < NFILTERS ? filter_names[f] : "?"; }
const char *ir_wrap_name(ir_wrap w) { return (unsigned)w < NWRAPS ? wrap_names[w] : "?"; }

int ir_wrap_index(int i, int n, ir_wrap w)
{
    switch (w) {
    case IR_WRAP_CLAMP:
        return i < 0 ? 0 : i >= n ? n - 1 : i;
    case IR_WRAP_MIRROR: {
        int m = ((i % (2 * n)) + 2 * n) % (2 * n);
        return m < n ? m : 2 * n - 1 - m;
    }
    default:
        return ((i % n) + n) % n;
    }
}

int ir_filter_by_name(const char *name)
{
    for (int i = 0; i < NFILTERS; i++)
        if (!strcmp(filter_names[i], name))
            return i;
    return -1;
}

int ir_wrap_by_name(const char *name)
{
    for (int i = 0; i < NWRAPS; i++)
        if (!strcmp(wrap_names[i], name))
            return i;
    return -1;
}

/* ---- the tables ---------------------------------------------------------- */

/* IR_OPS (ir.h) expanded into ir_opinfo rows.  The columns' shorthands: */
#define NOPORTS {0}
#define P1 {"x"}
#define P2 {"a", "b"}
#define PORTS(...) {__VA_ARGS__}
#define ENV NULL, NULL, NULL, NULL
#define CW(f) cw_eval, cw_interval, e_##f, i_##f
#define NODE(f) e_##f, i_##f, NULL, NULL
#define D(f)
#define D0

static const ir_opinfo op_table[IR_OP_COUNT] = {
#define X(id, name, nargs, flags, ports, glsl, type, sem, fin, fp32, cost, deriv) \
    [IR_OP_##id] = {name, ports, nargs, flags, glsl, type, sem, fin, IR_FP32_##fp32, cost \
                    /* new columns here; deriv: ir_derive_rules.c */},
    IR_OPS(X)
#undef X
};

const ir_opinfo *ir_opinfo_get(ir_op op)
{
    assert((unsigned)op < IR_OP_COUNT);
    return &op_table[op];
}

int ir_node_cost(const ir *ir, ir_ref r)
{
    const ir_node *n = ir_get(ir, r);
    int w = ir_type_width((ir_type)n->type);
    for (int i = 0; i < n->nargs; i++) {
        int aw = ir_type_width(ir_typeof(ir, n->arg[i]));
        w = aw > w ? aw : w;
    }
    return op_table[n->op].cost * w;
}

long ir_cost(const ir *ir, const ir_ref *roots, int nroots)
{
    /* Ids are topological: mark what the roots reach, top down. */
    bool *live = xcalloc(ir->nnodes, sizeof *live);
    for (int i = 0; i < nroots; i++)
        live[roots[i].id] = ir_ref_ok(roots[i]);
    long total = 0;
    for (uint32_t id = ir->nnodes; id-- > 1;) {
        if (!live[id])
            continue;
        const ir_node *n = &ir->nodes[id];
        for (int a = 0; a < n->nargs; a++)
            live[n->arg[a].id] = true;
        total += ir_node_cost(ir, (ir_ref){id});
    }
    free(live);
    return total;
}

/* The domains named by IR_INPUTS' domain column, per component. */
#define DOM_ALL    {{-INFINITY, INFINITY}, {-INFINITY, INFINITY}, {-INFINITY, INFINITY}}
#define DOM_UNIT   {{0, 1}, {0, 1}, {0, 1}}
#define DOM_SIGNED {{-1, 1}, {-1, 1}, {-1, 1}}
#define DOM_NORMAL {{-1, 1}, {0, 1}, {-1, 1}}   /* an up-facing unit normal */
#define DOM_DIST   {{0, INFINITY}}
#define IV(field) (long)offsetof(ir_ienv, field)
#define IV_NONE   -1L

static const ir_input_info input_table[IR_IN_COUNT] = {
#define X(id, name, type, glsl, key, ev, iv, domain, hoist, dglsl) \
    [IR_IN_##id] = {name, glsl, key, type, offsetof(ir_env, ev), iv, DOM_##domain, hoist, \
                    "in_" #ev, dglsl},
    IR_INPUTS(X)
#undef X
};

const ir_input_info *ir_input_get(ir_input_kind which)
{
    assert((unsigned)which < IR_IN_COUNT);
    return &input_table[which];
}

int ir_input_by_name(const char *name)
{
    for (int i = 0; i < IR_IN_COUNT; i++)
        if (!strcmp(input_table[i].name, name))
            return i;
    return -1;
}

double *ir_env_slot(ir_env *env, ir_input_kind which)
{
    return (double *)((char *)env + ir_input_get(which)->env_off);
}

ir_iv *ir_ienv_slot(ir_ienv *ienv, ir_input_kind which)
{
    long off = ir_input_get(which)->ienv_off;
    return off < 0 ? NULL : (ir_iv *)((char *)ienv + off);
}

void ir_ienv_domain(ir_ienv *ienv)
{
    for (int k = 0; k < IR_IN_COUNT; k++) {
        ir_iv *slot = ir_ienv_slot(ienv, (ir_input_kind)k);
        for (int c = 0; slot && c < ir_type_width(input_table[k].type); c++)
            slot[c] = input_table[k].domain[c];
    }
}

int ir_op_by_name(const char *name)
{
    for (int op = 0; op < IR_OP_COUNT; op++)
        if (op_table[op].name && strcmp(op_table[op].name, name) == 0)
            return op;
    return -1;
}
