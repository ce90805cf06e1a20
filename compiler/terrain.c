/* terrain.c — the heightfield on the CPU.
 *
 * Loading (16-bit PNG, 8-bit PNG scaled by 257, raw little-endian R16), the
 * CPU twins of the ABI's GLSL height and normal functions (abi.c), and sound
 * bounds of the terrain inputs over a rectangle of texels for the interval
 * analysis (analysis.c).
 *
 * Why the bounds are sound.  A fragment whose uv lies in texels
 * [x0, x1) x [z0, z1) sits at texel coordinate x = u*W - 0.5 in
 * [x0 - 0.5, x1 - 0.5].  The shading inputs (abi.c splat_terrain_at) are
 * the uniform cubic B-spline H over the texels, whose 4 taps per axis are
 * floor(x) - 1 .. floor(x) + 2, so they read texels x0-2 .. x1+1 (the
 * rectangle plus a two-texel ring, clamped to the edges): the "footprint".
 * (The mesh's bilinear heights read x0-1 .. x1, inside it.)
 *  - Height is a convex combination of footprint texels (the B-spline's
 *    weights are >= 0 and sum to 1; it never overshoots): [min, max].
 *  - Listing 1's unnormalised normal is (a, 2, b) with
 *      a = (H(x-1) - H(x+1)) * maxh/dx,  b = (H(z-1) - H(z+1)) * maxh/dz,
 *    and because both taps share their weights, a is the same B-spline of
 *    the per-texel differences gx(i,j) = h(i-1,j) - h(i+1,j) (indices
 *    clamped *after* the +-1; gx = 0 beyond the edge), likewise b.
 *    So a and b lie in [min, max] of gx, gz over the footprint; the
 *    normalised components and slope = 1 - n.y then follow by monotonicity
 *    (normal_bounds below).
 * GPU error, so the bounds hold on real pixels (documented constants):
 *  - the GPU computes the weights in float from a float uv, so they can
 *    differ from the exact ones by a few ulps, and before the B-spline
 *    the bilinear filter's two taps differed by a step of sub-texel
 *    precision; SUBTEXEL_EPS stays as margin for both: widens gx, gz by
 *    SUBTEXEL_EPS * (largest difference of neighbouring texels);
 *  - texel conversion and filtering arithmetic: UNORM16_EPS (one 16-bit
 *    step) on gx, gz and on heights that vary; FLOAT_EPS on the normalised
 *    normal and slope, and times the magnitudes involved on heights
 *    (max_height + |offset|) and positions (the world size).
 * Painted masks (analysis.c) are convex combinations of 8-bit texels and
 * are not widened when constant, so an all-0 / all-1 area stays exact.
 */
#include "terrain.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <stb_image.h>

#include "abi.h"
#include "util.h"

#define SUBTEXEL_EPS (1.0 / 256.0 + 1.0 / 4096.0)
#define UNORM16_EPS  (1.0 / 65536.0)
#define FLOAT_EPS    2e-6

/* ---- loading ------------------------------------------------------------ */

bool splat_image_info(FILE *f, long long *w, long long *h, int *comp, bool *is16)
{
    int iw, ih, ic;
    *w = *h = 0;
    *comp = 0;
    *is16 = false;
    if (stbi_info_from_file(f, &iw, &ih, &ic)) {
        *w = iw;
        *h = ih;
        *comp = ic;
        *is16 = stbi_is_16_bit_from_file(f) != 0;
        return true;
    }
    /* PNG signature, IHDR length 13 and type, then width, height (big-endian) */
    static const uint8_t sig[16] = { 0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n',
                                     0, 0, 0, 13, 'I', 'H', 'D', 'R' };
    uint8_t head[24];
    long pos = ftell(f);
    size_t got = fread(head, 1, sizeof head, f);
    fseek(f, pos, SEEK_SET);
    if (got != sizeof head || memcmp(head, sig, sizeof sig) != 0)
        return false;
    *w = (long long)head[16] << 24 | head[17] << 16 | head[18] << 8 | head[19];
    *h = (long long)head[20] << 24 | head[21] << 16 | head[22] << 8 | head[23];
    return true;
}

FILE *splat_png_open(const char *what, const char *path, int *w, int *h, int *comp,
                     bool *is16, sg_loc loc, sg_diags *d)
{
    char why[256];
    FILE *f = splat_input_fopen(path, SPLAT_MAX_IMAGE_BYTES, why, sizeof why);
    if (!f) {
        sg_error(d, loc, SG_E_IO, path, why);
        return NULL;
    }
    long long lw, lh;
    if (!splat_image_info(f, &lw, &lh, comp, is16)) {
        fclose(f);
        sg_error(d, loc, SG_E_IO, path, "not a PNG image");
        return NULL;
    }
    if (!splat_raster_check_size(what, path, lw, lh, loc, d)) {
        fclose(f);
        return NULL;
    }
    *w = (int)lw;
    *h = (int)lh;
    return f;
}

static bool load_png(splat_terrain *t, const char *path, sg_loc loc, sg_diags *d)
{
    int w, h, comp;
    bool is16;
    FILE *f = splat_png_open("heightfield", path, &w, &h, &comp, &is16, loc, d);
    if (!f)
        return false;
    if (comp != 1) {
        fclose(f);
        char msg[256];
        snprintf(msg, sizeof msg, "heightfield '%s' has %d channels; expected a "
                 "greyscale image (1 channel, 8 or 16 bits)", path, comp);
        sg_error(d, loc, SG_E_RASTER, msg);
        return false;
    }
    size_t n = (size_t)w * (size_t)h;
    t->texels = malloc(n * sizeof *t->texels);
    if (!t->texels) {
        fclose(f);
        sg_error(d, loc, SG_E_OUT_OF_MEMORY, "heightfield does not fit in memory");
        return false;
    }
    int lw, lh, lc;
    if (is16) {
        stbi_us *px = stbi_load_from_file_16(f, &lw, &lh, &lc, 1);
        if (!px || lw != w || lh != h) { stbi_image_free(px); goto fail; }
        memcpy(t->texels, px, n * sizeof *t->texels);
        stbi_image_free(px);
    } else {
        stbi_uc *px = stbi_load_from_file(f, &lw, &lh, &lc, 1);
        if (!px || lw != w || lh != h) { stbi_image_free(px); goto fail; }
        for (size_t i = 0; i < n; i++)
            t->texels[i] = (uint16_t)(px[i] * 257u);   /* 255 -> 65535 */
        stbi_image_free(px);
    }
    fclose(f);
    t->width = w;
    t->height = h;
    return true;
fail:
    fclose(f);
    {
        /* the header read, the data did not */
        char msg[160];
        snprintf(msg, sizeof msg, "truncated or corrupt PNG (stb_image: %s)",
                 stbi_failure_reason());
        sg_error(d, loc, SG_E_IO, path, msg);
    }
    free(t->texels);
    t->texels = NULL;
    return false;
}

static bool load_r16(splat_terrain *t, const char *path, int w, int h,
                     sg_loc loc, sg_diags *d)
{
    char msg[512];
    if (w <= 0 || h <= 0) {
        snprintf(msg, sizeof msg, "raw heightfield '%s' needs its size: "
                 "heightfield_size = WIDTH HEIGHT", path);
        sg_error(d, loc, SG_E_RASTER, msg);
        return false;
    }
    if (!splat_raster_check_size("heightfield", path, w, h, loc, d))
        return false;
    char why[256];
    unsigned long long len;
    int fd = splat_input_open(path, SPLAT_MAX_RASTER_BYTES, &len, why, sizeof why);
    if (fd < 0) {
        sg_error(d, loc, SG_E_IO, path, why);
        return false;
    }
    size_t n = (size_t)w * (size_t)h;
    if (len != n * 2) {
        snprintf(msg, sizeof msg, "raw heightfield '%s' is %llu bytes; "
                 "heightfield_size = %d %d needs %zu (16-bit little-endian)",
                 path, len, w, h, n * 2);
        sg_error(d, loc, SG_E_RASTER, msg);
        close(fd);
        return false;
    }
    uint8_t *raw = malloc(n * 2);
    t->texels = malloc(n * sizeof *t->texels);
    if (!raw || !t->texels) {
        free(raw);
        free(t->texels);
        t->texels = NULL;
        close(fd);
        sg_error(d, loc, SG_E_OUT_OF_MEMORY, "heightfield does not fit in memory");
        return false;
    }
    size_t got = 0;
    while (got < n * 2) {
        ssize_t r = read(fd, raw + got, n * 2 - got);
        if (r < 0 && errno == EINTR)
            continue;
        if (r <= 0)
            break;
        got += (size_t)r;
    }
    close(fd);
    if (got != n * 2) {
        sg_error(d, loc, SG_E_IO, path, "short read");
        free(raw);
        free(t->texels);
        t->texels = NULL;
        return false;
    }
    for (size_t i = 0; i < n; i++)
        t->texels[i] = (uint16_t)(raw[2 * i] | raw[2 * i + 1] << 8);
    free(raw);
    t->width = w;
    t->height = h;
    return true;
}

bool splat_terrain_load(splat_terrain *t, const char *path, sg_hf_format fmt,
                        int raw_width, int raw_height, sg_loc loc, sg_diags *d)
{
    /* Keep the caller's size / max_height / offset; reset the raster.  A
     * GDAL raster brings its own (size only where the caller's is 0). */
    t->texels = NULL;
    t->holes = NULL;
    t->width = t->height = 0;
    if (fmt == SG_HF_GDAL)
        return splat_raster_heightfield(t, path, t->size[0] > 0 && t->size[1] > 0,
                                        loc, d);
    if (fmt == SG_HF_R16)
        return load_r16(t, path, raw_width, raw_height, loc, d);
    return load_png(t, path, loc, d);
}

void splat_terrain_free(splat_terrain *t)
{
    free(t->texels);
    free(t->holes);
    t->texels = NULL;
    t->holes = NULL;
    t->width = t->height = 0;
}

int splat_terrain_hole(const splat_terrain *t, int x, int z)
{
    if (!t->holes) return 0;
    x = x < 0 ? 0 : x >= t->width ? t->width - 1 : x;
    z = z < 0 ? 0 : z >= t->height ? t->height - 1 : z;
    return t->holes[(size_t)z * (size_t)t->width + (size_t)x] != 0;
}

/* Breadth first from the known texels: each round, every hole texel next
 * to a known one takes the rounded mean of its known 4-neighbours (all
 * computed before any is written, so the order within a round does not
 * matter), then counts as known. */
bool splat_terrain_fill_holes(splat_terrain *t)
{
    if (!t->holes) return true;
    size_t W = (size_t)t->width, H = (size_t)t->height, n = W * H, nholes = 0;
    for (size_t i = 0; i < n; i++)
        nholes += t->holes[i] != 0;
    if (nholes == 0) return true;
    /* state: 0 known, 1 unknown hole, 2 unknown hole in the next round */
    uint8_t *state = malloc(n);
    uint32_t *cur = malloc(nholes * sizeof *cur), *nxt = malloc(nholes * sizeof *nxt);
    uint16_t *val = malloc(nholes * sizeof *val);
    if (!state || !cur || !nxt || !val) {
        free(state); free(cur); free(nxt); free(val);
        return false;
    }
    for (size_t i = 0; i < n; i++)
        state[i] = t->holes[i] ? 1 : 0;
    size_t ncur = 0;
    for (size_t z = 0; z < H; z++)
        for (size_t x = 0; x < W; x++) {
            size_t i = z * W + x;
            if (state[i] != 1) continue;
            if ((x > 0 && !state[i - 1]) || (x + 1 < W && !state[i + 1]) ||
                (z > 0 && !state[i - W]) || (z + 1 < H && !state[i + W])) {
                state[i] = 2;
                cur[ncur++] = (uint32_t)i;
            }
        }
    while (ncur > 0) {
        for (size_t k = 0; k < ncur; k++) {
            size_t i = cur[k], x = i % W, z = i / W;
            uint32_t sum = 0, cnt = 0;
            if (x > 0 && !state[i - 1]) { sum += t->texels[i - 1]; cnt++; }
            if (x + 1 < W && !state[i + 1]) { sum += t->texels[i + 1]; cnt++; }
            if (z > 0 && !state[i - W]) { sum += t->texels[i - W]; cnt++; }
            if (z + 1 < H && !state[i + W]) { sum += t->texels[i + W]; cnt++; }
            val[k] = (uint16_t)((sum + cnt / 2) / cnt);
        }
        for (size_t k = 0; k < ncur; k++) {
            t->texels[cur[k]] = val[k];
            state[cur[k]] = 0;
        }
        size_t nn = 0;
        for (size_t k = 0; k < ncur; k++) {
            size_t i = cur[k], x = i % W, z = i / W;
            size_t nb[4] = { x > 0 ? i - 1 : i, x + 1 < W ? i + 1 : i,
                             z > 0 ? i - W : i, z + 1 < H ? i + W : i };
            for (int j = 0; j < 4; j++)
                if (state[nb[j]] == 1) {
                    state[nb[j]] = 2;
                    nxt[nn++] = (uint32_t)nb[j];
                }
        }
        uint32_t *tmp = cur; cur = nxt; nxt = tmp;
        ncur = nn;
    }
    free(state); free(cur); free(nxt); free(val);
    return true;
}

/* ---- sampling: the CPU twins of abi.c ----------------------------------- */

static inline int clampi(int v, int lo, int hi)
{
    return v < lo ? lo : v > hi ? hi : v;
}

static inline double texel(const splat_terrain *t, int x, int z)
{
    x = clampi(x, 0, t->width - 1);
    z = clampi(z, 0, t->height - 1);
    return t->texels[(size_t)z * (size_t)t->width + (size_t)x] / 65535.0;
}

double splat_terrain_texel(const splat_terrain *t, int x, int z)
{
    return texel(t, x, z);
}

/* Normalised bilinear sample, clamp to edge, texel i centred at (i+0.5)/W. */
static double bilinear(const splat_terrain *t, double u, double v)
{
    double x = u * t->width - 0.5, z = v * t->height - 0.5;
    /* Far outside, every tap clamps to the edge; keep floor() in int range
     * (fmax/fmin also map NaN to the edge). */
    x = fmin(fmax(x, -1.0), (double)t->width);
    z = fmin(fmax(z, -1.0), (double)t->height);
    double fx = floor(x), fz = floor(z);
    int ix = (int)fx, iz = (int)fz;
    double ax = x - fx, az = z - fz;
    double h00 = texel(t, ix, iz), h10 = texel(t, ix + 1, iz);
    double h01 = texel(t, ix, iz + 1), h11 = texel(t, ix + 1, iz + 1);
    double top = h00 + (h10 - h00) * ax, bot = h01 + (h11 - h01) * ax;
    return top + (bot - top) * az;
}

double splat_terrain_mesh_height(const splat_terrain *t, double u, double v)
{
    return bilinear(t, u, v) * t->max_height + t->height_offset;
}

/* The uniform cubic B-spline at texel coordinate x = u*W - 0.5 (clamped
 * as bilinear() does): the first of its 4 taps, ix - 1, in *ix, and
 * their weights (abi.c splat_bspline_w). */
static void bspline(double u, int n, int *ix, double w[4])
{
    double x = fmin(fmax(u * n - 0.5, -1.0), (double)n);
    double f = floor(x), t = x - f, s = 1.0 - t, t2 = t * t, t3 = t2 * t;
    *ix = (int)f;
    w[0] = s * s * s / 6.0;
    w[1] = (3.0 * t3 - 6.0 * t2 + 4.0) / 6.0;
    w[2] = (-3.0 * t3 + 3.0 * t2 + 3.0 * t + 1.0) / 6.0;
    w[3] = t3 / 6.0;
}

/* The B-spline's value, and Listing 1's differences on it: a = H(x-1) -
 * H(x+1), b = H(z-1) - H(z+1), each the B-spline of the per-texel
 * differences (terrain.c's header; abi.c splat_terrain_at). */
static double smooth(const splat_terrain *t, double u, double v, double *a, double *b)
{
    int ix, iz;
    double wx[4], wz[4], h = 0, ga = 0, gb = 0;
    bspline(u, t->width, &ix, wx);
    bspline(v, t->height, &iz, wz);
    for (int j = 0; j < 4; j++) {
        int z = iz - 1 + j;
        double rh = 0, ra = 0, rb = 0;
        for (int i = 0; i < 4; i++) {
            int x = ix - 1 + i;
            rh += wx[i] * texel(t, x, z);
            ra += wx[i] * (texel(t, x - 1, z) - texel(t, x + 1, z));
            rb += wx[i] * (texel(t, x, z - 1) - texel(t, x, z + 1));
        }
        h += wz[j] * rh;
        ga += wz[j] * ra;
        gb += wz[j] * rb;
    }
    if (a) *a = ga;
    if (b) *b = gb;
    return h;
}

double splat_terrain_height(const splat_terrain *t, double u, double v)
{
    return smooth(t, u, v, NULL, NULL) * t->max_height + t->height_offset;
}

void splat_terrain_normal(const splat_terrain *t, double u, double v, double n[3])
{
    double tx = 1.0 / t->width, tz = 1.0 / t->height, a, b;
    smooth(t, u, v, &a, &b);
    splat_normal_filter(a, 0.0, b, 0.0, t->max_height, t->size[0] * tx, t->size[1] * tz, n);
}

double splat_terrain_cavity(const splat_terrain *t, double u, double v)
{
    double tx = 2.0 / t->width, tz = 2.0 / t->height;
    double s = bilinear(t, u - tx, v - tz) + bilinear(t, u + tx, v + tz) +
               bilinear(t, u + tx, v - tz) + bilinear(t, u - tx, v + tz);
    return (0.25 * s - bilinear(t, u, v)) * t->max_height;
}

/* ---- ranges ------------------------------------------------------------- */

static inline ir_iv iv(double lo, double hi) { return (ir_iv){ lo, hi }; }

/* Smallest and largest square of a value in [lo, hi]. */
static double sq_min(double lo, double hi)
{
    if (lo <= 0 && hi >= 0) return 0;
    return fmin(lo * lo, hi * hi);
}
static double sq_max(double lo, double hi) { return fmax(lo * lo, hi * hi); }

/* a / sqrt(a^2 + 4 + b2), the normalised x (or z) component. */
static double ncomp(double a, double b2)
{
    if (isinf(a)) return copysign(1.0, a);
    if (isinf(b2)) return 0.0;
    return a / sqrt(a * a + 4.0 + b2);
}

/* Bounds of normalize(a, 2, b) for a in A, b in B, and of 1 - n.y.
 * n.x grows with a and shrinks in magnitude as b^2 grows, so its extremes
 * are at a's ends with b^2 at whichever end pulls towards them; n.y is
 * 2 / |(a, 2, b)|, extreme at the extremes of a^2 + b^2. */
static void normal_bounds(ir_iv A, ir_iv B, ir_iv n[3], ir_iv *slope)
{
    double a2lo = sq_min(A.lo, A.hi), a2hi = sq_max(A.lo, A.hi);
    double b2lo = sq_min(B.lo, B.hi), b2hi = sq_max(B.lo, B.hi);
    n[0].hi = ncomp(A.hi, A.hi >= 0 ? b2lo : b2hi);
    n[0].lo = ncomp(A.lo, A.lo <= 0 ? b2lo : b2hi);
    n[2].hi = ncomp(B.hi, B.hi >= 0 ? a2lo : a2hi);
    n[2].lo = ncomp(B.lo, B.lo <= 0 ? a2lo : a2hi);
    double big = a2hi + b2hi, small = a2lo + b2lo;
    n[1].lo = isinf(big) ? 0.0 : 2.0 / sqrt(4.0 + big);
    n[1].hi = 2.0 / sqrt(4.0 + small);
    for (int c = 0; c < 3; c++) {
        n[c].lo -= FLOAT_EPS;
        n[c].hi += FLOAT_EPS;
    }
    *slope = iv(1.0 - n[1].hi, 1.0 - n[1].lo);
}

/* Metres per normalised height unit over metres per texel, per axis. */
static void gradient_scale(const splat_terrain *t, double *kx, double *kz)
{
    *kx = t->max_height / (t->size[0] / t->width);
    *kz = t->max_height / (t->size[1] / t->height);
}

void splat_terrain_ranges(const splat_terrain *t, int x0, int z0, int x1, int z1,
                          ir_ienv *out)
{
    ir_ienv_domain(out);   /* inputs the heightfield does not bound below */
    x0 = clampi(x0, 0, t->width - 1);
    z0 = clampi(z0, 0, t->height - 1);
    x1 = clampi(x1, x0 + 1, t->width);
    z1 = clampi(z1, z0 + 1, t->height);

    const uint16_t *h = t->texels;
    size_t W = (size_t)t->width;
    int hmin = 65535, hmax = 0;            /* footprint heights, raw units */
    int gxmin = 65535, gxmax = -65535;     /* h(i-1) - h(i+1)              */
    int gzmin = 65535, gzmax = -65535;
    int step = 0;                          /* largest neighbour difference */
    for (int j = z0 - 2; j <= z1 + 1; j++) {
        size_t row = (size_t)clampi(j, 0, t->height - 1) * W;
        size_t rowd = (size_t)clampi(j - 1, 0, t->height - 1) * W;
        size_t rowu = (size_t)clampi(j + 1, 0, t->height - 1) * W;
        for (int i = x0 - 2; i <= x1 + 1; i++) {
            size_t c = (size_t)clampi(i, 0, t->width - 1);
            size_t l = (size_t)clampi(i - 1, 0, t->width - 1);
            size_t r = (size_t)clampi(i + 1, 0, t->width - 1);
            int hc = h[row + c], hl = h[row + l], hr = h[row + r];
            int hd = h[rowd + c], hu = h[rowu + c];
            if (hc < hmin) hmin = hc;
            if (hc > hmax) hmax = hc;
            int gx = hl - hr, gz = hd - hu;
            if (gx < gxmin) gxmin = gx;
            if (gx > gxmax) gxmax = gx;
            if (gz < gzmin) gzmin = gz;
            if (gz > gzmax) gzmax = gz;
            int s = abs(hc - hl);
            if (abs(hr - hc) > s) s = abs(hr - hc);
            if (abs(hc - hd) > s) s = abs(hc - hd);
            if (abs(hu - hc) > s) s = abs(hu - hc);
            if (s > step) step = s;
        }
    }

    double maxh = t->max_height, off = t->height_offset;
    double lo = hmin / 65535.0 * maxh + off, hi = hmax / 65535.0 * maxh + off;
    if (lo > hi) {                         /* negative max_height */
        double tmp = lo; lo = hi; hi = tmp;
    }
    if (hmin != hmax) {                    /* filtering arithmetic */
        lo -= UNORM16_EPS * fabs(maxh);
        hi += UNORM16_EPS * fabs(maxh);
    }
    /* texel * max_height + offset in float: the error scales with both. */
    double eh = FLOAT_EPS * (fabs(maxh) + fabs(off));
    out->height = iv(lo - eh, hi + eh);

    double kx, kz;
    gradient_scale(t, &kx, &kz);
    double eg = SUBTEXEL_EPS * step / 65535.0 + UNORM16_EPS;
    ir_iv A = iv((gxmin / 65535.0 - eg) * kx, (gxmax / 65535.0 + eg) * kx);
    ir_iv B = iv((gzmin / 65535.0 - eg) * kz, (gzmax / 65535.0 + eg) * kz);
    if (A.lo > A.hi) A = iv(A.hi, A.lo);
    if (B.lo > B.hi) B = iv(B.hi, B.lo);
    if (isnan(A.lo) || isnan(A.hi)) A = iv(-INFINITY, INFINITY);
    if (isnan(B.lo) || isnan(B.hi)) B = iv(-INFINITY, INFINITY);
    normal_bounds(A, B, out->normal, &out->slope);

    double u0 = (double)x0 / t->width, u1 = (double)x1 / t->width;
    double v0 = (double)z0 / t->height, v1 = (double)z1 / t->height;
    out->uv[0] = iv(u0 - FLOAT_EPS, u1 + FLOAT_EPS);
    out->uv[1] = iv(v0 - FLOAT_EPS, v1 + FLOAT_EPS);
    double ex = FLOAT_EPS * fabs(t->size[0]), ez = FLOAT_EPS * fabs(t->size[1]);
    out->position[0] = iv(u0 * t->size[0] - ex, u1 * t->size[0] + ex);
    out->position[1] = out->height;
    out->position[2] = iv(v0 * t->size[1] - ez, v1 * t->size[1] + ez);
    out->destruction = iv(0.0, 0.0);    /* scene.h: undamaged at build time */
}

void splat_terrain_any_shape(const splat_terrain *t, ir_ienv *env)
{
    /* Any heightfield: neighbour differences span [-1, 1]; heights only go
     * down, to texel value 0. */
    double kx, kz;
    gradient_scale(t, &kx, &kz);
    ir_iv A = iv(-fabs(kx), fabs(kx)), B = iv(-fabs(kz), fabs(kz));
    if (isnan(kx)) A = iv(-INFINITY, INFINITY);
    if (isnan(kz)) B = iv(-INFINITY, INFINITY);
    normal_bounds(A, B, env->normal, &env->slope);
    double floor_h = t->max_height >= 0 ? t->height_offset
                                        : t->height_offset + t->max_height;
    double eh = FLOAT_EPS * (fabs(t->max_height) + fabs(t->height_offset));
    if (floor_h - eh < env->height.lo)
        env->height.lo = floor_h - eh;
    env->position[1] = env->height;
}
