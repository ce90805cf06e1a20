/* vector.c — the scene's vector shapes (seed 003 "vector texture maps as
 * masks", Unreal's landscape splines): `spline` roads and `polygon` decal
 * areas, read by materials as resolution-free masks.
 *
 * A spline is a centripetal Catmull-Rom curve through its points,
 * flattened here into segments within 5 cm of it; a polygon is its points closed into a loop.  A shape's
 * value at a point is its distance d (metres) to the nearest segment (0
 * inside a polygon); the mask is 1 for d <= half width (the core) and falls
 * to 0 over `falloff` metres (linear or smoothstep), and `across` is
 * d / (half width + falloff) clamped to [0, 1].
 *
 *   spline road { points = [0 0, 400 120, 900 100], width = 7, falloff = 3 }
 *   -> 4 to 256 segments a span; vector.road = 1 within 3.5 m of them, 0
 *      beyond 6.5 m
 *
 * The shader finds the segments near a pixel through a uniform grid: each
 * cell lists the segments whose distance to the cell is within their
 * shape's reach (at most SPLAT_MAX_VECTOR_CELL), so a pixel tests a few
 * segments.  A segment nearer than the reach to a point is listed in the
 * point's cell, so the grid's distance equals the true one wherever it is
 * below the reach, and both are past it elsewhere: the mask is exact.  A
 * polygon's inside test counts the crossings of the segment from the pixel
 * to the cell's reference point (whose inside bit the cell stores) with
 * the polygon's edges, all of which are listed where they cross the cell.
 *
 * The analysis bounds a shape over a rectangle (splat_vector_range) from
 * the same float segments the buffer holds, so combinations stay exact.
 */
#include "scene_load.h"
#include "util.h"

#include <assert.h>
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* ---- the buffer's words ------------------------------------------------ */

static float wf(const splat_vectors *v, size_t i)
{
    float f;
    memcpy(&f, &v->words[i], sizeof f);
    return f;
}

static uint32_t fw(float f)
{
    uint32_t u;
    memcpy(&u, &f, sizeof u);
    return u;
}

static size_t shape_at(const splat_vectors *v, int s)
{
    (void)v;
    return SPLAT_VEC_HEADER + (size_t)SPLAT_VEC_SHAPE * s;
}
static size_t cells_at(const splat_vectors *v) { return shape_at(v, (int)v->words[2]); }
static size_t entries_at(const splat_vectors *v)
{
    return cells_at(v) + (size_t)SPLAT_VEC_CELL * v->words[0] * v->words[1];
}
static size_t segs_at(const splat_vectors *v) { return entries_at(v) + v->words[4]; }

/* segment k: a, b (as the floats stored, in double) and its shape */
static int seg_get(const splat_vectors *v, uint32_t k, double a[2], double b[2])
{
    size_t o = segs_at(v) + (size_t)SPLAT_VEC_SEG * k;
    a[0] = wf(v, o), a[1] = wf(v, o + 1), b[0] = wf(v, o + 2), b[1] = wf(v, o + 3);
    return (int)v->words[o + 4];
}

void splat_vector_shape(const splat_vectors *v, int s, double *half_width, double *falloff,
                        int *profile, int *kind)
{
    size_t o = shape_at(v, s);
    *half_width = wf(v, o);
    *falloff = wf(v, o + 1);
    *profile = (int)(v->words[o + 2] & 255u);
    *kind = (int)(v->words[o + 2] >> 8);
}

/* ---- geometry ----------------------------------------------------------- */

static double seg_dist(const double p[2], const double a[2], const double b[2])
{
    double ab[2] = { b[0] - a[0], b[1] - a[1] }, ap[2] = { p[0] - a[0], p[1] - a[1] };
    double l2 = ab[0] * ab[0] + ab[1] * ab[1];
    double t = l2 > 0 ? (ap[0] * ab[0] + ap[1] * ab[1]) / l2 : 0;
    t = t < 0 ? 0 : t > 1 ? 1 : t;
    return hypot(ap[0] - t * ab[0], ap[1] - t * ab[1]);
}

/* Whether segment a-b meets the closed rectangle (Liang-Barsky). */
static bool seg_meets_rect(const double a[2], const double b[2], const double r[4])
{
    double t0 = 0, t1 = 1, d[2] = { b[0] - a[0], b[1] - a[1] };
    for (int k = 0; k < 2; k++) {
        double lo = r[k], hi = r[k + 2];
        if (d[k] == 0) {
            if (a[k] < lo || a[k] > hi) return false;
            continue;
        }
        double u = (lo - a[k]) / d[k], w = (hi - a[k]) / d[k];
        if (u > w) { double t = u; u = w; w = t; }
        if (u > t0) t0 = u;
        if (w < t1) t1 = w;
        if (t0 > t1) return false;
    }
    return true;
}

static double point_rect_dist(const double p[2], const double r[4])
{
    double dx = p[0] < r[0] ? r[0] - p[0] : p[0] > r[2] ? p[0] - r[2] : 0;
    double dz = p[1] < r[1] ? r[1] - p[1] : p[1] > r[3] ? p[1] - r[3] : 0;
    return hypot(dx, dz);
}

/* Distance from segment a-b to rectangle r (x0 z0 x1 z1). */
static double seg_rect_dist(const double a[2], const double b[2], const double r[4])
{
    if (seg_meets_rect(a, b, r)) return 0;
    double d = fmin(point_rect_dist(a, r), point_rect_dist(b, r));
    const double c[4][2] = { { r[0], r[1] }, { r[2], r[1] }, { r[0], r[3] }, { r[2], r[3] } };
    for (int k = 0; k < 4; k++)
        d = fmin(d, seg_dist(c[k], a, b));
    return d;
}

/* Even-odd: whether p is inside polygon s, from all of its segments
 * (half-open crossings of the ray towards +x). */
static bool inside_polygon(const splat_vectors *v, int s, const double p[2])
{
    bool in = false;
    uint32_t lo = v->shape_first[s], hi = v->shape_first[s + 1];
    for (uint32_t k = lo; k < hi; k++) {
        double a[2], b[2];
        seg_get(v, k, a, b);
        if ((a[1] > p[1]) != (b[1] > p[1])) {
            double x = a[0] + (p[1] - a[1]) * (b[0] - a[0]) / (b[1] - a[1]);
            if (x > p[0]) in = !in;
        }
    }
    return in;
}

double splat_vector_profile(const splat_vectors *v, int s, double d, bool across)
{
    double hw, f;
    int profile, kind;
    splat_vector_shape(v, s, &hw, &f, &profile, &kind);
    if (across)
        return fmin(fmax(d / fmax(hw + f, 1e-6), 0.0), 1.0);
    double t = f > 0 ? fmin(fmax((d - hw) / f, 0.0), 1.0) : (d > hw ? 1.0 : 0.0);
    if (profile == SPLAT_VEC_SMOOTHSTEP) t = t * t * (3 - 2 * t);
    return 1 - t;
}

double splat_vector_distance(const splat_vectors *v, int s, double x, double z)
{
    double p[2] = { x, z }, d = INFINITY;
    for (uint32_t k = v->shape_first[s]; k < v->shape_first[s + 1]; k++) {
        double a[2], b[2];
        seg_get(v, k, a, b);
        d = fmin(d, seg_dist(p, a, b));
    }
    double hw, f;
    int profile, kind;
    splat_vector_shape(v, s, &hw, &f, &profile, &kind);
    if (kind == SPLAT_VEC_POLYGON && inside_polygon(v, s, p)) return 0;
    return d;
}

/* The shader's evaluation (abi.c splat_vector_distance) in double: the
 * point's grid cell, its listed segments, the reference point's parity. */
double splat_vector_distance_grid(const splat_vectors *v, int s, double x, double z)
{
    uint32_t ncx = v->words[0], ncz = v->words[1];
    double o[2] = { wf(v, 5), wf(v, 6) }, c = wf(v, 7);
    double gx = floor((x - o[0]) / c), gz = floor((z - o[1]) / c);
    if (gx < 0 || gz < 0 || gx >= ncx || gz >= ncz) return 1e30;
    size_t cb = cells_at(v) + (size_t)SPLAT_VEC_CELL * ((size_t)gz * ncx + (size_t)gx);
    uint32_t first = v->words[cb], count = v->words[cb + 1];
    bool in = (v->words[cb + 2] >> s) & 1u;
    double r[2] = { wf(v, cb + 4), wf(v, cb + 5) }, p[2] = { x, z }, d = 1e30;
    for (uint32_t k = 0; k < count; k++) {
        double a[2], b[2];
        if (seg_get(v, v->words[entries_at(v) + first + k], a, b) != s) continue;
        d = fmin(d, seg_dist(p, a, b));
        double ab[2] = { b[0] - a[0], b[1] - a[1] }, pr[2] = { r[0] - p[0], r[1] - p[1] };
        double o1 = ab[0] * (p[1] - a[1]) - ab[1] * (p[0] - a[0]);
        double o2 = ab[0] * (r[1] - a[1]) - ab[1] * (r[0] - a[0]);
        double o3 = pr[0] * (a[1] - p[1]) - pr[1] * (a[0] - p[0]);
        double o4 = pr[0] * (b[1] - p[1]) - pr[1] * (b[0] - p[0]);
        if ((o1 > 0) != (o2 > 0) && (o3 > 0) != (o4 > 0)) in = !in;
    }
    double hw, f;
    int profile, kind;
    splat_vector_shape(v, s, &hw, &f, &profile, &kind);
    return kind == SPLAT_VEC_POLYGON && in ? 0 : d;
}

void splat_vector_range(const splat_vectors *v, int s, const double rect[4], double *dlo,
                        double *dhi)
{
    double lo = INFINITY, hi = INFINITY;
    const double c[4][2] = { { rect[0], rect[1] }, { rect[2], rect[1] },
                             { rect[0], rect[3] }, { rect[2], rect[3] } };
    bool meets = false;
    /* Only the segments the shader can see there: those listed in the
     * grid cells the rectangle (and a margin) overlaps.  Where none is,
     * the shader's distance is 1e30 at every point (and the true one past
     * the reach).  Elsewhere the shader's distance is the least over its
     * cell's list, at least `lo` below; it is the true distance wherever
     * that is within the reach, so `hi` bounds it where it matters (past
     * the reach the mask is 0 and across 1 either way). */
    uint32_t ncx = v->words[0], ncz = v->words[1];
    double o[2] = { wf(v, 5), wf(v, 6) }, cs = wf(v, 7), gm = 1e-3 * cs + v->margin;
    double gx0 = floor((rect[0] - gm - o[0]) / cs), gx1 = floor((rect[2] + gm - o[0]) / cs);
    double gz0 = floor((rect[1] - gm - o[1]) / cs), gz1 = floor((rect[3] + gm - o[1]) / cs);
    gx0 = fmax(gx0, 0), gz0 = fmax(gz0, 0), gx1 = fmin(gx1, ncx - 1.0), gz1 = fmin(gz1, ncz - 1.0);
    bool listed = false;
    for (double gz = gz0; gz <= gz1; gz++)
        for (double gx = gx0; gx <= gx1; gx++) {
            size_t cb = cells_at(v) + (size_t)SPLAT_VEC_CELL * ((size_t)gz * ncx + (size_t)gx);
            for (uint32_t e = 0; e < v->words[cb + 1]; e++) {
                uint32_t k = v->words[entries_at(v) + v->words[cb] + e];
                double a[2], b[2];
                if (seg_get(v, k, a, b) != s) continue;
                listed = true;
                double dr = seg_rect_dist(a, b, rect);
                meets |= dr == 0;
                lo = fmin(lo, dr);
                /* the distance to a segment is convex: its largest over
                 * the rectangle is at a corner; the shape's is at most
                 * the least of those */
                double far = 0;
                for (int q = 0; q < 4; q++)
                    far = fmax(far, seg_dist(c[q], a, b));
                hi = fmin(hi, far);
            }
        }
    double hw, f;
    int profile, kind;
    splat_vector_shape(v, s, &hw, &f, &profile, &kind);
    bool polygon_here = false;
    if (kind == SPLAT_VEC_POLYGON) {   /* a cell wholly inside lists no edge */
        for (double gz = gz0; gz <= gz1 && !polygon_here; gz++)
            for (double gx = gx0; gx <= gx1 && !polygon_here; gx++) {
                size_t cb = cells_at(v) + (size_t)SPLAT_VEC_CELL * ((size_t)gz * ncx + (size_t)gx);
                polygon_here = (v->words[cb + 2] >> s) & 1u;
            }
    }
    if (!listed && !polygon_here) {
        *dlo = *dhi = 1e30;
        return;
    }
    if (!listed) {   /* every overlapped cell inside the polygon, no edge near */
        *dlo = *dhi = 0;
        return;
    }
    /* the shader's fp32 position and arithmetic: a margin */
    double m = v->margin;
    bool wholly = false;
    if (kind == SPLAT_VEC_POLYGON) {
        int inside = 0;
        for (int q = 0; q < 4; q++)
            inside += inside_polygon(v, s, c[q]);
        /* wholly inside, and farther than the margin from every edge: the
         * shader's inside test holds at every pixel, its distance is 0 */
        wholly = inside == 4 && !meets && lo > m;
        if (inside > 0) lo = 0;
    }
    *dlo = fmax(lo - m, 0.0);
    *dhi = wholly ? 0.0 : hi + m;
}

/* ---- building ----------------------------------------------------------- */

/* A centripetal Catmull-Rom span (Barry-Goldman), from p1 (at knot t1)
 * to p2 (t2); knots spaced by the square root of the chord lengths, so
 * uneven point spacing neither loops nor overshoots. */
typedef struct span { double p[4][2], t[4]; } span;

static void span_at(const span *S, double t, double out[2])
{
    const double *t_ = S->t;
    for (int k = 0; k < 2; k++) {
        double a1 = ((t_[1] - t) * S->p[0][k] + (t - t_[0]) * S->p[1][k]) / (t_[1] - t_[0]);
        double a2 = ((t_[2] - t) * S->p[1][k] + (t - t_[1]) * S->p[2][k]) / (t_[2] - t_[1]);
        double a3 = ((t_[3] - t) * S->p[2][k] + (t - t_[2]) * S->p[3][k]) / (t_[3] - t_[2]);
        double b1 = ((t_[2] - t) * a1 + (t - t_[0]) * a2) / (t_[2] - t_[0]);
        double b2 = ((t_[3] - t) * a2 + (t - t_[1]) * a3) / (t_[3] - t_[1]);
        out[k] = ((t_[2] - t) * b1 + (t - t_[1]) * b2) / (t_[2] - t_[1]);
    }
}

typedef struct seglist { float (*xz)[4]; int *shape; size_t n, cap; } seglist;

static void seg_push(seglist *l, const double a[2], const double b[2], int s)
{
    if (l->n == l->cap) {
        l->cap = l->cap ? 2 * l->cap : 256;
        l->xz = xrealloc(l->xz, l->cap * sizeof *l->xz);
        l->shape = xrealloc(l->shape, l->cap * sizeof *l->shape);
    }
    l->xz[l->n][0] = (float)a[0], l->xz[l->n][1] = (float)a[1];
    l->xz[l->n][2] = (float)b[0], l->xz[l->n][3] = (float)b[1];
    l->shape[l->n++] = s;
}

/* Shape s's segments: each span of a spline cut in halves until the
 * chord's midpoint lies within FLAT_TOL metres of the curve's (at least 4
 * pieces, so an S-bend is seen; at most 256); a polygon's edges as they
 * are.  A span's missing neighbour is its end mirrored. */
#define FLAT_TOL 0.05

static void flatten_span(const span *S, double ta, double tb, const double a[2],
                         const double b[2], int depth, seglist *l, int s)
{
    double m[2], tm = 0.5 * (ta + tb);
    span_at(S, tm, m);
    double ab[2] = { b[0] - a[0], b[1] - a[1] }, len = hypot(ab[0], ab[1]);
    double dev = len > 0 ? fabs(ab[0] * (m[1] - a[1]) - ab[1] * (m[0] - a[0])) / len
                         : hypot(m[0] - a[0], m[1] - a[1]);
    if (depth >= 8 || (depth >= 2 && dev <= FLAT_TOL)) {
        seg_push(l, a, b, s);
        return;
    }
    flatten_span(S, ta, tm, a, m, depth + 1, l, s);
    flatten_span(S, tm, tb, m, b, depth + 1, l, s);
}

static void flatten_curve(const sg_scene_vector *sv, const double *P, int n, int s,
                          seglist *l)
{
    if (sv->kind == SPLAT_VEC_POLYGON) {
        for (int i = 0; i < n; i++)
            seg_push(l, &P[2 * i], &P[2 * ((i + 1) % n)], s);
        return;
    }
    for (int i = 0; i + 1 < n; i++) {
        const double *p1 = &P[2 * i], *p2 = &P[2 * (i + 1)];
        double len = hypot(p2[0] - p1[0], p2[1] - p1[1]);
        if (!(len > 0)) continue;   /* a repeated point: no span */
        span S;
        for (int k = 0; k < 2; k++) {
            S.p[1][k] = p1[k];
            S.p[2][k] = p2[k];
            S.p[0][k] = i > 0 ? P[2 * (i - 1) + k] : 2 * p1[k] - p2[k];
            S.p[3][k] = i + 2 < n ? P[2 * (i + 2) + k] : 2 * p2[k] - p1[k];
        }
        /* a neighbour on top of its point: mirror instead */
        if (!(hypot(S.p[0][0] - p1[0], S.p[0][1] - p1[1]) > 0))
            for (int k = 0; k < 2; k++) S.p[0][k] = 2 * p1[k] - p2[k];
        if (!(hypot(S.p[3][0] - p2[0], S.p[3][1] - p2[1]) > 0))
            for (int k = 0; k < 2; k++) S.p[3][k] = 2 * p2[k] - p1[k];
        S.t[0] = 0;
        for (int k = 1; k < 4; k++)
            S.t[k] = S.t[k - 1] + sqrt(hypot(S.p[k][0] - S.p[k - 1][0],
                                             S.p[k][1] - S.p[k - 1][1]));
        flatten_span(&S, S.t[1], S.t[2], p1, p2, 0, l, s);
    }
}

/* Each curve of the shape (each `points` of its block) on its own. */
static void flatten(const sg_scene_vector *sv, int s, seglist *l)
{
    for (int c = 0; c < sv->ncurves; c++) {
        int at = c ? sv->curve_end[c - 1] : 0;
        flatten_curve(sv, &sv->points[2 * at], sv->curve_end[c] - at, s, l);
    }
}

/* The grid's lists: count[i] and first[i] of each cell, the entries
 * (pass 2), for cell size c from origin o; returns the largest count,
 * its cell in *worst.  A segment is listed in every cell within its
 * shape's reach (plus the margins). */
static uint32_t bucket(const sg_scene *sc, const seglist *l, const double o[2], double c,
                       uint32_t ncx, uint32_t ncz, double margin, uint32_t *count,
                       uint32_t *first, uint32_t **entries, size_t *nentries, size_t *worst)
{
    size_t ncells = (size_t)ncx * ncz;
    double cm = 1e-3 * c + margin;   /* a pixel's cell may be its neighbour's */
    uint32_t most = 0;
    *entries = NULL;
    for (int pass = 0; pass < 2; pass++) {
        if (pass == 1) {
            size_t at = 0;
            for (size_t i = 0; i < ncells; i++) {
                first[i] = (uint32_t)at;
                at += count[i];
                count[i] = 0;
            }
            *nentries = at;
            *entries = xcalloc(at ? at : 1, sizeof **entries);
        } else
            memset(count, 0, ncells * sizeof *count);
        for (size_t k = 0; k < l->n; k++) {
            const sg_scene_vector *sv = &sc->vectors[l->shape[k]];
            double r = (sv->kind == SPLAT_VEC_SPLINE ? 0.5 * sv->width : 0) + sv->falloff;
            double a[2] = { l->xz[k][0], l->xz[k][1] }, b[2] = { l->xz[k][2], l->xz[k][3] };
            double x0 = floor((fmin(a[0], b[0]) - r - cm - o[0]) / c);
            double x1 = floor((fmax(a[0], b[0]) + r + cm - o[0]) / c);
            double z0 = floor((fmin(a[1], b[1]) - r - cm - o[1]) / c);
            double z1 = floor((fmax(a[1], b[1]) + r + cm - o[1]) / c);
            for (int gz = z0 < 0 ? 0 : (int)z0; gz <= z1 && gz < (int)ncz; gz++)
                for (int gx = x0 < 0 ? 0 : (int)x0; gx <= x1 && gx < (int)ncx; gx++) {
                    double rect[4] = { o[0] + gx * c - cm, o[1] + gz * c - cm,
                                       o[0] + (gx + 1) * c + cm, o[1] + (gz + 1) * c + cm };
                    if (seg_rect_dist(a, b, rect) > r + margin) continue;
                    size_t i = (size_t)gz * ncx + gx;
                    if (pass == 1) (*entries)[first[i] + count[i]] = (uint32_t)k;
                    count[i]++;
                }
        }
        if (pass == 0)
            for (size_t i = 0; i < ncells; i++)
                if (count[i] > most) most = count[i], *worst = i;
        if (pass == 0 && most > SPLAT_MAX_VECTOR_CELL)
            return most;
    }
    return most;
}

/* The shapes' words (half width, falloff, profile and kind) and the
 * segments' (end points, shape). */
static void shape_words(const sg_scene *sc, splat_vectors *v, const seglist *l)
{
    uint32_t *w = v->words;
    for (int s = 0; s < sc->nvectors; s++) {
        const sg_scene_vector *sv = &sc->vectors[s];
        uint32_t *q = &w[shape_at(v, s)];
        q[0] = fw(sv->kind == SPLAT_VEC_SPLINE ? (float)(0.5 * sv->width) : 0.0f);
        q[1] = fw((float)sv->falloff);
        q[2] = (uint32_t)sv->profile | (uint32_t)sv->kind << 8;
    }
    for (size_t k = 0; k < l->n; k++) {
        uint32_t *q = &w[segs_at(v) + SPLAT_VEC_SEG * k];
        for (int j = 0; j < 4; j++) q[j] = fw(l->xz[k][j]);
        q[4] = (uint32_t)l->shape[k];
    }
}

/* The cells' words: first entry and count, the reference point, and the
 * polygons the reference point is inside (after the segments' words:
 * it reads them back as the shader does). */
static void cell_words(const sg_scene *sc, splat_vectors *v, const double o[2], double c,
                       uint32_t ncx, size_t ncells, const uint32_t *count,
                       const uint32_t *first, const uint32_t *entries)
{
    bool polygons = false;
    for (int s = 0; s < sc->nvectors; s++)
        polygons |= sc->vectors[s].kind == SPLAT_VEC_POLYGON;
    for (size_t i = 0; i < ncells; i++) {
        uint32_t *q = &v->words[cells_at(v) + SPLAT_VEC_CELL * i];
        q[0] = first[i], q[1] = count[i];
        double gx = (double)(i % ncx), gz = (double)(i / ncx);
        /* the reference point: the candidate farthest from the cell's
         * polygon edges, so the shader's fp32 crossings agree */
        double best[2] = { o[0] + (gx + 0.5) * c, o[1] + (gz + 0.5) * c }, bestd = -1;
        for (int cand = 0; polygons && count[i] > 0 && cand < 9; cand++) {
            double p[2] = { (float)(o[0] + (gx + 0.25 + 0.25 * (cand % 3)) * c),
                            (float)(o[1] + (gz + 0.25 + 0.25 * (cand / 3)) * c) };
            double m = INFINITY;
            for (uint32_t e = 0; e < count[i]; e++) {
                double a[2], b[2];
                int s = seg_get(v, entries[first[i] + e], a, b);
                if (sc->vectors[s].kind == SPLAT_VEC_POLYGON) m = fmin(m, seg_dist(p, a, b));
            }
            if (m > bestd) bestd = m, best[0] = p[0], best[1] = p[1];
        }
        q[4] = fw((float)best[0]), q[5] = fw((float)best[1]);
        double ref[2] = { wf(v, cells_at(v) + SPLAT_VEC_CELL * i + 4),
                          wf(v, cells_at(v) + SPLAT_VEC_CELL * i + 5) };
        for (int s = 0; s < sc->nvectors; s++)
            if (sc->vectors[s].kind == SPLAT_VEC_POLYGON && inside_polygon(v, s, ref))
                q[2] |= 1u << s;
    }
}

void splat_vectors_free(splat_vectors *v)
{
    free(v->words);
    free(v->shape_first);
    memset(v, 0, sizeof *v);
}

bool splat_vectors_build(const sg_scene *sc, splat_vectors *v, sg_diags *d)
{
    memset(v, 0, sizeof *v);
    int ns = sc->nvectors;
    if (ns == 0) return true;
    seglist l = { 0 };
    v->shape_first = xcalloc((size_t)ns + 1, sizeof *v->shape_first);
    double reach = 0, ext = 0, box[4] = { INFINITY, INFINITY, -INFINITY, -INFINITY };
    for (int s = 0; s < ns; s++) {
        const sg_scene_vector *sv = &sc->vectors[s];
        v->shape_first[s] = (uint32_t)l.n;
        flatten(sv, s, &l);
        if (l.n > SPLAT_MAX_VECTOR_SEGMENTS) {
            sg_errorf(d, sg_loc_or(sv->loc, sc->loc), SG_E_OVER_LIMIT, "the splines and "
                      "polygons up to '%s' make %zu segments, over the pack limit of %d",
                      sv->name, l.n, SPLAT_MAX_VECTOR_SEGMENTS);
            goto fail;
        }
        double hw = sv->kind == SPLAT_VEC_SPLINE ? 0.5 * sv->width : 0;
        reach = fmax(reach, hw + sv->falloff);
    }
    v->shape_first[ns] = (uint32_t)l.n;
    for (size_t k = 0; k < l.n; k++)
        for (int q = 0; q < 4; q++) {
            box[q & 1] = fmin(box[q & 1], l.xz[k][q]);
            box[2 + (q & 1)] = fmax(box[2 + (q & 1)], l.xz[k][q]);
            ext = fmax(ext, fabs(l.xz[k][q]));
        }
    /* the shader's fp32 position (ulp 1/2^24 of it) and arithmetic */
    v->margin = 0.05 + 4e-6 * (ext + reach);
    double pad = reach + 2 * v->margin;
    double o[2] = { (float)(box[0] - pad), (float)(box[1] - pad) };
    double span = fmax(box[2] - box[0], box[3] - box[1]) + 2 * pad;
    /* The cell: twice the largest reach, and cells enough for a buffer
     * of about 2^16 cells (1.5 MB) over the shapes' box; halved while a
     * cell lists more than SPLAT_MAX_VECTOR_CELL segments, down to half
     * the reach (closer segments stay in every cell near them). */
    double c = fmax(fmax(2 * reach, 1.0), fmax(span / (SPLAT_MAX_VECTOR_GRID - 4), span / 256));
    uint32_t ncx, ncz, *count = NULL, *first = NULL, *entries = NULL, most;
    size_t nentries = 0, worst = 0, ncells;
    for (;;) {
        c = (float)c;
        ncx = (uint32_t)ceil((box[2] + pad - o[0]) / c) + 1;
        ncz = (uint32_t)ceil((box[3] + pad - o[1]) / c) + 1;
        assert(ncx <= SPLAT_MAX_VECTOR_GRID && ncz <= SPLAT_MAX_VECTOR_GRID);
        ncells = (size_t)ncx * ncz;
        count = xrealloc(count, ncells * sizeof *count);
        first = xrealloc(first, ncells * sizeof *first);
        free(entries);
        most = bucket(sc, &l, o, c, ncx, ncz, v->margin, count, first, &entries, &nentries,
                      &worst);
        if (most <= SPLAT_MAX_VECTOR_CELL || c / 2 < fmax(0.5 * reach, 0.5) ||
            ceil(span / (c / 2)) + 4 > SPLAT_MAX_VECTOR_GRID)
            break;
        c /= 2;
    }
    if (most > SPLAT_MAX_VECTOR_CELL) {
        double cx = o[0] + ((double)(worst % ncx) + 0.5) * c;
        double cz = o[1] + ((double)(worst / ncx) + 0.5) * c;
        sg_errorf(d, sg_loc_or(sc->vectors[0].loc, sc->loc), SG_E_OVER_LIMIT,
                  "%u spline or polygon segments lie near x %.0f z %.0f (a %.1f m "
                  "grid cell), over the limit of %d a cell: fewer points there, or "
                  "narrower shapes", most, cx, cz, c, SPLAT_MAX_VECTOR_CELL);
        free(count), free(first), free(entries);
        goto fail;
    }
    /* the words */
    v->nwords = SPLAT_VEC_HEADER + (size_t)SPLAT_VEC_SHAPE * ns + SPLAT_VEC_CELL * ncells +
                nentries + (size_t)SPLAT_VEC_SEG * l.n;
    if (v->nwords > SPLAT_MAX_VECTOR_WORDS) {
        sg_errorf(d, sg_loc_or(sc->vectors[0].loc, sc->loc), SG_E_OVER_LIMIT, "the splines "
                  "and polygons need %zu words of grid and segments, over the pack limit of "
                  "%d (fewer points, or shapes closer together)", v->nwords,
                  SPLAT_MAX_VECTOR_WORDS);
        free(count), free(first), free(entries);
        goto fail;
    }
    v->words = xcalloc(v->nwords, sizeof *v->words);
    uint32_t *w = v->words;
    w[0] = ncx, w[1] = ncz, w[2] = (uint32_t)ns, w[3] = (uint32_t)l.n;
    w[4] = (uint32_t)nentries;
    w[5] = fw((float)o[0]), w[6] = fw((float)o[1]), w[7] = fw((float)c);
    shape_words(sc, v, &l);
    memcpy(&w[entries_at(v)], entries, nentries * sizeof *entries);
    cell_words(sc, v, o, c, ncx, ncells, count, first, entries);
    free(count), free(first), free(entries);
    free(l.xz), free(l.shape);
    return true;
fail:
    free(l.xz), free(l.shape);
    splat_vectors_free(v);
    return false;
}

int splat_vector_find(const sg_scene *sc, const char *painted_name, bool *across)
{
    if (strncmp(painted_name, "vector.", 7) != 0) return -1;
    const char *name = painted_name + 7, *dot = strchr(name, '.');
    size_t n = dot ? (size_t)(dot - name) : strlen(name);
    if (dot && strcmp(dot, ".across") != 0) return -1;
    *across = dot != NULL;
    for (int s = 0; s < sc->nvectors; s++)
        if (strlen(sc->vectors[s].name) == n && !strncmp(sc->vectors[s].name, name, n))
            return s;
    return -1;
}
