/* bench_lanes.c — layer efficiency predicted for other subgroup sizes and
 * other pixel-to-lane assignments (issue 33, item 4), from the layers view
 * (abi.h SPLAT_VIEW_LAYERS) of one screen-path frame read back as floats:
 * per terrain pixel the set of layers it needs and the layers its lane
 * evaluated on this device.
 *
 * The model is the counting variant's: the surface of layer j runs for a
 * subgroup when any of its live lanes needs j (the composite's branches
 * are subgroupAny there, and SIMD hardware pays the same where they
 * diverge), and then counts as evaluated for every live lane.  So a
 * subgroup of live lanes L evaluates |L| * |union of their sets| layers,
 * and the efficiency is the sum of |set| over the pixels divided by the
 * sum of that over the subgroups.  A lane without terrain returns before
 * the composite: it is not live.
 *
 * The screen path shades an 8x8 tile per workgroup of 64 invocations,
 * invocation x + 8 y for pixel (x, y) of the tile, and a subgroup of S
 * lanes takes invocations S k .. S k + S - 1: rows of 8 on lavapipe (S
 * 8), the tile's upper and lower halves (8x4) on NVIDIA (S 32), the whole
 * tile on AMD (S 64).  Predicting S = this device's subgroup size for
 * that assignment must give the measured figure exactly; that is the
 * check of the model (printed beside it). */
#include "bench.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define T 64         /* pixels per tile */
#define BLOCK_MAX 16 /* tiles in the largest block */

typedef struct lane_px {
    uint64_t need;   /* the layers the pixel needs, layer j as bit j */
    uint64_t prev;   /* the same pixel's set one frame earlier (0: none) */
    int      list;   /* the combination that shaded it */
    bool     live;   /* terrain */
} lane_px;

/* The assignments: each orders the pixels of a block of tiles; lanes take
 * them in that order, S to a subgroup, a subgroup within one tile (the
 * first three) or one combination (the sorted ones). */
typedef enum lane_scheme {
    LS_ROWS,        /* the shading pass now: invocation x + 8 y            */
    LS_COLUMNS,     /* y + 8 x: subgroups of 4x8 columns                   */
    LS_MORTON,      /* Z order within the tile                            */
    LS_SORT_MASK,   /* the tile's live pixels sorted by their set (stable):
                       the best a permutation within the tile can do      */
    LS_SORT_PREV,   /* sorted by the set the same pixel needed one frame
                       earlier: a permutation made from the last frame    */
    LS_SORT_MASK4,  /* the live pixels of 2x2 tiles of one combination
                       sorted by their set: workgroups of 4 tiles          */
    LS_SORT_PREV4,  /* the same, by last frame's set                      */
    LS_SORT_MASK16, /* 4x4 tiles (pixel sorting's 16 tiles, but square)   */
    LS_SORT_PREV16, /* the same, by last frame's set                      */
    LS_SORT_ROW16,  /* 16x1 tiles sorted by set: pixel sorting's 16 tiles
                       where a list holds rows of tiles                    */
    LS_COUNT
} lane_scheme;

static const char *const scheme_names[LS_COUNT] = {
    "rows (now)", "columns", "Z order", "tile sorted by set", "tile sorted by last frame",
    "2x2 tiles sorted by set", "2x2 tiles by last frame", "4x4 tiles sorted by set",
    "4x4 tiles by last frame", "16x1 tiles sorted by set",
};
/* the block of tiles a scheme orders, across and down */
static const int scheme_bw[LS_COUNT] = { 1, 1, 1, 1, 1, 2, 2, 4, 4, 16 };
static const int scheme_bh[LS_COUNT] = { 1, 1, 1, 1, 1, 2, 2, 4, 4, 1 };
static bool scheme_prev(int s)
{
    return s == LS_SORT_PREV || s == LS_SORT_PREV4 || s == LS_SORT_PREV16;
}

static int popc(uint64_t v) { return __builtin_popcountll(v); }

static unsigned morton(int li)
{
    unsigned x = (unsigned)li & 7u, y = (unsigned)li >> 3;
    unsigned m = 0;
    for (int b = 0; b < 3; b++)
        m |= ((x >> b) & 1u) << (2 * b) | ((y >> b) & 1u) << (2 * b + 1);
    return m;
}

/* A pixel of the layers view (abi.c splat_layers_color). */
static void px_read(const float *p, lane_px *q)
{
    q->live = p[2] >= 4096.0f;
    if (!q->live)
        return;
    q->need = (uint64_t)(uint32_t)p[0] | (uint64_t)(uint32_t)p[1] << 24;
    q->list = (int)(p[2] / 256.0f) - 16;
}

static double px_evaluated(const float *p) { return fmod(p[2], 256.0); }

typedef struct sort_item {
    int      list;
    uint64_t key;
    int      at;
} sort_item;

static int by_key(const void *a, const void *b)
{
    const sort_item *x = a, *y = b;
    if (x->list != y->list)
        return x->list - y->list;
    if (x->key != y->key)
        return x->key < y->key ? -1 : 1;
    return x->at - y->at;   /* stable */
}

/* The layers a block of n pixels (tile k's at 64 k .. 64 k + 63, in
 * invocation order x + 8 y) evaluates with subgroups of S lanes under
 * scheme s. */
static double block_evaluated(const lane_px *px, int n, lane_scheme s, int S)
{
    static int order[T * BLOCK_MAX];
    static sort_item it[T * BLOCK_MAX];
    double ev = 0;
    if (s <= LS_MORTON) {   /* per tile, dead lanes kept in place */
        for (int t = 0; t < n; t += T) {
            for (int i = 0; i < T; i++)
                order[i] = s == LS_COLUMNS ? (i & 7) * 8 + (i >> 3) : i;
            if (s == LS_MORTON)
                for (int i = 0; i < T; i++)
                    order[morton(i)] = i;
            for (int g = 0; g < T; g += S) {
                uint64_t u = 0;
                int live = 0;
                for (int k = g; k < g + S; k++)
                    if (px[t + order[k]].live) {
                        u |= px[t + order[k]].need;
                        live++;
                    }
                ev += (double)live * popc(u);
            }
        }
        return ev;
    }
    bool prev = scheme_prev(s);
    int m = 0;
    for (int i = 0; i < n; i++)
        if (px[i].live)   /* per tile: the tile's index keeps tiles apart */
            it[m++] = (sort_item){ scheme_bw[s] == 1 ? i / T : px[i].list,
                                   prev ? px[i].prev : px[i].need, i };
    qsort(it, (size_t)m, sizeof *it, by_key);
    for (int g = 0; g < m;) {
        uint64_t u = 0;
        int live = 0, k = g;
        for (; k < m && k < g + S && it[k].list == it[g].list; k++) {
            u |= px[it[k].at].need;
            live++;
        }
        ev += (double)live * popc(u);
        g = k;
    }
    return ev;
}

void lanes_predict(FILE *out, const char *label, const float *rgba, const float *prev_rgba,
                   int w, int h)
{
    static const int sizes[3] = { 8, 32, 64 };
    static lane_px px[T * BLOCK_MAX];
    double ev[LS_COUNT][3] = { { 0 } }, need = 0, measured = 0;
    long live = 0;
    int tw = (w + 7) / 8, th = (h + 7) / 8;
    for (int s = 0; s < LS_COUNT; s++) {
        if (scheme_prev(s) && !prev_rgba)
            continue;
        int BW = scheme_bw[s], BH = scheme_bh[s];
        for (int by = 0; by < th; by += BH)
            for (int bx = 0; bx < tw; bx += BW) {
                int n = 0;
                for (int ty = by; ty < by + BH && ty < th; ty++)
                    for (int tx = bx; tx < bx + BW && tx < tw; tx++, n += T)
                        for (int i = 0; i < T; i++) {
                            int x = tx * 8 + (i & 7), y = ty * 8 + (i >> 3);
                            lane_px *q = &px[n + i];
                            memset(q, 0, sizeof *q);
                            if (x >= w || y >= h)
                                continue;
                            size_t at = ((size_t)y * (size_t)w + (size_t)x) * 4;
                            px_read(rgba + at, q);
                            if (!q->live)
                                continue;
                            if (prev_rgba) {
                                lane_px o;
                                memset(&o, 0, sizeof o);
                                px_read(prev_rgba + at, &o);
                                q->prev = o.live ? o.need : 0;
                            }
                            if (s == 0) {
                                need += popc(q->need);
                                measured += px_evaluated(rgba + at);
                                live++;
                            }
                        }
                for (int k = 0; k < 3; k++)
                    ev[s][k] += block_evaluated(px, n, (lane_scheme)s, sizes[k]);
            }
    }
    double n = live ? (double)live : 1.0;
    fprintf(out, "lanes %s: %ld terrain pixels, %.4f layers needed per pixel; measured on this "
                 "device: %.4f evaluated, efficiency %.2f %%\n",
            label, live, need / n, measured / n, measured > 0 ? 100.0 * need / measured : 100.0);
    fprintf(out, "lanes %s: predicted efficiency     %9s %9s %9s   (lanes per subgroup)\n",
            label, "8", "32", "64");
    for (int s = 0; s < LS_COUNT; s++) {
        if (scheme_prev(s) && !prev_rgba)
            continue;
        fprintf(out, "lanes %s:   %-27s", label, scheme_names[s]);
        for (int k = 0; k < 3; k++)
            fprintf(out, "  %5.2f %%", ev[s][k] > 0 ? 100.0 * need / ev[s][k] : 100.0);
        fprintf(out, "\n");
    }
}
