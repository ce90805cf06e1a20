/* texgen_surfaces.c — colour PBR ground surfaces for the example materials:
 * grass, dry grass, dirt, mud, sand, gravel, rock, cliff rock, snow, moss,
 * forest floor and asphalt, each an albedo / normal / height / roughness /
 * ambient-occlusion set (texgen.h), and the swatch sheet docs/textures.png.
 *
 * How: each surface is a recipe, a function of the unit coordinates (u, v)
 * that returns a height, a linear albedo and a roughness.  The recipes use
 * only periodic fields (texgen_fbm, and the cellular `cells` and stroke
 * `scatter` fields below, whose lattices wrap with an integer period), so
 * every image tiles.  Then, per surface:
 *   - the albedo is scaled so that its mean linear luminance (Rec. 709) is
 *     the surface's target, inside its measured range (table below), and
 *     encoded to sRGB;
 *   - the height is stretched to 0..1;
 *   - the normal is the height's central differences (wrapping), the height
 *     taken as `depth` texels of relief at 256 texels (scaled with the size
 *     so that a feature keeps its slope);
 *   - the ambient occlusion is 1 - the mean sine of the horizon angle in 8
 *     directions, marched over 1..16 texels (at 256) of the same relief.
 *
 * The albedo image carries the height in its alpha channel (linear: an
 * sRGB sampler decodes only the colour), so that a material reads colour
 * and height in one sample and one texture binding; the height image is the
 * same values on their own.
 *
 * Albedo ranges (broadband surface albedo, 0..1).  Sources:
 *   [W]  Wikipedia, "Albedo", table of typical albedos (fresh asphalt 0.04,
 *        worn asphalt 0.12, conifer forest 0.08-0.15, bare soil 0.17, green
 *        grass 0.25, desert sand 0.40, fresh snow 0.80-0.90);
 *   [O]  T. R. Oke, Boundary Layer Climates, 2nd ed. (1987), Table 1.1
 *        (soils dark wet 0.05 .. light dry 0.40; grass long 0.16 .. short
 *        0.26; deserts 0.20-0.45; coniferous forest 0.05-0.15; tundra
 *        0.18-0.25; fresh snow 0.80-0.95; asphalt 0.05-0.20);
 *   [D]  the DONTNOD / Unreal "physically based albedo" charts used by PBR
 *        artists (dark soil ~0.08-0.13, dry clay/rock 0.15-0.35, fresh
 *        snow 0.85, asphalt 0.04-0.12 linear).
 * A texture is seen in visible light while the broadband figures include
 * the near infrared, where vegetation is bright, so the targets for the
 * plant surfaces sit at the low end of their ranges.
 *
 *   surface       range        target  source
 *   grass         0.15-0.26    0.16    [O] grass, [W] green grass 0.25
 *   dry_grass     0.25-0.35    0.27    [O] short dry grass/steppe, [W]
 *   dirt          0.10-0.25    0.15    [W] bare soil 0.17, [O] soils
 *   mud           0.05-0.12    0.08    [O] dark wet soil 0.05, [D]
 *   sand          0.30-0.45    0.36    [W] desert sand 0.40, [O] deserts
 *   gravel        0.15-0.30    0.20    [D] dry rock, [O] light dry soil
 *   rock          0.12-0.30    0.19    [D] dry rock (granite, limestone)
 *   cliff_rock    0.12-0.30    0.18    [D] sandstone/granite faces
 *   snow          0.80-0.90    0.84    [W] fresh snow, [O]
 *   moss          0.08-0.18    0.11    [O] tundra 0.18-0.25 (visible lower)
 *   forest_floor  0.05-0.15    0.09    [O],[W] coniferous forest
 *   asphalt       0.05-0.12    0.08    [W] fresh 0.04 .. worn 0.12, [O]
 */
#include "texgen.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static const double TAU = 6.28318530717958647692;

/* ---- small helpers ----------------------------------------------------- */

typedef struct rgb { double r, g, b; } rgb;

static double clamp01(double x) { return x < 0 ? 0 : x > 1 ? 1 : x; }
static double smooth(double e0, double e1, double x)
{
    double t = clamp01((x - e0) / (e1 - e0));
    return t * t * (3 - 2 * t);
}
static double mixd(double a, double b, double t) { return a + (b - a) * t; }
static rgb mixc(rgb a, rgb b, double t)
{
    return (rgb){mixd(a.r, b.r, t), mixd(a.g, b.g, t), mixd(a.b, b.b, t)};
}
static rgb scalec(rgb a, double k) { return (rgb){a.r * k, a.g * k, a.b * k}; }

static double srgb_to_linear(double c)
{
    return c <= 0.04045 ? c / 12.92 : pow((c + 0.055) / 1.055, 2.4);
}
static double linear_to_srgb(double c)
{
    c = clamp01(c);
    return c <= 0.0031308 ? c * 12.92 : 1.055 * pow(c, 1 / 2.4) - 0.055;
}
/* A colour written as sRGB hex (what an artist picks), in linear. */
static rgb hex(unsigned x)
{
    return (rgb){srgb_to_linear(((x >> 16) & 255) / 255.0),
                 srgb_to_linear(((x >> 8) & 255) / 255.0),
                 srgb_to_linear((x & 255) / 255.0)};
}
static double luma(rgb c) { return 0.2126 * c.r + 0.7152 * c.g + 0.0722 * c.b; }

static int wrapi(int i, int p)
{
    int r = i % p;
    return r < 0 ? r + p : r;
}
/* A hash of a lattice point to [0, 1). */
static double rnd(int x, int y, uint32_t seed)
{
    return (double)(texgen_hash(x, y, seed) >> 8) / 16777216.0;
}
/* Tileable fBm mapped to about [0, 1]: `p` cells across. */
static double n01(double u, double v, int p, int octaves, uint32_t seed)
{
    return clamp01(0.5 + 0.9 * texgen_fbm(u * p, v * p, p, p, octaves, 0.5, seed));
}

/* Cellular field, `period` cells across, feature points jittered in their
 * cell: f1, f2 the nearest two distances (cell units), id a hash of the
 * nearest cell, (dx, dy) from that feature point to (u, v). */
typedef struct cell { double f1, f2, dx, dy; uint32_t id; } cell;

static cell cells(double u, double v, int period, uint32_t seed)
{
    double x = u * period, y = v * period;
    int ix = (int)floor(x), iy = (int)floor(y);
    cell c = {9, 9, 0, 0, 0};
    for (int j = -1; j <= 1; j++)
        for (int i = -1; i <= 1; i++) {
            int cx = wrapi(ix + i, period), cy = wrapi(iy + j, period);
            double fx = ix + i + 0.1 + 0.8 * rnd(cx, cy, seed);
            double fy = iy + j + 0.1 + 0.8 * rnd(cx, cy, seed + 1);
            double d = hypot(x - fx, y - fy);
            if (d < c.f1) {
                c.f2 = c.f1;
                c.f1 = d;
                c.dx = x - fx;
                c.dy = y - fy;
                c.id = texgen_hash(cx, cy, seed + 2);
            } else if (d < c.f2) {
                c.f2 = d;
            }
        }
    return c;
}
static double id01(uint32_t id, int k) { return (double)(texgen_hash((int32_t)id, k, 77) >> 8) / 16777216.0; }

/* Elongated strokes scattered per cell, seen from above: grass blades
 * (tapering, rising to a drooping tip, radiating from a tuft centre when
 * `tuft` > 0), needles, or leaves (ellipses lying at random depths).  The
 * highest stroke under (u, v) wins: h its height (0 where none), id its
 * hash, t the position along it (0 base .. 1 tip). */
typedef struct scatter_desc {
    int    period, per_cell;
    double len, width;       /* cell units                                   */
    double tuft;             /* 0: bases anywhere; 1: bases at the centre    */
    bool   leaf;             /* ellipse lying flat at a random depth         */
} scatter_desc;
typedef struct stroke { double h, t; uint32_t id; } stroke;

static stroke scatter(double u, double v, const scatter_desc *d, uint32_t seed)
{
    double x = u * d->period, y = v * d->period;
    int ix = (int)floor(x), iy = (int)floor(y);
    int reach = (int)ceil(d->len + 0.5);
    stroke best = {0, 0, 0};
    for (int j = -reach; j <= reach; j++)
        for (int i = -reach; i <= reach; i++) {
            int cx = wrapi(ix + i, d->period), cy = wrapi(iy + j, d->period);
            double tx = ix + i + 0.2 + 0.6 * rnd(cx, cy, seed + 11);
            double ty = iy + j + 0.2 + 0.6 * rnd(cx, cy, seed + 12);
            for (int k = 0; k < d->per_cell; k++) {
                uint32_t h = texgen_hash(cx * 31 + k, cy, seed);
                double r0 = (h & 1023) / 1024.0, r1 = ((h >> 10) & 1023) / 1024.0;
                double r2 = ((h >> 20) & 1023) / 1024.0;
                double bx = mixd(ix + i + r0, tx + (r0 - 0.5) * 0.25, d->tuft);
                double by = mixd(iy + j + r1, ty + (r1 - 0.5) * 0.25, d->tuft);
                double a = r2 * TAU;
                if (d->tuft > 0) {        /* lean away from the tuft centre */
                    double ox = bx - tx, oy = by - ty;
                    if (ox * ox + oy * oy > 1e-6)
                        a = atan2(oy, ox) + (r2 - 0.5) * 1.6;
                }
                double L = d->len * (0.55 + 0.45 * rnd(cx * 31 + k, cy, seed + 13));
                double ca = cos(a), sa = sin(a);
                double px = x - bx, py = y - by;
                double t = (px * ca + py * sa) / L;
                if (t < 0 || t > 1)
                    continue;
                double perp = fabs(-px * sa + py * ca);
                double w = d->leaf ? d->width * sqrt(1 - (2 * t - 1) * (2 * t - 1))
                                   : d->width * pow(1 - t, 0.6);
                if (perp >= w)
                    continue;
                double across = sqrt(1 - (perp / w) * (perp / w));
                double hh = d->leaf ? 0.35 + 0.6 * rnd(cx * 31 + k, cy, seed + 14) + 0.05 * across
                                    : (0.3 + 0.7 * sin(t * 2.0)) * (0.85 + 0.15 * across);
                if (hh > best.h)
                    best = (stroke){hh, t, h};
            }
        }
    return best;
}

/* ---- recipes ----------------------------------------------------------- */

typedef struct texel { double h; rgb c; double rough; } texel;
typedef struct ctx { int size; uint32_t seed; } ctx;
/* A per-texel hash in [0, 1) (grain); i, j are texel indices. */
#define GRAIN(k) rnd(i, j, x->seed + (k))

typedef void recipe(const ctx *x, int i, int j, double u, double v, texel *o);

static void grass_like(const ctx *x, int i, int j, double u, double v, texel *o, bool dry)
{
    scatter_desc d = {dry ? 20 : 24, dry ? 7 : 9, dry ? 1.7 : 1.3, dry ? 0.05 : 0.075, 1.0, false};
    stroke b = scatter(u, v, &d, x->seed);
    double patch = n01(u, v, 3, 3, x->seed + 5);
    double under = n01(u, v, 16, 3, x->seed + 6);
    rgb soil = dry ? mixc(hex(0x6b5a3c), hex(0x8a7650), under) : mixc(hex(0x2e3318), hex(0x4a4526), under);
    if (b.h <= 0) {
        o->h = 0.12 * under;
        o->c = soil;
        o->rough = 0.95;
        return;
    }
    double r = id01(b.id, 1), r2 = id01(b.id, 2);
    rgb c;
    if (dry) {
        c = mixc(hex(0xb09a62), hex(0xd2bd83), r);
        c = mixc(c, hex(0x8d7c52), smooth(0.75, 1.0, r2) * 0.8);         /* grey-brown dead   */
        c = mixc(c, hex(0x8f9256), smooth(0.6, 0.9, patch) * 0.35);        /* a trace of green  */
    } else {
        c = mixc(hex(0x46592a), hex(0x6f7d3c), r);
        c = mixc(c, hex(0x4f6b2c), smooth(0.3, 0.8, patch) * 0.6);         /* lusher patches    */
        c = mixc(c, hex(0x9a9048), smooth(0.86, 1.0, r2));                 /* dry blades        */
    }
    c = mixc(c, scalec(c, 1.25), smooth(0.5, 1.0, b.t));                   /* lighter tips      */
    o->h = 0.15 + 0.85 * b.h;
    o->c = c;
    o->rough = 0.85 - 0.1 * b.t;
}
static void r_grass(const ctx *x, int i, int j, double u, double v, texel *o) { grass_like(x, i, j, u, v, o, false); }
static void r_dry_grass(const ctx *x, int i, int j, double u, double v, texel *o) { grass_like(x, i, j, u, v, o, true); }

/* Pebbles: a cellular field where some cells hold a rounded stone. */
static double pebble(double u, double v, int period, double share, uint32_t seed, cell *c)
{
    *c = cells(u, v, period, seed);
    if (id01(c->id, 3) > share)
        return 0;
    double r = 0.25 + 0.2 * id01(c->id, 4);
    double q = c->f1 / r;
    return q < 1 ? sqrt(1 - q * q) : 0;
}

static void r_dirt(const ctx *x, int i, int j, double u, double v, texel *o)
{
    double clod = n01(u, v, 6, 5, x->seed);
    double fine = n01(u, v, 32, 2, x->seed + 1);
    cell c;
    double p = pebble(u, v, 22, 0.2, x->seed + 2, &c);
    rgb soil = mixc(hex(0x5e4c3c), hex(0x7e6a54), n01(u, v, 8, 3, x->seed + 3));
    soil = mixc(soil, hex(0x3d3024), (1 - clod) * 0.6);
    soil = scalec(soil, 0.9 + 0.2 * GRAIN(4));
    rgb stone = mixc(hex(0x6e665c), hex(0x857560), id01(c.id, 5));
    o->h = 0.6 * clod + 0.15 * fine + 0.3 * p;
    o->c = mixc(soil, stone, smooth(0.0, 0.3, p));
    o->rough = p > 0 ? 0.75 : 0.92;
}

static void r_mud(const ctx *x, int i, int j, double u, double v, texel *o)
{
    double n = n01(u, v, 4, 4, x->seed);
    double wet = smooth(0.47, 0.37, n);                     /* puddled hollows */
    double wu = 0.03 * texgen_fbm(u * 8, v * 8, 8, 8, 2, 0.5, x->seed + 7);
    double wv = 0.03 * texgen_fbm(u * 8, v * 8, 8, 8, 2, 0.5, x->seed + 8);
    cell c = cells(u + wu, v + wv, 7, x->seed + 1);
    double e = c.f2 - c.f1;
    double crack = (1 - smooth(0.03, 0.08, e)) * (1 - wet);
    double plate = 0.55 + 0.25 * n + 0.12 * smooth(0.0, 0.4, e) + 0.05 * n01(u, v, 24, 2, x->seed + 2);
    double h = plate - 0.45 * crack;
    double water = 0.42;
    rgb dry = mixc(hex(0x6e5b47), hex(0x806a52), id01(c.id, 1));
    rgb damp = hex(0x3a2e22);
    rgb col = mixc(dry, damp, smooth(0.6, 0.35, n));
    col = mixc(col, hex(0x1e1711), crack);
    col = mixc(col, hex(0x2a2119), wet);
    o->h = wet > 0.5 ? fmax(h * (1 - wet) + water * wet, water - 0.02) : h;
    o->c = scalec(col, 0.93 + 0.14 * GRAIN(3));
    o->rough = mixd(mixd(0.85, 0.6, smooth(0.6, 0.35, n)), 0.12, wet);
}

static void r_sand(const ctx *x, int i, int j, double u, double v, texel *o)
{
    double warp = texgen_fbm(u * 4, v * 4, 4, 4, 3, 0.5, x->seed);
    double r = 0.5 + 0.5 * sin(TAU * (18 * u + 4 * v) + 8.0 * warp);
    double ripple = pow(r, 1.6);
    double g = GRAIN(1);
    rgb c = mixc(hex(0xb89d70), hex(0xd0b98a), n01(u, v, 5, 3, x->seed + 2));
    c = mixc(c, hex(0xa88d62), (1 - ripple) * 0.35);       /* finer, darker grains in troughs */
    if (g > 0.93)
        c = mixc(c, hex(0x6b5e50), 0.6);                   /* dark mineral grains */
    else if (g < 0.05)
        c = mixc(c, hex(0xeee2c8), 0.6);                   /* quartz */
    o->h = 0.75 * ripple + 0.2 * n01(u, v, 16, 2, x->seed + 3) + 0.05 * g;
    o->c = c;
    o->rough = 0.88 + 0.08 * g;
}

static void r_gravel(const ctx *x, int i, int j, double u, double v, texel *o)
{
    static const unsigned pal[] = {0x8c8579, 0xa39a8a, 0x6e6a64, 0x9a8468, 0x7d7468, 0xb0a898};
    cell a = cells(u, v, 12, x->seed);
    cell b = cells(u, v, 27, x->seed + 1);
    double big = pow(smooth(0.0, 0.35, a.f2 - a.f1), 0.6) * (0.75 + 0.25 * id01(a.id, 1));
    double small = 0.6 * pow(smooth(0.0, 0.3, b.f2 - b.f1), 0.6) * (0.7 + 0.3 * id01(b.id, 1));
    double tex = n01(u, v, 48, 2, x->seed + 2);
    bool top = big >= small;
    uint32_t id = top ? a.id : b.id;
    rgb stone = hex(pal[(int)(id01(id, 2) * 6) % 6]);
    stone = scalec(stone, 0.85 + 0.3 * tex);
    double s = top ? big : small;
    double gap = 1 - smooth(0.02, 0.2, s);
    o->h = s + 0.05 * tex;
    o->c = mixc(stone, hex(0x3d362e), gap);
    o->rough = mixd(0.65 + 0.2 * id01(id, 3), 0.95, gap);
}

/* Ridged multifractal, periods 4..128. */
static double ridged(double u, double v, int octaves, uint32_t seed)
{
    double r = 0, amp = 1, norm = 0;
    for (int k = 0, p = 4; k < octaves; k++, p *= 2) {
        r += amp * (1 - fabs(texgen_gradient(u * p, v * p, p, p, seed + (uint32_t)k)) * 1.41);
        norm += amp;
        amp *= 0.5;
    }
    return r / norm;
}

static void r_rock(const ctx *x, int i, int j, double u, double v, texel *o)
{
    double rd = ridged(u, v, 6, x->seed);
    double wu = 0.06 * texgen_fbm(u * 6, v * 6, 6, 6, 3, 0.5, x->seed + 7);
    double wv = 0.06 * texgen_fbm(u * 6, v * 6, 6, 6, 3, 0.5, x->seed + 8);
    cell c = cells(u + wu, v + wv, 5, x->seed + 1);
    /* joints: only some of the cell edges open, where a noise says so */
    double open = smooth(0.45, 0.6, n01(u, v, 4, 3, x->seed + 9));
    double crack = (1 - smooth(0.0, 0.035, c.f2 - c.f1)) * open;
    double lichen = smooth(0.68, 0.74, n01(u, v, 10, 4, x->seed + 2));
    double spots = smooth(0.78, 0.82, n01(u, v, 40, 2, x->seed + 3));
    rgb col = mixc(hex(0x6f6a63), hex(0xa19a8f), smooth(0.3, 0.8, rd));
    col = mixc(col, hex(0x8a8670), id01(c.id, 1) * 0.4);   /* each block its own tint */
    col = mixc(col, hex(0x8d8a55), lichen * 0.7);
    col = mixc(col, hex(0xb07a3a), spots * 0.6);
    col = mixc(col, hex(0x2e2a26), crack);
    o->h = rd - 0.5 * crack;
    o->c = scalec(col, 0.94 + 0.12 * GRAIN(4));
    o->rough = mixd(0.72, 0.9, lichen) + 0.05 * (1 - rd);
}

static void r_cliff_rock(const ctx *x, int i, int j, double u, double v, texel *o)
{
    double warp = texgen_fbm(u * 3, v * 3, 3, 3, 3, 0.5, x->seed);
    double layer = v * 7 + 0.8 * warp;                     /* strata across v */
    double f = layer - floor(layer);
    int band = wrapi((int)floor(layer), 7);
    double ledge = smooth(0.75, 0.95, f);
    /* erosion streaks: noise stretched along v (water running down) */
    double streak = clamp01(0.5 + 1.2 * texgen_fbm(u * 24, v * 2, 24, 2, 3, 0.55, x->seed + 1));
    double rd = ridged(u, v, 5, x->seed + 2);
    double wu = 0.05 * texgen_fbm(u * 5, v * 5, 5, 5, 3, 0.5, x->seed + 7);
    cell c = cells(u + wu, v + 0.3 * wu, 4, x->seed + 3);
    double crack = (1 - smooth(0.0, 0.03, c.f2 - c.f1)) * smooth(0.4, 0.55, n01(u, v, 3, 3, x->seed + 9));
    static const unsigned pal[] = {0x857064, 0x9a8a7c, 0x6d625a, 0x8f8072, 0x7a6f66, 0xa09284, 0x726860};
    rgb col = mixc(hex(pal[band]), hex(pal[(band + 1) % 7]), smooth(0.8, 1.0, f));
    col = mixc(col, scalec(col, 1.15), smooth(0.4, 0.9, rd));
    col = mixc(col, hex(0x3f3a36), smooth(0.55, 0.9, streak) * 0.6);   /* desert varnish */
    col = mixc(col, hex(0xc0b2a0), smooth(0.25, 0.05, streak) * 0.3);  /* leached */
    col = mixc(col, hex(0x2a2420), crack);
    o->h = 0.45 * rd + 0.3 * (1 - ledge) * f - 0.15 * smooth(0.5, 0.9, streak) - 0.4 * crack;
    o->c = scalec(col, 0.95 + 0.1 * GRAIN(4));
    o->rough = 0.8 + 0.1 * streak;
}

static void r_snow(const ctx *x, int i, int j, double u, double v, texel *o)
{
    double base = n01(u, v, 4, 5, x->seed);
    double warp = texgen_fbm(u * 2, v * 2, 2, 2, 3, 0.5, x->seed + 1);
    double sas = pow(0.5 + 0.5 * sin(TAU * (6 * u + 2 * v) + 5 * warp), 3.0);  /* sastrugi */
    double h = 0.7 * base + 0.25 * sas + 0.05 * n01(u, v, 64, 1, x->seed + 2);
    rgb col = mixc(hex(0xd9e3ee), hex(0xf7f9fc), smooth(0.2, 0.8, h));
    if (GRAIN(3) > 0.985)
        col = hex(0xffffff);                               /* glints */
    o->h = h;
    o->c = col;
    o->rough = 0.55 + 0.2 * (1 - base);
}

static void r_moss(const ctx *x, int i, int j, double u, double v, texel *o)
{
    double wu = 0.02 * texgen_fbm(u * 16, v * 16, 16, 16, 2, 0.5, x->seed + 7);
    cell c = cells(u + wu, v - wu, 36, x->seed);
    double cushion = clamp01(1 - c.f1 * 1.2) * (0.6 + 0.4 * n01(u, v, 12, 3, x->seed + 8));
    cell cb = cells(u, v, 6, x->seed + 1);
    double mound = clamp01(1 - cb.f1 * 0.9);
    double fibre = n01(u, v, 96, 2, x->seed + 2);
    double h = 0.45 * mound + 0.4 * sqrt(cushion) + 0.15 * fibre;
    rgb col = mixc(hex(0x3a5418), hex(0x6e8c28), smooth(0.2, 0.9, cushion));
    col = mixc(col, hex(0x8f9a3a), smooth(0.65, 0.85, fibre) * cushion);  /* sporophyte tips */
    col = mixc(col, hex(0x586a2a), id01(cb.id, 1) * 0.5);
    col = mixc(col, hex(0x22301a), 1 - smooth(0.0, 0.25, cushion));
    o->h = h;
    o->c = col;
    o->rough = 0.95;
}

static void r_forest_floor(const ctx *x, int i, int j, double u, double v, texel *o)
{
    static const unsigned pal[] = {0x6a4a2e, 0x7e6240, 0x54402c, 0x8a7050, 0x4a3e30, 0x665438};
    scatter_desc leaves = {10, 3, 1.0, 0.3, 0.0, true};
    scatter_desc needles = {28, 4, 1.3, 0.05, 0.0, false};
    stroke l = scatter(u, v, &leaves, x->seed);
    stroke n = scatter(u, v, &needles, x->seed + 1);
    double soil = n01(u, v, 8, 3, x->seed + 2);
    rgb col = mixc(hex(0x2a2016), hex(0x3c2c1c), soil);
    double h = 0.15 * soil;
    double rough = 0.9;
    if (l.h > 0 && l.h * 0.9 + 0.1 > n.h * 0.8) {
        rgb c = hex(pal[(int)(id01(l.id, 1) * 6) % 6]);
        c = scalec(c, 0.8 + 0.35 * l.h);
        col = c;
        h = 0.2 + 0.8 * l.h;
        rough = 0.75;
    } else if (n.h > 0) {
        col = mixc(hex(0x6b5036), hex(0x80654a), id01(n.id, 1));
        h = 0.25 + 0.7 * n.h;
        rough = 0.7;
    }
    o->h = h;
    o->c = scalec(col, 0.93 + 0.14 * GRAIN(3));
    o->rough = rough;
}

static void r_asphalt(const ctx *x, int i, int j, double u, double v, texel *o)
{
    static const unsigned pal[] = {0x9a9790, 0x7c7770, 0x8c7f70, 0xa8a49c, 0x6a6660};
    cell c;
    double stone = pebble(u, v, 44, 0.55, x->seed, &c);
    double binder = n01(u, v, 12, 4, x->seed + 1);
    double pore = GRAIN(2) > 0.95 ? 1 : 0;
    cell k = cells(u, v, 3, x->seed + 3);
    double crack = (1 - smooth(0.0, 0.015, k.f2 - k.f1)) * smooth(0.5, 0.6, n01(u, v, 3, 3, x->seed + 4));
    rgb col = mixc(hex(0x262524), hex(0x33312f), binder);
    col = mixc(col, hex(pal[(int)(id01(c.id, 1) * 5) % 5]), smooth(0.0, 0.35, stone) * 0.85);
    col = mixc(col, hex(0x141312), fmax(pore * 0.7, crack));
    o->h = 0.35 + 0.15 * binder + 0.4 * stone - 0.2 * pore - 0.35 * crack;
    o->c = col;
    o->rough = stone > 0 ? 0.7 : 0.92;
}

/* ---- the table --------------------------------------------------------- */

static const struct surface {
    const char *name, *about;
    recipe     *fn;
    double      lo, hi, target;   /* mean linear albedo: measured range, target */
    double      depth;            /* relief in texels at 256 texels            */
} surfaces[] = {
    {"grass",        "grass tufts: scattered tapering blades, dry blades, lusher patches", r_grass,        0.15, 0.26, 0.16, 6},
    {"dry_grass",    "dry steppe grass: long straw blades over bare soil",                r_dry_grass,    0.25, 0.35, 0.27, 6},
    {"dirt",         "bare soil: fBm clods, pebbles",                                     r_dirt,         0.10, 0.25, 0.15, 5},
    {"mud",          "mud: Voronoi drying cracks, wet glossy hollows",                    r_mud,          0.05, 0.12, 0.08, 5},
    {"sand",         "sand: wind ripples warped by fBm, mineral grains",                  r_sand,         0.30, 0.45, 0.36, 3},
    {"gravel",       "gravel: two sizes of Voronoi stones, each its own colour",          r_gravel,       0.15, 0.30, 0.20, 8},
    {"rock",         "rock: ridged fBm, Voronoi joints, lichen",                          r_rock,         0.12, 0.30, 0.19, 8},
    {"cliff_rock",   "cliff rock: strata, erosion streaks (varnish), blocky joints",      r_cliff_rock,   0.12, 0.30, 0.18, 10},
    {"snow",         "snow: soft fBm drifts, sastrugi, glints",                           r_snow,         0.80, 0.90, 0.84, 2},
    {"moss",         "moss: cellular cushions over mounds, fibres",                       r_moss,         0.08, 0.18, 0.11, 5},
    {"forest_floor", "forest floor: leaf litter and needles over dark soil",              r_forest_floor, 0.05, 0.15, 0.09, 5},
    {"asphalt",      "asphalt: Voronoi aggregate in binder, pores, sparse cracks",        r_asphalt,      0.05, 0.12, 0.08, 3},
};
enum { NSURF = (int)(sizeof surfaces / sizeof surfaces[0]) };

int texgen_surface_count(void) { return NSURF; }
const char *texgen_surface_name(int i) { return i >= 0 && i < NSURF ? surfaces[i].name : NULL; }
const char *texgen_surface_about(int i) { return i >= 0 && i < NSURF ? surfaces[i].about : NULL; }
void texgen_surface_albedo_range(int i, double *lo, double *hi)
{
    *lo = i >= 0 && i < NSURF ? surfaces[i].lo : 0;
    *hi = i >= 0 && i < NSURF ? surfaces[i].hi : 0;
}

void texgen_surface_free(texgen_surface_set *set)
{
    texgen_image_free(&set->albedo);
    texgen_image_free(&set->normal);
    texgen_image_free(&set->height);
    texgen_image_free(&set->roughness);
    texgen_image_free(&set->ao);
}

static uint8_t unorm8(double x) { return (uint8_t)floor(clamp01(x) * 255.0 + 0.5); }

double texgen_mean_albedo(const texgen_image *img)
{
    size_t n = (size_t)img->width * img->height;
    if (img->channels < 3 || !n)
        return 0;
    double lut[256], s = 0;
    for (int k = 0; k < 256; k++)
        lut[k] = srgb_to_linear(k / 255.0);
    for (size_t p = 0; p < n; p++) {
        const uint8_t *q = img->pixels + p * img->channels;
        s += 0.2126 * lut[q[0]] + 0.7152 * lut[q[1]] + 0.0722 * lut[q[2]];
    }
    return s / n;
}

bool texgen_surface_make(int i, int size, uint32_t seed, texgen_surface_set *out)
{
    memset(out, 0, sizeof *out);
    if (i < 0 || i >= NSURF || size < 16 || (size & (size - 1)))
        return false;
    const struct surface *sf = &surfaces[i];
    size_t n = (size_t)size * size;
    texel *f = malloc(sizeof *f * n);
    double *hh = malloc(sizeof *hh * n);
    if (!f || !hh ||
        !texgen_image_alloc(&out->albedo, size, size, 4) ||
        !texgen_image_alloc(&out->normal, size, size, 3) ||
        !texgen_image_alloc(&out->height, size, size, 1) ||
        !texgen_image_alloc(&out->roughness, size, size, 1) ||
        !texgen_image_alloc(&out->ao, size, size, 1)) {
        free(f);
        free(hh);
        texgen_surface_free(out);
        return false;
    }
    /* each surface its own seed: the name hashed in (FNV-1a) */
    uint32_t s = 2166136261u;
    for (const char *c = sf->name; *c; c++)
        s = (s ^ (uint8_t)*c) * 16777619u;
    ctx x = {size, seed ^ s};
    double hmin = 1e30, hmax = -1e30;
    for (int j = 0; j < size; j++)
        for (int k = 0; k < size; k++) {
            texel *t = &f[(size_t)j * size + k];
            *t = (texel){0, {0, 0, 0}, 0.9};
            sf->fn(&x, k, j, (k + 0.5) / size, (j + 0.5) / size, t);
            hmin = fmin(hmin, t->h);
            hmax = fmax(hmax, t->h);
        }
    /* albedo: scale to the target mean luminance (clamping can lower the
     * mean, so iterate), then encode */
    double k = 1;
    for (int it = 0; it < 4; it++) {
        double sum = 0;
        for (size_t p = 0; p < n; p++) {
            rgb c = scalec(f[p].c, k);
            sum += luma((rgb){clamp01(c.r), clamp01(c.g), clamp01(c.b)});
        }
        double mean = sum / n;
        if (mean <= 0)
            break;
        k *= sf->target / mean;
    }
    double span = hmax > hmin ? hmax - hmin : 1;
    for (size_t p = 0; p < n; p++) {
        rgb c = scalec(f[p].c, k);
        hh[p] = (f[p].h - hmin) / span;
        out->albedo.pixels[4 * p + 0] = unorm8(linear_to_srgb(c.r));
        out->albedo.pixels[4 * p + 1] = unorm8(linear_to_srgb(c.g));
        out->albedo.pixels[4 * p + 2] = unorm8(linear_to_srgb(c.b));
        out->albedo.pixels[4 * p + 3] = unorm8(hh[p]);      /* the height again */
        out->height.pixels[p] = unorm8(hh[p]);
        out->roughness.pixels[p] = unorm8(f[p].rough);
    }
    /* normal and ambient occlusion from the height, `depth` texels deep */
    double depth = sf->depth * size / 256.0;
    double step = size / 256.0;
#define HT(a, b) (hh[(size_t)wrapi(b, size) * size + wrapi(a, size)] * depth)
    static const int dirs[8][2] = {{1, 0}, {1, 1}, {0, 1}, {-1, 1}, {-1, 0}, {-1, -1}, {0, -1}, {1, -1}};
    static const double radii[] = {1, 2, 3, 5, 8, 12, 16};
    for (int j = 0; j < size; j++)
        for (int a = 0; a < size; a++) {
            size_t p = (size_t)j * size + a;
            double dx = (HT(a + 1, j) - HT(a - 1, j)) * 0.5;
            double dy = (HT(a, j + 1) - HT(a, j - 1)) * 0.5;
            double len = sqrt(dx * dx + dy * dy + 1);
            out->normal.pixels[3 * p + 0] = unorm8(-dx / len * 0.5 + 0.5);
            out->normal.pixels[3 * p + 1] = unorm8(-dy / len * 0.5 + 0.5);
            out->normal.pixels[3 * p + 2] = unorm8(1 / len * 0.5 + 0.5);
            double h0 = HT(a, j), occ = 0;
            for (int d = 0; d < 8; d++) {
                double dl = (d & 1) ? sqrt(2.0) : 1.0, best = 0;
                for (size_t r = 0; r < sizeof radii / sizeof radii[0]; r++) {
                    int o = (int)(radii[r] * step + 0.5);
                    double sl = (HT(a + dirs[d][0] * o, j + dirs[d][1] * o) - h0) / (o * dl);
                    best = fmax(best, sl);
                }
                occ += best / sqrt(1 + best * best);
            }
            out->ao.pixels[p] = unorm8(1 - occ / 8);
        }
#undef HT
    free(f);
    free(hh);
    return true;
}

/* ---- files ------------------------------------------------------------- */

static bool write_one(const char *dir, const char *name, const char *what,
                      const texgen_image *img, char **err)
{
    size_t n = strlen(dir) + strlen(name) + strlen(what) + 8;
    char *path = malloc(n);
    if (!path) {
        if (err)
            *err = strdup("out of memory");
        return false;
    }
    snprintf(path, n, "%s/%s_%s.png", dir, name, what);
    bool ok = texgen_write_png(path, img, err);
    free(path);
    return ok;
}

bool texgen_write_surfaces(const char *dir, int size, uint32_t seed,
                           FILE *log, char **err)
{
    for (int i = 0; i < NSURF; i++) {
        texgen_surface_set set;
        if (!texgen_surface_make(i, size, seed, &set)) {
            if (err)
                *err = strdup("cannot generate a surface set (size must be a power of two >= 16)");
            return false;
        }
        const char *name = surfaces[i].name;
        bool ok = write_one(dir, name, "albedo", &set.albedo, err) &&
                  write_one(dir, name, "normal", &set.normal, err) &&
                  write_one(dir, name, "height", &set.height, err) &&
                  write_one(dir, name, "roughness", &set.roughness, err) &&
                  write_one(dir, name, "ao", &set.ao, err);
        if (ok && log)
            fprintf(log, "%s/%s_{albedo,normal,height,roughness,ao}.png  %dx%d, mean albedo %.3f in [%.2f, %.2f]  (%s)\n",
                    dir, name, size, size, texgen_mean_albedo(&set.albedo),
                    surfaces[i].lo, surfaces[i].hi, surfaces[i].about);
        texgen_surface_free(&set);
        if (!ok)
            return false;
    }
    return true;
}

/* ---- the swatch sheet -------------------------------------------------- */

/* A 5x7 font for the labels: rows top to bottom, bit 4 the left column. */
static const char glyph_chars[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789.-:=/[], ";
static const uint8_t glyphs[][7] = {
    {14,17,17,31,17,17,17}, {30,17,17,30,17,17,30}, {14,17,16,16,16,17,14}, {30,17,17,17,17,17,30},
    {31,16,16,30,16,16,31}, {31,16,16,30,16,16,16}, {14,17,16,23,17,17,15}, {17,17,17,31,17,17,17},
    {14,4,4,4,4,4,14},      {7,2,2,2,2,18,12},      {17,18,20,24,20,18,17}, {16,16,16,16,16,16,31},
    {17,27,21,21,17,17,17}, {17,17,25,21,19,17,17}, {14,17,17,17,17,17,14}, {30,17,17,30,16,16,16},
    {14,17,17,17,21,18,13}, {30,17,17,30,20,18,17}, {15,16,16,14,1,1,30},   {31,4,4,4,4,4,4},
    {17,17,17,17,17,17,14}, {17,17,17,17,17,10,4},  {17,17,17,21,21,21,10}, {17,17,10,4,10,17,17},
    {17,17,17,10,4,4,4},    {31,1,2,4,8,16,31},
    {14,17,19,21,25,17,14}, {4,12,4,4,4,4,14},      {14,17,1,2,4,8,31},     {31,2,4,2,1,17,14},
    {2,6,10,18,31,2,2},     {31,16,30,1,1,17,14},   {6,8,16,30,17,17,14},   {31,1,2,4,8,8,8},
    {14,17,17,14,17,17,14}, {14,17,17,15,1,2,12},
    {0,0,0,0,0,12,12},      {0,0,0,31,0,0,0},       {0,12,12,0,12,12,0},    {0,0,31,0,31,0,0},
    {1,1,2,4,8,16,16},      {14,8,8,8,8,8,14},      {14,2,2,2,2,2,14},      {0,0,0,0,12,4,8},
    {0,0,0,0,0,0,0},
};

static void put_text(texgen_image *img, int x, int y, int scale, const char *s, uint8_t v)
{
    for (; *s; s++, x += 6 * scale) {
        char ch = *s >= 'a' && *s <= 'z' ? (char)(*s - 32) : *s == '_' ? ' ' : *s;
        const char *at = strchr(glyph_chars, ch);
        if (!at || !ch)
            continue;
        const uint8_t *g = glyphs[at - glyph_chars];
        for (int r = 0; r < 7 * scale; r++)
            for (int c = 0; c < 5 * scale; c++) {
                int px = x + c, py = y + r;
                if (px >= img->width || py >= img->height || !(g[r / scale] & (16 >> (c / scale))))
                    continue;
                for (int k = 0; k < 3; k++)
                    img->pixels[((size_t)py * img->width + px) * 3 + k] = v;
            }
    }
}

/* Copy `src` (size² texels, box-reduced to `cell`) into the sheet at (x, y);
 * grey sources are repeated into RGB; `lit` shades it instead. */
static void put_swatch(texgen_image *sheet, int x0, int y0, int cell,
                       const texgen_image *src, const texgen_surface_set *lit)
{
    int f = src->width / cell;
    double L[3] = {-0.45, -0.5, 0.74};   /* sun from the upper left */
    double ll = sqrt(L[0] * L[0] + L[1] * L[1] + L[2] * L[2]);
    for (int y = 0; y < cell; y++)
        for (int x = 0; x < cell; x++) {
            double acc[3] = {0, 0, 0};
            for (int j = 0; j < f; j++)
                for (int i = 0; i < f; i++) {
                    size_t p = (size_t)(y * f + j) * src->width + (size_t)(x * f + i);
                    if (lit) {
                        const uint8_t *a = lit->albedo.pixels + 4 * p, *nn = lit->normal.pixels + 3 * p;
                        double nv[3], d = 0;
                        for (int k = 0; k < 3; k++)
                            nv[k] = nn[k] / 127.5 - 1;
                        for (int k = 0; k < 3; k++)
                            d += nv[k] * L[k] / ll;
                        double e = 1.2 * fmax(d, 0) + 0.3 * lit->ao.pixels[p] / 255.0;
                        for (int k = 0; k < 3; k++)
                            acc[k] += srgb_to_linear(a[k] / 255.0) * e;
                    } else {
                        for (int k = 0; k < 3; k++)
                            acc[k] += src->pixels[p * src->channels + (src->channels >= 3 ? k : 0)];
                    }
                }
            for (int k = 0; k < 3; k++) {
                double m = acc[k] / (f * f);
                sheet->pixels[((size_t)(y0 + y) * sheet->width + (x0 + x)) * 3 + k] =
                    lit ? unorm8(linear_to_srgb(m)) : (uint8_t)floor(m + 0.5);
            }
        }
}

bool texgen_write_sheet(const char *path, int size, uint32_t seed, int cell, char **err)
{
    static const char *const heads[] = {"ALBEDO", "NORMAL", "HEIGHT", "ROUGHNESS", "AO", "LIT"};
    enum { COLS = 6, LABEL = 230, GAP = 6, HEAD = 30 };
    if (cell < 8 || cell > size) {
        if (err)
            *err = strdup("bad swatch size");
        return false;
    }
    texgen_image sheet;
    int w = LABEL + COLS * (cell + GAP) + GAP, h = HEAD + NSURF * (cell + GAP) + GAP;
    if (!texgen_image_alloc(&sheet, w, h, 3)) {
        if (err)
            *err = strdup("out of memory");
        return false;
    }
    memset(sheet.pixels, 40, (size_t)w * h * 3);
    for (int c = 0; c < COLS; c++)
        put_text(&sheet, LABEL + c * (cell + GAP) + GAP, 10,
                 (int)strlen(heads[c]) * 12 <= cell ? 2 : 1, heads[c], 230);
    bool ok = true;
    for (int i = 0; i < NSURF && ok; i++) {
        texgen_surface_set set;
        if (!texgen_surface_make(i, size, seed, &set)) {
            ok = false;
            if (err)
                *err = strdup("cannot generate a surface set");
            break;
        }
        int y = HEAD + i * (cell + GAP) + GAP;
        char line[64];
        put_text(&sheet, 10, y + 8, 2, surfaces[i].name, 240);
        snprintf(line, sizeof line, "RANGE %.2f-%.2f", surfaces[i].lo, surfaces[i].hi);
        put_text(&sheet, 10, y + 34, 1, line, 190);
        snprintf(line, sizeof line, "MEAN ALBEDO %.3f", texgen_mean_albedo(&set.albedo));
        put_text(&sheet, 10, y + 46, 1, line, 190);
        const texgen_image *col[COLS] = {&set.albedo, &set.normal, &set.height,
                                         &set.roughness, &set.ao, &set.albedo};
        for (int c = 0; c < COLS; c++)
            put_swatch(&sheet, LABEL + c * (cell + GAP) + GAP, y, cell, col[c],
                       c == COLS - 1 ? &set : NULL);
        texgen_surface_free(&set);
    }
    if (ok)
        ok = texgen_write_png(path, &sheet, err);
    texgen_image_free(&sheet);
    return ok;
}
