/* sparse_query.c — reading a built (or loaded) atlas: a mask's value at a
 * point (sparse_sample, what the GPU's sparse_mask() computes), the
 * stored bounds per cell and their range over a rectangle, and the GLSL
 * table of each mask's place. */
#include "sparse_internal.h"
#include "ir.h"
#include "util.h"

#include <assert.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <xxhash.h>

#include <stb_image.h>

/* ---- atlas access --------------------------------------------------------- */

size_t sparse_cell_at(const sparse_masks *s, int mask, int cx, int cz)
{
    return (((size_t)(mask / 4) * s->cells_z + cz) * s->cells_x + cx) * 4 + mask % 4;
}

/* Atlas texel (ax, az) as stored, 0..1 (BC4 decoded). */
static float atlas_texel(const sparse_masks *s, int ax, int az)
{
    ax = sparse_clampi(ax, 0, s->atlas_width - 1);
    az = sparse_clampi(az, 0, s->atlas_height - 1);
    if (s->format == SPARSE_R8)
        return s->atlas[(size_t)az * s->atlas_width + ax] / 255.0f;
    float block[16];
    size_t b = (size_t)(az / 4) * (s->atlas_width / 4) + (size_t)(ax / 4);
    sparse_bc4_decode(s->atlas + b * 8, block);
    return block[(az % 4) * 4 + ax % 4];
}

void sparse_slot_origin(const sparse_masks *s, int slot, int *ox, int *oz)
{
    *ox = (slot % s->atlas_cols) * SPARSE_SLOT;
    *oz = (slot / s->atlas_cols) * SPARSE_SLOT;
}

bool sparse_placed(const sparse_masks *s, int mask)
{
    const sparse_place *p = &s->place[mask];
    return p->width != s->width || p->height != s->height || p->rect[0] != 0.0 ||
           p->rect[1] != 0.0 || p->rect[2] != 1.0 || p->rect[3] != 1.0;
}

/* The floats the GLSL's splat_painted_rect holds (sparse_glsl_places). */
static void place_floats(const sparse_place *p, float f[4])
{
    f[0] = (float)p->rect[0];
    f[1] = (float)p->rect[1];
    f[2] = (float)(1.0 / (p->rect[2] - p->rect[0]));
    f[3] = (float)(1.0 / (p->rect[3] - p->rect[1]));
}

double sparse_sample(const sparse_masks *s, int mask, double u, double v)
{
    assert(mask >= 0 && mask < s->nmasks);
    const sparse_place *pl = &s->place[mask];
    /* the GLSL's float arithmetic, step by step */
    float mu = (float)u, mv = (float)v;
    if (sparse_placed(s, mask)) {
        float r[4];
        place_floats(pl, r);
        mu = (mu - r[0]) * r[2];
        mv = (mv - r[1]) * r[3];
        if (!(mu >= 0.0f && mv >= 0.0f && mu <= 1.0f && mv <= 1.0f))   /* or NaN */
            return 0.0;
    }
    float tx = mu * (float)pl->width, tz = mv * (float)pl->height;
    int cx = sparse_clampi((int)floorf(tx * (1.0f / 32.0f)), 0, pl->cells_x - 1);
    int cz = sparse_clampi((int)floorf(tz * (1.0f / 32.0f)), 0, pl->cells_z - 1);
    size_t at = sparse_cell_at(s, mask, cx, cz);
    unsigned e = s->index[at];
    if (e == SPARSE_CONST0)
        return 0.0;
    if (e == SPARSE_CONST1)
        return 1.0;
    int L = s->level[at];
    float scale = ldexpf(1.0f, -L);
    float qx = tx * scale - (float)(cx >> L) * 32.0f;
    float qz = tz * scale - (float)(cz >> L) * 32.0f;
    qx = qx < 0.0f ? 0.0f : qx > 32.0f ? 32.0f : qx;
    qz = qz < 0.0f ? 0.0f : qz > 32.0f ? 32.0f : qz;
    int ox, oz;
    sparse_slot_origin(s, (int)e - 1, &ox, &oz);
    double ax = ox + SPARSE_PAD + (double)qx - 0.5;
    double az = oz + SPARSE_PAD + (double)qz - 0.5;
    double fx = floor(ax), fz = floor(az);
    int ix = (int)fx, iz = (int)fz;
    double wx = ax - fx, wz = az - fz;
    double a = atlas_texel(s, ix, iz), b = atlas_texel(s, ix + 1, iz);
    double c = atlas_texel(s, ix, iz + 1), d = atlas_texel(s, ix + 1, iz + 1);
    double top = a + (b - a) * wx, bot = c + (d - c) * wx;
    return top + (bot - top) * wz;
}

/* ---- bounds ------------------------------------------------------------- */

typedef struct bounds { double lo, hi; } bounds;

static void bounds_add(bounds *b, double v)
{
    if (v < b->lo) b->lo = v;
    if (v > b->hi) b->hi = v;
}

/* Slot-local texel range read by samples with q in [qa, qb] (clamped). */
static void q_texels(double qa, double qb, int *j0, int *j1)
{
    qa = qa < 0 ? 0 : qa > 32 ? 32 : qa;
    qb = qb < 0 ? 0 : qb > 32 ? 32 : qb;
    *j0 = sparse_clampi((int)floor(qa - 0.5), -1, SPARSE_TILE);
    *j1 = sparse_clampi((int)floor(qb - 0.5) + 1, -1, SPARSE_TILE);
}

/* Values the GPU may read in cell n for raster positions in the closed
 * rectangle [tx0, tx1] x [tz0, tz1].  `dec` is the decoded atlas. */
static void stored_bounds(const sparse_masks *s, const float *dec, int mask,
                          int nx, int nz, double tx0, double tz0, double tx1,
                          double tz1, bounds *b)
{
    size_t at = sparse_cell_at(s, mask, nx, nz);
    unsigned e = s->index[at];
    if (e == SPARSE_CONST0 || e == SPARSE_CONST1) {
        bounds_add(b, e == SPARSE_CONST1 ? 1.0 : 0.0);
        return;
    }
    int L = s->level[at];
    double sc = ldexp(1.0, -L);
    double bx = 32.0 * (nx >> L), bz = 32.0 * (nz >> L);
    int i0, i1, j0, j1, ox, oz;
    q_texels(tx0 * sc - bx, tx1 * sc - bx, &i0, &i1);
    q_texels(tz0 * sc - bz, tz1 * sc - bz, &j0, &j1);
    sparse_slot_origin(s, (int)e - 1, &ox, &oz);
    bounds sb = { 1.0, 0.0 };
    for (int j = j0; j <= j1; j++)
        for (int i = i0; i <= i1; i++) {
            size_t a = (size_t)(oz + SPARSE_PAD + j) * s->atlas_width + (size_t)(ox + SPARSE_PAD + i);
            bounds_add(&sb, dec[a]);
        }
    /* A GPU may round BC4's interpolated palette entries to 8 bits. */
    if (s->format == SPARSE_BC4) {
        double h = 0.5 / 255.0;
        if (fabs(sb.lo * 255.0 - round(sb.lo * 255.0)) > 1e-3)
            sb.lo = sb.lo - h < 0 ? 0 : sb.lo - h;
        if (fabs(sb.hi * 255.0 - round(sb.hi * 255.0)) > 1e-3)
            sb.hi = sb.hi + h > 1 ? 1 : sb.hi + h;
    }
    bounds_add(b, sb.lo);
    bounds_add(b, sb.hi);
}

static float float_down(double v)
{
    float f = (float)v;
    return (double)f > v ? nextafterf(f, -INFINITY) : f;
}

static float float_up(double v)
{
    float f = (float)v;
    return (double)f < v ? nextafterf(f, INFINITY) : f;
}

void sparse_compute_bounds(sparse_masks *s, const sparse_desc *d)
{
    size_t ncell = (size_t)s->cells_x * s->cells_z;
    s->lo = xcalloc(ncell * (size_t)(d->nmasks ? d->nmasks : 1), sizeof *s->lo);
    s->hi = xcalloc(ncell * (size_t)(d->nmasks ? d->nmasks : 1), sizeof *s->hi);
    /* the atlas as the GPU reads it, decoded once */
    size_t aw = (size_t)s->atlas_width, ah = (size_t)s->atlas_height;
    float *dec = xcalloc(aw * ah, sizeof *dec);
    if (s->format == SPARSE_R8) {
        for (size_t i = 0; i < aw * ah; i++)
            dec[i] = s->atlas[i] / 255.0f;
    } else {
        for (size_t bz = 0; bz < ah / 4; bz++)
            for (size_t bx = 0; bx < aw / 4; bx++) {
                float block[16];
                sparse_bc4_decode(s->atlas + (bz * (aw / 4) + bx) * 8, block);
                for (int j = 0; j < 4; j++)
                    memcpy(dec + (bz * 4 + j) * aw + bx * 4, block + 4 * j, 4 * sizeof *dec);
            }
    }
    for (int m = 0; m < d->nmasks; m++) {
        const sparse_place *pl = &s->place[m];
        raster r = { pl->width, pl->height, d->masks[m].texels };
        for (int cz = 0; cz < pl->cells_z; cz++)
            for (int cx = 0; cx < pl->cells_x; cx++) {
                bounds b = { 1.0, 0.0 };
                /* (a) the original raster's bilinear footprint */
                int lo = 255, hi = 0;
                for (int z = 32 * cz - 1; z <= 32 * cz + 32; z++)
                    for (int x = 32 * cx - 1; x <= 32 * cx + 32; x++) {
                        int v = sparse_texel(&r, x, z);
                        lo = v < lo ? v : lo;
                        hi = v > hi ? v : hi;
                    }
                bounds_add(&b, lo / 255.0);
                bounds_add(&b, hi / 255.0);
                /* (b) own stored data, (c) neighbours' data on shared edges */
                double x0 = 32.0 * cx, x1 = x0 + 32, z0 = 32.0 * cz, z1 = z0 + 32;
                for (int dz = -1; dz <= 1; dz++)
                    for (int dx = -1; dx <= 1; dx++) {
                        int nx = cx + dx, nz = cz + dz;
                        if (nx < 0 || nz < 0 || nx >= pl->cells_x || nz >= pl->cells_z)
                            continue;
                        double ax0 = fmax(x0, 32.0 * nx), ax1 = fmin(x1, 32.0 * nx + 32);
                        double az0 = fmax(z0, 32.0 * nz), az1 = fmin(z1, 32.0 * nz + 32);
                        stored_bounds(s, dec, m, nx, nz, ax0, az0, ax1, az1, &b);
                    }
                size_t k = (size_t)m * ncell + (size_t)cz * s->cells_x + cx;
                s->lo[k] = float_down(b.lo);
                s->hi[k] = float_up(b.hi);
            }
    }
    free(dec);
}

void sparse_range(const sparse_masks *s, int mask, int x0, int z0, int x1,
                  int z1, double *lo, double *hi)
{
    assert(mask >= 0 && mask < s->nmasks && x0 < x1 && z0 < z1);
    const sparse_place *pl = &s->place[mask];
    int cx0 = sparse_clampi(x0 / SPARSE_TILE, 0, pl->cells_x - 1);
    int cz0 = sparse_clampi(z0 / SPARSE_TILE, 0, pl->cells_z - 1);
    int cx1 = sparse_clampi((x1 - 1) / SPARSE_TILE, 0, pl->cells_x - 1);
    int cz1 = sparse_clampi((z1 - 1) / SPARSE_TILE, 0, pl->cells_z - 1);
    size_t ncell = (size_t)s->cells_x * s->cells_z;
    bounds b = { 1.0, 0.0 };
    for (int cz = cz0; cz <= cz1; cz++)
        for (int cx = cx0; cx <= cx1; cx++) {
            size_t k = (size_t)mask * ncell + (size_t)cz * s->cells_x + cx;
            bounds_add(&b, s->lo[k]);
            bounds_add(&b, s->hi[k]);
        }
    *lo = b.lo;
    *hi = b.hi;
}

/* Heightfield texels [a0, a1) on an axis -> the mask texels [t0, t1) that
 * fragments there can read, widened for float rounding; *outside when
 * some of them lie off the mask's rectangle.  Returns false when none is
 * on it. */
static bool map_axis(double a0, double a1, int hf, double r0, double r1, int n,
                     int *t0, int *t1, bool *outside)
{
    /* the GPU's uv carries a few ulps of 1; the mapping (uv - r0) * s and
     * the multiply by n a few ulps of n: one texel covers both */
    double slop = 1.0 + 4e-6 * n / (r1 - r0);
    double m0 = (a0 / hf - r0) / (r1 - r0) * n - slop;
    double m1 = (a1 / hf - r0) / (r1 - r0) * n + slop;
    *outside |= m0 < 0.0 || m1 > n;
    if (m1 <= 0.0 || m0 >= n)
        return false;
    *t0 = m0 < 0.0 ? 0 : (int)floor(m0);
    *t1 = m1 > n ? n : (int)ceil(m1);
    if (*t1 <= *t0)
        *t1 = *t0 + 1;
    return true;
}

void sparse_range_terrain(const sparse_masks *s, int mask, int x0, int z0, int x1,
                          int z1, double *lo, double *hi)
{
    if (!sparse_placed(s, mask)) {
        sparse_range(s, mask, x0, z0, x1, z1, lo, hi);
        return;
    }
    const sparse_place *pl = &s->place[mask];
    int tx0, tx1, tz0, tz1;
    bool outside = false;
    bool on = map_axis(x0, x1, s->width, pl->rect[0], pl->rect[2], pl->width, &tx0, &tx1,
                       &outside);
    on &= map_axis(z0, z1, s->height, pl->rect[1], pl->rect[3], pl->height, &tz0, &tz1,
                   &outside);
    bounds b = { 1.0, 0.0 };
    if (on)
        sparse_range(s, mask, tx0, tz0, tx1, tz1, &b.lo, &b.hi);
    if (outside || !on)
        bounds_add(&b, 0.0);
    *lo = b.lo;
    *hi = b.hi;
}

char *sparse_glsl_places(const sparse_masks *s)
{
    bool any = false;
    for (int m = 0; m < s->nmasks; m++)
        any |= sparse_placed(s, m);
    if (!any)
        return NULL;
    ir_buf b = { 0 };
    ir_buf_printf(&b, "#define SPLAT_PAINTED_PLACED 1\n"
                      "const vec4 splat_painted_rect[%d] = vec4[%d](", s->nmasks, s->nmasks);
    for (int m = 0; m < s->nmasks; m++) {
        float r[4];
        place_floats(&s->place[m], r);
        ir_buf_printf(&b, "%svec4(%.9g, %.9g, %.9g, %.9g)", m ? ", " : "", r[0], r[1], r[2],
                      r[3]);
    }
    ir_buf_printf(&b, ");\nconst vec2 splat_painted_size[%d] = vec2[%d](", s->nmasks,
                  s->nmasks);
    for (int m = 0; m < s->nmasks; m++)
        ir_buf_printf(&b, "%svec2(%d.0, %d.0)", m ? ", " : "", s->place[m].width,
                      s->place[m].height);
    ir_buf_printf(&b, ");\n");
    return b.s;
}
