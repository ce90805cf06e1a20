/* shadow.c — the terrain's shadow from the sun: a sun-visibility map, one
 * R8 texel per heightfield texel (set 0, binding SPLAT_BIND_SHADOW), that
 * the prelude's splat_light samples bilinearly at the shaded point and
 * multiplies the sun term by (every shading path alike).
 *
 * Each texel centre marches towards the sun over the heightfield: samples
 * every half texel (t = k step, k = 1, 2, ...), the terrain read as the
 * shaders read it (bilinear between texel centres, rt_height_at), stepping
 * over every quadtree node whose maximum height (rt_bounds, which craters
 * keep current) lies so far below the ray that no sample in it could lower
 * the result, and stopping once the ray is above the whole terrain or off
 * it.  The visibility is the fraction of the sun's disc (0.27 degrees of
 * radius) above the horizon the march found: 0.5 + m / (2 tan r), clamped,
 * with m the lowest clearance angle's tangent along the ray.
 *
 * A crater remakes only the texels whose march can pass over its disc: the
 * disc swept away from the sun by (highest - lowest) / rise, plus two
 * texels (rt_shadow_crater_rect; render.shadow checks the result equals
 * the whole map made again).
 *
 * This is the reference: the renderer marches the same samples on the
 * device by default (shadow_gpu.c, over a pyramid of texel maxima instead
 * of the quadtree: the skips pass only over samples that cannot change the
 * result, so the bound used does not change the map; render.shadow_gpu
 * holds the two within 1/255), and here with rt_render_desc.shadow
 * RT_SHADOW_CPU (splatview --shadow cpu, SPLAT_SHADOW=cpu).
 *
 * Why a map, not a per-pixel march nor a horizon map: the sun and the
 * heights change only on an event (the viewer's sun keys, a light
 * override, a crater), so a frame pays one texture tap per pixel and
 * nothing else.  A horizon map would store many directions to make turning
 * the sun free, at many times the memory, for an event that is rare.  The
 * cost of an update is in the benchmark (splatbench shadow: the CPU and
 * the device's march on colorado, side by side). */
#include "rt_internal.h"

#include <math.h>
#include <pthread.h>
#include <stdbool.h>
#include <stdlib.h>
#include <unistd.h>

/* tan of the sun's angular radius */
#define SUN_TAN 0.0047

typedef struct march {
    const uint16_t  *heights;
    const rt_pack   *p;
    const rt_bounds *b;
    double dir[2], rise;    /* horizontal unit direction; rise per metre    */
    double leaf[2];         /* a quadtree leaf's size in metres             */
    double top;             /* highest height of the terrain                */
} march;

/* Distance along the ray from (x, z) to where it leaves the cell (cx, cz)
 * of `size` metres. */
static double cell_exit(const march *m, double x, double z, int cx, int cz, const double size[2])
{
    double t = INFINITY;
    for (int a = 0; a < 2; a++) {
        double pos = a ? z : x, d = m->dir[a];
        int c = a ? cz : cx;
        if (d > 1e-12)
            t = fmin(t, ((c + 1) * size[a] - pos) / d);
        else if (d < -1e-12)
            t = fmin(t, (c * size[a] - pos) / d);
    }
    return fmax(t, 0.0);
}

/* How far the ray at (x, z), height `ray`, t along, may skip: the exit of
 * the largest quadtree node around it whose samples cannot lower the
 * lowest clearance below `thr` (min(lowest so far, tan of the sun's
 * radius): the ray only rises, so past t a sample's clearance is at least
 * (ray - hmax) / (t + exit) where that is positive, (ray - hmax) / t
 * where it is not); 0: none. */
static double skip(const march *m, double x, double z, double ray, double t, double thr)
{
    const rt_bounds *b = m->b;
    double best = 0, size[2] = { m->leaf[0], m->leaf[1] };
    for (int L = 0; L < b->nlevels; L++, size[0] *= 2, size[1] *= 2) {
        int cx = (int)(x / size[0]), cz = (int)(z / size[1]);
        cx = cx < b->width[L] ? cx : b->width[L] - 1;
        cz = cz < b->height[L] ? cz : b->height[L] - 1;
        double hmax = b->hmax[L][(size_t)cz * (size_t)b->width[L] + (size_t)cx];
        double exit = cell_exit(m, x, z, cx, cz, size);
        if (!(ray - hmax > thr * (thr >= 0 ? t + exit : t)))
            break;
        best = exit;
    }
    return best;
}

/* The samples lie at t = k step, k = 1, 2, ... whatever is skipped, and
 * a skip passes over only samples that cannot lower the result (skip), so
 * the map is the same over any bound of the heights: the GPU march
 * (shadow_gpu.c) skips over a pyramid of texel maxima and makes this map.
 * The march ends off the terrain or above its highest point (the top of
 * the quadtree's bounds, which craters keep current). */
static uint8_t visibility(const march *m, double x0, double z0, double y0, double step)
{
    const rt_pack *p = m->p;
    double lowest = INFINITY;   /* tan of the lowest clearance */
    for (double k = 1; lowest > -SUN_TAN;) {
        double t = k * step;
        double x = x0 + m->dir[0] * t, z = z0 + m->dir[1] * t, ray = y0 + m->rise * t;
        if (x < 0 || z < 0 || x > p->size[0] || z > p->size[1] || ray > m->top)
            break;
        double jump = skip(m, x, z, ray, t, fmin(lowest, SUN_TAN));
        if (jump > 0) {
            k = fmax(k + 1, floor((t + jump) / step) + 1);
            continue;
        }
        double h = rt_height_at(m->heights, p, x, z);
        lowest = fmin(lowest, (ray - h) / t);
        k++;
    }
    double v = isinf(lowest) ? 1.0 : 0.5 + lowest / (2.0 * SUN_TAN);
    v = v < 0 ? 0 : v > 1 ? 1 : v;
    return (uint8_t)lrint(v * 255.0);
}

/* Rows [j0, j1), columns [i0, i1) of the map. */
typedef struct rows {
    const march *m;
    uint8_t     *out;
    int          j0, j1, i0, i1;
    double       step;
} rows;

static void *map_rows(void *arg)
{
    const rows *r = arg;
    const rt_pack *p = r->m->p;
    int W = p->hf_width, H = p->hf_height;
    double sx = p->size[0] / W, sz = p->size[1] / H;
    for (int j = r->j0; j < r->j1; j++)
        for (int i = r->i0; i < r->i1; i++) {
            double x = (i + 0.5) * sx, z = (j + 0.5) * sz;
            double y = rt_height_at(r->m->heights, p, x, z) + 1e-4 * (p->max_height + 1.0);
            r->out[(size_t)j * (size_t)W + (size_t)i] = visibility(r->m, x, z, y, r->step);
        }
    return NULL;
}

bool rt_shadow_crater_rect(const rt_pack *p, const rt_bounds *b, const double sun[3],
                           double x, double z, double radius, int rect[4])
{
    int W = p->hf_width, H = p->hf_height;
    double flat = sqrt(sun[0] * sun[0] + sun[2] * sun[2]);
    if (sun[1] <= -SUN_TAN * flat || flat < 1e-9)
        return false;   /* the map does not depend on the heights */
    /* a march reaches the disc only from up to L before it, away from the
     * sun: L = (highest - lowest) / rise */
    double rise = sun[1] / flat, span = b->hmax[b->nlevels - 1][0] - b->hmin[b->nlevels - 1][0];
    double len = rise > 1e-9 ? span / rise : p->size[0] + p->size[1];
    len = fmin(len, p->size[0] + p->size[1]);
    double ex = -sun[0] / flat * len, ez = -sun[2] / flat * len;
    double sx = p->size[0] / W, sz = p->size[1] / H;
    double lo[2] = { fmin(x, x + ex) - radius, fmin(z, z + ez) - radius };
    double hi[2] = { fmax(x, x + ex) + radius, fmax(z, z + ez) + radius };
    /* two texels more: bilinear reads around the changed ones */
    rect[0] = (int)fmax(0, floor(lo[0] / sx) - 2);
    rect[1] = (int)fmax(0, floor(lo[1] / sz) - 2);
    rect[2] = (int)fmin(W, ceil(hi[0] / sx) + 3);
    rect[3] = (int)fmin(H, ceil(hi[1] / sz) + 3);
    return true;
}

void rt_shadow_map(const uint16_t *heights, const rt_pack *p, const rt_bounds *b,
                   const double sun[3], const int rect[4], uint8_t *out)
{
    int W = p->hf_width, H = p->hf_height;
    int i0 = rect ? rect[0] : 0, j0 = rect ? rect[1] : 0;
    int i1 = rect ? rect[2] : W, j1 = rect ? rect[3] : H;
    double flat = sqrt(sun[0] * sun[0] + sun[2] * sun[2]);
    size_t n = (size_t)W * (size_t)H;
    if (sun[1] <= -SUN_TAN * flat || flat < 1e-9) {   /* below the horizon, or overhead */
        for (size_t i = 0; i < n; i++)
            out[i] = sun[1] > 0 ? 255 : 0;
        return;
    }
    if (i0 >= i1 || j0 >= j1)
        return;
    double sx = p->size[0] / W, sz = p->size[1] / H;
    march m = {
        .heights = heights, .p = p, .b = b,
        .dir = { sun[0] / flat, sun[2] / flat }, .rise = sun[1] / flat,
        .leaf = { sx * p->cell_texels, sz * p->cell_texels },
        .top = b->hmax[b->nlevels - 1][0],
    };
    /* rows split over the CPU's cores; each texel's march is independent */
    enum { MAX_THREADS = 32 };
    long cores = sysconf(_SC_NPROCESSORS_ONLN);
    int nt = cores < 1 ? 1 : cores > MAX_THREADS ? MAX_THREADS : (int)cores;
    nt = nt > j1 - j0 ? j1 - j0 : nt;
    rows part[MAX_THREADS];
    pthread_t tid[MAX_THREADS];
    bool started[MAX_THREADS] = { false };
    for (int k = 0; k < nt; k++) {
        part[k] = (rows){ &m, out, j0 + (int)((long)(j1 - j0) * k / nt),
                          j0 + (int)((long)(j1 - j0) * (k + 1) / nt), i0, i1, 0.5 * fmin(sx, sz) };
        started[k] = k > 0 && pthread_create(&tid[k], NULL, map_rows, &part[k]) == 0;
    }
    for (int k = 0; k < nt; k++)
        if (!started[k])
            map_rows(&part[k]);   /* the caller's share, or a thread that did not start */
    for (int k = 1; k < nt; k++)
        if (started[k])
            pthread_join(tid[k], NULL);
}
