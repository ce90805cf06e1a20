/* sparse.c — painted masks as sparse quad-tree textures (see sparse.h for
 * the layout).
 *
 * The build, per mask:
 *   1. reduced rasters D_L for L = 1..max_level (rounded block means);
 *   2. cells whose level-0 slot is all 0 or all 255 are constants;
 *   3. quad-tree levels, coarse to fine: an aligned block of 2^L x 2^L
 *      cells outside the `near` rect, with at least two non-constant cells,
 *      goes to level L if the exact max error of sampling D_L instead of
 *      the raster over its non-constant cells is within max_error (the
 *      error is exact because the difference of two bilinear interpolants
 *      is bilinear between the union of both grids' texel centres, which
 *      all lie on the half-texel lattice we evaluate);
 *   4. every non-constant cell's padded slot is hashed (XXH3) and stored
 *      once across all masks, in order of first use (deterministic);
 * then the atlas is laid out and encoded (R8 or BC4), and each cell's
 * bounds are taken from what the GPU and the CPU reference can read.
 *
 * Example: a 64 x 32 raster, all 0 but a soft disc in x 40..60:
 *   cells (0,0) -> index 0 (constant 0); cell (1,0) -> slot 0 (index 1);
 *   atlas 1 x 1 slots = 36 x 36 texels.
 */
#include "sparse.h"
#include "ir.h"
#include "util.h"

#include <assert.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <xxhash.h>

#include <stb_image.h>

const char SPLAT_GLSL_SPARSE[] = SPARSE_GLSL_FUNCTIONS;

enum { SLOT_TEXELS = SPARSE_SLOT * SPARSE_SLOT };

static const char *const error_formats[SPARSE_E_COUNT] = {
#define X(id, fmt) fmt,
    SPARSE_ERRORS(X)
#undef X
};

static bool fail(sparse_error *err, sparse_error_id id, ...)
{
    if (err) {
        va_list ap;
        va_start(ap, id);
        err->id = id;
        vsnprintf(err->msg, sizeof err->msg, error_formats[id], ap);
        va_end(ap);
    }
    return false;
}

static int clampi(int v, int lo, int hi)
{
    return v < lo ? lo : v > hi ? hi : v;
}

/* ---- rasters and bilinear sampling ------------------------------------- */

typedef struct raster {
    int w, h;
    const uint8_t *t;
} raster;

static int texel(const raster *r, int x, int z)
{
    return r->t[(size_t)clampi(z, 0, r->h - 1) * (size_t)r->w + (size_t)clampi(x, 0, r->w - 1)];
}

/* Bilinear with clamp to edge at raster position (x, z), in texel units
 * where texel i has its centre at i + 0.5. */
static double bilinear(const raster *r, double x, double z)
{
    double px = x - 0.5, pz = z - 0.5;
    double fx = floor(px), fz = floor(pz);
    int ix = (int)fx, iz = (int)fz;
    double ax = px - fx, az = pz - fz;
    double a = texel(r, ix, iz), b = texel(r, ix + 1, iz);
    double c = texel(r, ix, iz + 1), d = texel(r, ix + 1, iz + 1);
    double top = a + (b - a) * ax, bot = c + (d - c) * ax;
    return (top + (bot - top) * az) / 255.0;
}

double sparse_raster_bilinear(const uint8_t *texels, int width, int height,
                              double u, double v)
{
    raster r = { width, height, texels };
    return bilinear(&r, u * width, v * height);
}

/* D_L: each texel the rounded mean of the in-range texels of its
 * 2^L x 2^L block of the original. */
static uint8_t *reduce(const raster *src, int level, raster *out)
{
    int s = 1 << level;
    int w = (src->w + s - 1) / s, h = (src->h + s - 1) / s;
    uint8_t *t = xcalloc((size_t)w * h, 1);
    for (int z = 0; z < h; z++)
        for (int x = 0; x < w; x++) {
            unsigned sum = 0, n = 0;
            for (int zz = z * s; zz < (z + 1) * s && zz < src->h; zz++)
                for (int xx = x * s; xx < (x + 1) * s && xx < src->w; xx++) {
                    sum += src->t[(size_t)zz * src->w + xx];
                    n++;
                }
            t[(size_t)z * w + x] = (uint8_t)((sum + n / 2) / n);
        }
    *out = (raster){ w, h, t };
    return t;
}

/* The 36 x 36 slot of block (bx, bz) of raster r: slot-local texel j in
 * -2..33 reads block texel clamp(j, -1, 32), clamped to the raster. */
static void make_slot(const raster *r, int bx, int bz, uint8_t *slot)
{
    for (int j = 0; j < SPARSE_SLOT; j++) {
        int z = SPARSE_TILE * bz + clampi(j - SPARSE_PAD, -1, SPARSE_TILE);
        for (int i = 0; i < SPARSE_SLOT; i++) {
            int x = SPARSE_TILE * bx + clampi(i - SPARSE_PAD, -1, SPARSE_TILE);
            slot[j * SPARSE_SLOT + i] = (uint8_t)texel(r, x, z);
        }
    }
}

/* 0 or 255 if every texel of the slot has that value, else -1. */
static int slot_constant(const uint8_t *slot)
{
    int v = slot[0];
    if (v != 0 && v != 255)
        return -1;
    for (int i = 1; i < SLOT_TEXELS; i++)
        if (slot[i] != v)
            return -1;
    return v;
}

/* ---- the slot store: unique slots, deduplicated by XXH3 + bytes --------- */

typedef struct slot_store {
    uint8_t  *data;      /* n * SLOT_TEXELS bytes                         */
    uint64_t *hashes;
    int       n, cap;
    int32_t  *table;     /* open addressing, -1 = empty; tcap power of 2  */
    size_t    tcap;
} slot_store;

static void store_rehash(slot_store *st, size_t tcap)
{
    free(st->table);
    st->table = xcalloc(tcap, sizeof *st->table);
    memset(st->table, 0xff, tcap * sizeof *st->table);
    st->tcap = tcap;
    for (int k = 0; k < st->n; k++) {
        size_t i = st->hashes[k] & (tcap - 1);
        while (st->table[i] >= 0)
            i = (i + 1) & (tcap - 1);
        st->table[i] = k;
    }
}

/* The index of `slot` in the store, adding it if new (*added = true). */
static int store_intern(slot_store *st, const uint8_t *slot, bool *added)
{
    if ((size_t)(st->n + 1) * 2 > st->tcap)
        store_rehash(st, st->tcap ? st->tcap * 2 : 256);
    uint64_t h = XXH3_64bits(slot, SLOT_TEXELS);
    size_t i = h & (st->tcap - 1);
    for (; st->table[i] >= 0; i = (i + 1) & (st->tcap - 1)) {
        int k = st->table[i];
        if (st->hashes[k] == h &&
            memcmp(st->data + (size_t)k * SLOT_TEXELS, slot, SLOT_TEXELS) == 0) {
            *added = false;
            return k;
        }
    }
    if (st->n == st->cap) {
        st->cap = st->cap ? st->cap * 2 : 64;
        st->data = realloc(st->data, (size_t)st->cap * SLOT_TEXELS);
        st->hashes = realloc(st->hashes, (size_t)st->cap * sizeof *st->hashes);
        if (!st->data || !st->hashes)
            abort();
    }
    memcpy(st->data + (size_t)st->n * SLOT_TEXELS, slot, SLOT_TEXELS);
    st->hashes[st->n] = h;
    st->table[i] = st->n;
    *added = true;
    return st->n++;
}

static void store_free(slot_store *st)
{
    free(st->data);
    free(st->hashes);
    free(st->table);
}

/* ---- quad-tree levels --------------------------------------------------- */

/* Exact max |D_L - original| over the bilinear samples of cell (cx, cz). */
static double cell_reduce_error(const raster *orig, const raster *red,
                                int level, int cx, int cz)
{
    double s = ldexp(1.0, level), err = 0.0;
    int x1 = SPARSE_TILE * (cx + 1) < orig->w ? SPARSE_TILE * (cx + 1) : orig->w;
    int z1 = SPARSE_TILE * (cz + 1) < orig->h ? SPARSE_TILE * (cz + 1) : orig->h;
    for (int j = 2 * SPARSE_TILE * cz; j <= 2 * z1; j++)
        for (int i = 2 * SPARSE_TILE * cx; i <= 2 * x1; i++) {
            double x = 0.5 * i, z = 0.5 * j;
            double e = fabs(bilinear(red, x / s, z / s) - bilinear(orig, x, z));
            if (e > err)
                err = e;
        }
    return err;
}

static bool rects_overlap(int ax0, int az0, int ax1, int az1, const int b[4])
{
    return ax0 < b[2] && b[0] < ax1 && az0 < b[3] && b[1] < az1;
}

/* Fill lvl[] (cells_z x cells_x, -1 = constant at level 0) for one mask. */
static void choose_levels(const sparse_mask_desc *md, const raster *red,
                          int cells_x, int cells_z, int8_t *lvl,
                          sparse_mask_info *info)
{
    for (int L = md->max_level; L >= 1; L--) {
        int n = 1 << L, span = SPARSE_TILE << L;
        for (int bz = 0; bz * n < cells_z; bz++)
            for (int bx = 0; bx * n < cells_x; bx++) {
                if (md->near[2] > md->near[0] && md->near[3] > md->near[1] &&
                    rects_overlap(bx * span, bz * span, (bx + 1) * span,
                                  (bz + 1) * span, md->near))
                    continue;
                int cz1 = (bz + 1) * n < cells_z ? (bz + 1) * n : cells_z;
                int cx1 = (bx + 1) * n < cells_x ? (bx + 1) * n : cells_x;
                int live = 0;
                bool taken = false;
                for (int cz = bz * n; cz < cz1; cz++)
                    for (int cx = bx * n; cx < cx1; cx++) {
                        int8_t l = lvl[cz * cells_x + cx];
                        live += l >= 0;
                        taken |= l > 0;
                    }
                if (taken || live < 2)
                    continue;
                double err = 0.0;
                for (int cz = bz * n; cz < cz1 && err <= md->max_error; cz++)
                    for (int cx = bx * n; cx < cx1 && err <= md->max_error; cx++)
                        if (lvl[cz * cells_x + cx] >= 0) {
                            double e = cell_reduce_error(&red[0], &red[L], L, cx, cz);
                            err = e > err ? e : err;
                        }
                if (err > md->max_error)
                    continue;
                for (int cz = bz * n; cz < cz1; cz++)
                    for (int cx = bx * n; cx < cx1; cx++)
                        if (lvl[cz * cells_x + cx] >= 0)
                            lvl[cz * cells_x + cx] = (int8_t)L;
                if (err > info->reduce_error)
                    info->reduce_error = err;
            }
    }
}

/* ---- atlas access --------------------------------------------------------- */

static size_t cell_at(const sparse_masks *s, int mask, int cx, int cz)
{
    return (((size_t)(mask / 4) * s->cells_z + cz) * s->cells_x + cx) * 4 + mask % 4;
}

/* Atlas texel (ax, az) as stored, 0..1 (BC4 decoded). */
static float atlas_texel(const sparse_masks *s, int ax, int az)
{
    ax = clampi(ax, 0, s->atlas_width - 1);
    az = clampi(az, 0, s->atlas_height - 1);
    if (s->format == SPARSE_R8)
        return s->atlas[(size_t)az * s->atlas_width + ax] / 255.0f;
    float block[16];
    size_t b = (size_t)(az / 4) * (s->atlas_width / 4) + (size_t)(ax / 4);
    sparse_bc4_decode(s->atlas + b * 8, block);
    return block[(az % 4) * 4 + ax % 4];
}

static void slot_origin(const sparse_masks *s, int slot, int *ox, int *oz)
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
    int cx = clampi((int)floorf(tx * (1.0f / 32.0f)), 0, pl->cells_x - 1);
    int cz = clampi((int)floorf(tz * (1.0f / 32.0f)), 0, pl->cells_z - 1);
    size_t at = cell_at(s, mask, cx, cz);
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
    slot_origin(s, (int)e - 1, &ox, &oz);
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
    *j0 = clampi((int)floor(qa - 0.5), -1, SPARSE_TILE);
    *j1 = clampi((int)floor(qb - 0.5) + 1, -1, SPARSE_TILE);
}

/* Values the GPU may read in cell n for raster positions in the closed
 * rectangle [tx0, tx1] x [tz0, tz1].  `dec` is the decoded atlas. */
static void stored_bounds(const sparse_masks *s, const float *dec, int mask,
                          int nx, int nz, double tx0, double tz0, double tx1,
                          double tz1, bounds *b)
{
    size_t at = cell_at(s, mask, nx, nz);
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
    slot_origin(s, (int)e - 1, &ox, &oz);
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

static void compute_bounds(sparse_masks *s, const sparse_desc *d)
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
                        int v = texel(&r, x, z);
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
    int cx0 = clampi(x0 / SPARSE_TILE, 0, pl->cells_x - 1);
    int cz0 = clampi(z0 / SPARSE_TILE, 0, pl->cells_z - 1);
    int cx1 = clampi((x1 - 1) / SPARSE_TILE, 0, pl->cells_x - 1);
    int cz1 = clampi((z1 - 1) / SPARSE_TILE, 0, pl->cells_z - 1);
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

/* ---- the build ---------------------------------------------------------- */

static void layout_atlas(sparse_masks *s, const slot_store *st)
{
    int cols = 1;
    while (cols * cols < st->n)
        cols++;
    s->nslots = st->n;
    s->atlas_cols = cols;
    s->atlas_rows = st->n > cols ? (st->n + cols - 1) / cols : 1;
    s->atlas_width = cols * SPARSE_SLOT;
    s->atlas_height = s->atlas_rows * SPARSE_SLOT;
    size_t w = (size_t)s->atlas_width, h = (size_t)s->atlas_height;
    uint8_t *r8 = xcalloc(w * h, 1);
    for (int k = 0; k < st->n; k++) {
        int ox, oz;
        slot_origin(s, k, &ox, &oz);
        for (int j = 0; j < SPARSE_SLOT; j++)
            memcpy(r8 + (size_t)(oz + j) * w + ox,
                   st->data + (size_t)k * SLOT_TEXELS + j * SPARSE_SLOT, SPARSE_SLOT);
    }
    if (s->format == SPARSE_R8) {
        s->atlas = r8;
        s->atlas_bytes = w * h;
        return;
    }
    s->atlas_bytes = w * h / 2;
    s->atlas = xcalloc(s->atlas_bytes, 1);
    for (size_t bz = 0; bz < h / 4; bz++)
        for (size_t bx = 0; bx < w / 4; bx++) {
            uint8_t in[16];
            for (int j = 0; j < 4; j++)
                memcpy(in + 4 * j, r8 + (bz * 4 + j) * w + bx * 4, 4);
            sparse_bc4_encode(s->atlas + (bz * (w / 4) + bx) * 8, in);
        }
    free(r8);
}

/* A desc's rect of all zeros means "the whole terrain". */
static bool rect_given(const double r[4])
{
    return r[0] != 0 || r[1] != 0 || r[2] != 0 || r[3] != 0;
}

/* A place's cells from its raster; the grid grown to hold them. */
static void place_cells(sparse_place *p, int *grid_x, int *grid_z)
{
    p->cells_x = (p->width + SPARSE_TILE - 1) / SPARSE_TILE;
    p->cells_z = (p->height + SPARSE_TILE - 1) / SPARSE_TILE;
    *grid_x = p->cells_x > *grid_x ? p->cells_x : *grid_x;
    *grid_z = p->cells_z > *grid_z ? p->cells_z : *grid_z;
}

static bool check_desc(const sparse_desc *d, sparse_error *err)
{
    if (d->width <= 0 || d->height <= 0 || d->nmasks < 0 ||
        (d->nmasks > 0 && !d->masks))
        return fail(err, SPARSE_E_BAD_OPTION, "(all)", "empty raster or no mask data");
    if (d->format != SPARSE_BC4 && d->format != SPARSE_R8)
        return fail(err, SPARSE_E_BAD_OPTION, "(all)", "unknown atlas format");
    for (int m = 0; m < d->nmasks; m++) {
        const sparse_mask_desc *md = &d->masks[m];
        const char *name = md->name ? md->name : "(unnamed)";
        if (!md->texels)
            return fail(err, SPARSE_E_BAD_OPTION, name, "no raster");
        if (md->max_level < 0 || md->max_level > SPARSE_MAX_LEVEL)
            return fail(err, SPARSE_E_BAD_OPTION, name,
                        "max_level must be 0..7 (the quad-tree's coarsest level)");
        if (!(md->max_error >= 0.0 && md->max_error <= 1.0))
            return fail(err, SPARSE_E_BAD_OPTION, name, "max_error must be in 0..1");
        if (md->width < 0 || md->height < 0 || (md->width > 0) != (md->height > 0) ||
            md->width > SPARSE_MAX_TEXELS || md->height > SPARSE_MAX_TEXELS)
            return fail(err, SPARSE_E_BAD_OPTION, name,
                        "a placed raster must be 1..65536 texels on each side");
        const double *r = md->rect;
        bool in_range = true;
        for (int i = 0; i < 4; i++)
            in_range &= isfinite(r[i]) && fabs(r[i]) < 1e6;
        if (rect_given(r) && !(in_range && r[2] - r[0] > 1e-9 && r[3] - r[1] > 1e-9))
            return fail(err, SPARSE_E_BAD_OPTION, name,
                        "its rectangle is empty or out of range (terrain uv within 1e6)");
    }
    return true;
}

/* Each mask's raster, rectangle and cells; the index grid the largest. */
static void set_places(sparse_masks *s, const sparse_desc *d)
{
    s->place = xcalloc((size_t)(d->nmasks ? d->nmasks : 1), sizeof *s->place);
    s->cells_x = d->nmasks ? 1 : (d->width + SPARSE_TILE - 1) / SPARSE_TILE;
    s->cells_z = d->nmasks ? 1 : (d->height + SPARSE_TILE - 1) / SPARSE_TILE;
    for (int m = 0; m < d->nmasks; m++) {
        const sparse_mask_desc *md = &d->masks[m];
        sparse_place *p = &s->place[m];
        p->width = md->width ? md->width : d->width;
        p->height = md->height ? md->height : d->height;
        static const double unit[4] = { 0, 0, 1, 1 };
        memcpy(p->rect, rect_given(md->rect) ? md->rect : unit, sizeof p->rect);
        place_cells(p, &s->cells_x, &s->cells_z);
    }
}

bool sparse_build(sparse_masks *s, const sparse_desc *d, sparse_error *err)
{
    memset(s, 0, sizeof *s);
    if (err)
        err->id = SPARSE_E_OK, err->msg[0] = 0;
    if (!check_desc(d, err))
        return false;
    s->width = d->width;
    s->height = d->height;
    s->nmasks = d->nmasks;
    s->format = d->format;
    set_places(s, d);
    s->layers = (d->nmasks + 3) / 4 > 0 ? (d->nmasks + 3) / 4 : 1;
    size_t ncell = (size_t)s->cells_x * s->cells_z;
    s->index = xcalloc(ncell * 4 * s->layers, sizeof *s->index);
    s->level = xcalloc(ncell * 4 * s->layers, 1);
    s->info = xcalloc((size_t)(d->nmasks ? d->nmasks : 1), sizeof *s->info);

    slot_store st = { 0 };
    uint8_t slot[SLOT_TEXELS];
    int8_t *lvl = xcalloc(ncell, 1);
    for (int m = 0; m < d->nmasks; m++) {
        const sparse_mask_desc *md = &d->masks[m];
        const sparse_place *pl = &s->place[m];
        int ncx = pl->cells_x, ncz = pl->cells_z;
        sparse_mask_info *info = &s->info[m];
        info->name = strdup(md->name ? md->name : "");
        info->max_level = md->max_level;
        raster red[SPARSE_MAX_LEVEL + 1];
        uint8_t *owned[SPARSE_MAX_LEVEL + 1] = { 0 };
        red[0] = (raster){ pl->width, pl->height, md->texels };
        for (int L = 1; L <= md->max_level; L++)
            owned[L] = reduce(&red[0], L, &red[L]);

        for (int cz = 0; cz < ncz; cz++)
            for (int cx = 0; cx < ncx; cx++) {
                make_slot(&red[0], cx, cz, slot);
                lvl[(size_t)cz * ncx + cx] = slot_constant(slot) >= 0 ? -1 : 0;
            }
        choose_levels(md, red, ncx, ncz, lvl, info);

        for (int cz = 0; cz < ncz; cz++)
            for (int cx = 0; cx < ncx; cx++) {
                int L = lvl[(size_t)cz * ncx + cx];
                L = L < 0 ? 0 : L;
                make_slot(&red[L], cx >> L, cz >> L, slot);
                size_t at = cell_at(s, m, cx, cz);
                int c = slot_constant(slot);
                s->level[at] = (uint8_t)L;
                if (c >= 0) {
                    s->index[at] = c ? SPARSE_CONST1 : SPARSE_CONST0;
                    s->level[at] = 0;
                    if (c) info->const1++; else info->const0++;
                    continue;
                }
                bool added;
                int k = store_intern(&st, slot, &added);
                if (k >= SPARSE_MAX_SLOTS) {
                    for (int L2 = 1; L2 <= md->max_level; L2++)
                        free(owned[L2]);
                    free(lvl);
                    store_free(&st);
                    sparse_free(s);
                    return fail(err, SPARSE_E_TOO_MANY_TILES, k + 1, (int)SPARSE_MAX_SLOTS);
                }
                s->index[at] = (uint16_t)(k + 1);
                info->stored++;
                info->reduced += L > 0;
                info->new_slots += added;
            }
        for (int L = 1; L <= md->max_level; L++)
            free(owned[L]);
    }
    free(lvl);
    layout_atlas(s, &st);
    store_free(&st);
    compute_bounds(s, d);
    return true;
}

void sparse_free(sparse_masks *s)
{
    if (s->info)
        for (int m = 0; m < s->nmasks; m++)
            free(s->info[m].name);
    free(s->info);
    free(s->index);
    free(s->level);
    free(s->atlas);
    free(s->lo);
    free(s->hi);
    free(s->place);
    memset(s, 0, sizeof *s);
}

/* ---- memory report ------------------------------------------------------ */

void sparse_get_stats(const sparse_masks *s, sparse_stats *st)
{
    memset(st, 0, sizeof *st);
    size_t ncell = (size_t)s->cells_x * s->cells_z;
    size_t aw = (size_t)s->atlas_width, ah = (size_t)s->atlas_height;
    st->nmasks = s->nmasks;
    st->cells = (int)ncell;
    st->nslots = s->nslots;
    for (int m = 0; m < s->nmasks; m++)
        st->dense_bytes += (size_t)s->place[m].width * s->place[m].height;
    st->index_bytes = ncell * 4 * s->layers * sizeof *s->index;
    st->level_bytes = ncell * 4 * s->layers;
    st->atlas_bytes = s->atlas_bytes;
    st->atlas_r8 = aw * ah;
    st->atlas_bc4 = aw * ah / 2;
    st->total_bytes = st->index_bytes + st->level_bytes + st->atlas_bytes;
    for (int m = 0; m < s->nmasks && s->info; m++) {
        st->const_cells += s->info[m].const0 + s->info[m].const1;
        st->stored_cells += s->info[m].stored;
        st->reduced_cells += s->info[m].reduced;
    }
    st->fraction = st->dense_bytes ? (double)st->total_bytes / st->dense_bytes : 0.0;
}

void sparse_print_stats(const sparse_masks *s, FILE *out)
{
    sparse_stats st;
    sparse_get_stats(s, &st);
    const char *fmt = s->format == SPARSE_BC4 ? "BC4" : "R8";
    fprintf(out, "painted masks: %d on %dx%d texels, %dx%d cells of %d, "
            "%s atlas %dx%d slots (%dx%d texels)\n",
            s->nmasks, s->width, s->height, s->cells_x, s->cells_z, SPARSE_TILE,
            fmt, s->atlas_cols, s->atlas_rows, s->atlas_width, s->atlas_height);
    fprintf(out, "  %-16s %5s %7s %7s %7s %7s %9s %10s\n", "mask", "level",
            "const0", "const1", "stored", "reduced", "new slots", "reduce err");
    for (int m = 0; m < s->nmasks && s->info; m++) {
        const sparse_mask_info *i = &s->info[m];
        fprintf(out, "  %-16s %5d %7d %7d %7d %7d %9d %10.5f\n", i->name,
                i->max_level, i->const0, i->const1, i->stored, i->reduced,
                i->new_slots, i->reduce_error);
        const sparse_place *p = &s->place[m];
        if (sparse_placed(s, m))
            fprintf(out, "  %-16s placed: %dx%d texels over terrain uv %.6g %.6g .. "
                    "%.6g %.6g\n", "", p->width, p->height, p->rect[0], p->rect[1],
                    p->rect[2], p->rect[3]);
    }
    fprintf(out, "  dense 8-bit        %12zu B\n", st.dense_bytes);
    fprintf(out, "  index (RGBA16UI)   %12zu B\n", st.index_bytes);
    fprintf(out, "  level (RGBA8UI)    %12zu B\n", st.level_bytes);
    fprintf(out, "  atlas (%-3s)        %12zu B   (R8 %zu B, BC4 %zu B)\n", fmt,
            st.atlas_bytes, st.atlas_r8, st.atlas_bc4);
    fprintf(out, "  sparse total       %12zu B = %.2f %% of dense (%d unique slots, "
            "%d of %d cells constant)\n", st.total_bytes, 100.0 * st.fraction,
            st.nslots, st.const_cells, st.cells * st.nmasks);
}

/* ---- rasters from files --------------------------------------------------- */

bool sparse_load_raster(const char *path, int width, int height,
                        uint8_t **texels, sparse_error *err)
{
    *texels = NULL;
    int w, h, comp;
    char why[256];
    FILE *f = splat_input_fopen(path, SPLAT_MAX_IMAGE_BYTES, why, sizeof why);
    if (!f)
        return fail(err, SPARSE_E_IO, path, why);
    if (!stbi_info_from_file(f, &w, &h, &comp)) {
        fclose(f);
        return fail(err, SPARSE_E_IO, path, stbi_failure_reason());
    }
    bool is16 = stbi_is_16_bit_from_file(f);
    if (comp != 1) {
        fclose(f);
        return fail(err, SPARSE_E_BAD_CHANNELS, path, comp);
    }
    if (is16) {
        fclose(f);
        return fail(err, SPARSE_E_BAD_DEPTH, path);
    }
    if (w != width || h != height) {
        fclose(f);
        return fail(err, SPARSE_E_BAD_SIZE, path, w, h, width, height);
    }
    uint8_t *t = stbi_load_from_file(f, &w, &h, &comp, 1);
    fclose(f);
    if (!t) {
        /* the header read, the data did not */
        char why[160];
        snprintf(why, sizeof why, "truncated or corrupt PNG (stb_image: %s)",
                 stbi_failure_reason());
        return fail(err, SPARSE_E_IO, path, why);
    }
    /* copy into a malloc'd buffer the caller frees with free() */
    *texels = xcalloc((size_t)w * h, 1);
    memcpy(*texels, t, (size_t)w * h);
    stbi_image_free(t);
    return true;
}

/* ---- pack file ------------------------------------------------------------ */

static const char file_magic[8] = { 'S', 'P', 'L', 'A', 'T', 'S', 'P', 'M' };
enum { FILE_VERSION = 2, FILE_HEADER_WORDS = 11, PLACE_BYTES = 8 + 4 * 8 };

static void put_u32(uint8_t *p, uint32_t v)
{
    for (int i = 0; i < 4; i++)
        p[i] = (uint8_t)(v >> (8 * i));
}

static uint32_t get_u32(const uint8_t *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

static bool write_floats(const float *v, size_t n, FILE *f)
{
    uint8_t b[4];
    for (size_t i = 0; i < n; i++) {
        uint32_t u;
        memcpy(&u, &v[i], 4);
        put_u32(b, u);
        if (fwrite(b, 1, 4, f) != 4)
            return false;
    }
    return true;
}

bool sparse_write(const sparse_masks *s, FILE *f)
{
    uint8_t hdr[8 + 4 * FILE_HEADER_WORDS];
    uint32_t words[FILE_HEADER_WORDS] = {
        FILE_VERSION, (uint32_t)s->width, (uint32_t)s->height, (uint32_t)s->nmasks,
        (uint32_t)s->format, (uint32_t)s->cells_x, (uint32_t)s->cells_z,
        (uint32_t)s->layers, (uint32_t)s->nslots, (uint32_t)s->atlas_cols,
        (uint32_t)s->atlas_rows,
    };
    memcpy(hdr, file_magic, 8);
    for (int i = 0; i < FILE_HEADER_WORDS; i++)
        put_u32(hdr + 8 + 4 * i, words[i]);
    if (fwrite(hdr, 1, sizeof hdr, f) != sizeof hdr)
        return false;
    for (int m = 0; m < s->nmasks; m++) {
        uint8_t b[PLACE_BYTES];
        put_u32(b, (uint32_t)s->place[m].width);
        put_u32(b + 4, (uint32_t)s->place[m].height);
        for (int i = 0; i < 4; i++) {
            uint64_t u;
            memcpy(&u, &s->place[m].rect[i], 8);
            put_u32(b + 8 + 8 * i, (uint32_t)u);
            put_u32(b + 12 + 8 * i, (uint32_t)(u >> 32));
        }
        if (fwrite(b, 1, sizeof b, f) != sizeof b)
            return false;
    }
    size_t n = (size_t)s->cells_x * s->cells_z * 4 * s->layers;
    for (size_t i = 0; i < n; i++) {
        uint8_t b[2] = { (uint8_t)s->index[i], (uint8_t)(s->index[i] >> 8) };
        if (fwrite(b, 1, 2, f) != 2)
            return false;
    }
    size_t ncell = (size_t)s->cells_x * s->cells_z * s->nmasks;
    return fwrite(s->level, 1, n, f) == n &&
           fwrite(s->atlas, 1, s->atlas_bytes, f) == s->atlas_bytes &&
           write_floats(s->lo, ncell, f) && write_floats(s->hi, ncell, f);
}

/* The masks' places after the header: each raster 1..SPARSE_MAX_TEXELS
 * texels a side, its rectangle non-empty and finite, the index grid the
 * largest mask's cells (the heightfield's with no mask).  s->place is set
 * (and owned by s) when true. */
static bool read_places(sparse_masks *s, const uint8_t *at)
{
    int cx = s->nmasks ? 1 : (s->width + 31) / 32, cz = s->nmasks ? 1 : (s->height + 31) / 32;
    sparse_place *pl = calloc((size_t)(s->nmasks ? s->nmasks : 1), sizeof *pl);
    if (!pl)
        return false;
    for (int m = 0; m < s->nmasks; m++, at += PLACE_BYTES) {
        sparse_place *p = &pl[m];
        uint32_t w = get_u32(at), h = get_u32(at + 4);
        bool ok = w >= 1 && w <= SPARSE_MAX_TEXELS && h >= 1 && h <= SPARSE_MAX_TEXELS;
        for (int i = 0; i < 4; i++) {
            uint64_t u = (uint64_t)get_u32(at + 8 + 8 * i) |
                         (uint64_t)get_u32(at + 12 + 8 * i) << 32;
            memcpy(&p->rect[i], &u, 8);
            ok = ok && isfinite(p->rect[i]) && fabs(p->rect[i]) < 1e6;
        }
        if (!ok || !(p->rect[2] - p->rect[0] > 1e-9 && p->rect[3] - p->rect[1] > 1e-9)) {
            free(pl);
            return false;
        }
        p->width = (int)w;
        p->height = (int)h;
        place_cells(p, &cx, &cz);
    }
    if (cx != s->cells_x || cz != s->cells_z) {
        free(pl);
        return false;
    }
    s->place = pl;
    return true;
}

/* The header's words, checked, then the file's size against what they
 * describe, before anything is allocated: a forged header can neither
 * make the reader allocate more than the file holds nor read past it. */
bool sparse_read(sparse_masks *s, const uint8_t *data, size_t size, const char *name,
                 sparse_error *err)
{
    memset(s, 0, sizeof *s);
    enum { HDR = 8 + 4 * FILE_HEADER_WORDS };
    if (size < HDR || memcmp(data, file_magic, 8) != 0)
        return fail(err, SPARSE_E_BAD_FILE, name, "bad header");
    uint32_t w[FILE_HEADER_WORDS];
    for (int i = 0; i < FILE_HEADER_WORDS; i++)
        w[i] = get_u32(data + 8 + 4 * i);
    if (w[0] != FILE_VERSION)
        return fail(err, SPARSE_E_BAD_FILE, name, "unsupported version");
    /* every word bounded before any arithmetic on it */
    for (int i = 1; i < FILE_HEADER_WORDS; i++)
        if (w[i] > 65536)
            return fail(err, SPARSE_E_BAD_FILE, name, "inconsistent header (a field over 65536)");
    s->width = (int)w[1];
    s->height = (int)w[2];
    s->nmasks = (int)w[3];
    s->format = (sparse_format)w[4];
    s->cells_x = (int)w[5];
    s->cells_z = (int)w[6];
    s->layers = (int)w[7];
    s->nslots = (int)w[8];
    s->atlas_cols = (int)w[9];
    s->atlas_rows = (int)w[10];
    /* the header must describe a consistent, reasonably sized object */
    if (s->width <= 0 || s->height <= 0 || s->nmasks > 4096 ||
        size < HDR + (size_t)s->nmasks * PLACE_BYTES || !read_places(s, data + HDR) ||
        (s->format != SPARSE_R8 && s->format != SPARSE_BC4) ||
        s->layers != ((s->nmasks + 3) / 4 > 0 ? (s->nmasks + 3) / 4 : 1) ||
        s->nslots > SPARSE_MAX_SLOTS || s->atlas_cols <= 0 ||
        s->atlas_cols > 256 || s->atlas_rows <= 0 || s->atlas_rows > 256 ||
        s->atlas_cols * s->atlas_rows < s->nslots) {
        free(s->place);
        memset(s, 0, sizeof *s);
        return fail(err, SPARSE_E_BAD_FILE, name, "inconsistent header");
    }
    s->atlas_width = s->atlas_cols * SPARSE_SLOT;
    s->atlas_height = s->atlas_rows * SPARSE_SLOT;
    s->atlas_bytes = (size_t)s->atlas_width * s->atlas_height /
                     (s->format == SPARSE_BC4 ? 2 : 1);
    size_t n = (size_t)s->cells_x * s->cells_z * 4 * s->layers;
    size_t ncell = (size_t)s->cells_x * s->cells_z * s->nmasks;
    /* all sizes < 2^48 here (each factor <= 65536 or a small constant) */
    size_t want = HDR + (size_t)s->nmasks * PLACE_BYTES + n * 2 + n + s->atlas_bytes +
                  ncell * 8;
    if (size != want) {
        char what[160];
        snprintf(what, sizeof what, "%s: the header describes %zu bytes, the file has %zu",
                 size < want ? "truncated" : "trailing bytes", want, size);
        free(s->place);
        memset(s, 0, sizeof *s);
        return fail(err, SPARSE_E_BAD_FILE, name, what);
    }
    s->index = calloc(n ? n : 1, sizeof *s->index);
    s->level = calloc(n ? n : 1, 1);
    s->atlas = calloc(s->atlas_bytes ? s->atlas_bytes : 1, 1);
    s->lo = calloc(ncell ? ncell : 1, sizeof *s->lo);
    s->hi = calloc(ncell ? ncell : 1, sizeof *s->hi);
    if (!s->index || !s->level || !s->atlas || !s->lo || !s->hi) {
        sparse_free(s);
        return fail(err, SPARSE_E_BAD_FILE, name, "does not fit in memory");
    }
    const uint8_t *at = data + HDR + (size_t)s->nmasks * PLACE_BYTES;
    bool ok = true;
    for (size_t i = 0; i < n; i++, at += 2) {
        s->index[i] = (uint16_t)(at[0] | at[1] << 8);
        ok = ok && (s->index[i] == SPARSE_CONST1 || s->index[i] <= (unsigned)s->nslots);
    }
    memcpy(s->level, at, n);
    at += n;
    for (size_t i = 0; i < n; i++)
        ok = ok && s->level[i] <= SPARSE_MAX_LEVEL;
    memcpy(s->atlas, at, s->atlas_bytes);
    at += s->atlas_bytes;
    for (size_t i = 0; i < 2 * ncell; i++, at += 4) {
        uint32_t u = get_u32(at);
        memcpy(i < ncell ? &s->lo[i] : &s->hi[i - ncell], &u, 4);
    }
    if (!ok) {
        sparse_free(s);
        return fail(err, SPARSE_E_BAD_FILE, name, "index or level out of range");
    }
    return true;
}
