/* far_atlas.c — `splatc build --far-atlas[=N]`: the far atlas (far_atlas.h).
 *
 * What: one atlas texel per N x N heightfield texels (default N = 1: the
 * heightfield's own density, colorado 73.5 x 92.6 m), covering the terrain
 * uv square; its leaf cells' blocks lie where the quadtree's leaf cells
 * lie, so a node's part of the atlas is the rectangle of its cells.  Each
 * texel holds the mean of the composite at 2 x 2 points spread over it
 * (FAR_SS: a box filter over the texel), each point shaded by the
 * combination of the leaf cell it falls in (the pack's combos.bin level
 * 0; the forward and screen paths shade that cell with it or an equal
 * superset), without lighting: "composite.albedo / .normal / .roughness"
 * (compose.h).
 *
 * How (`--far-bake cpu`, and auto without a GPU): on the CPU, in double,
 * with the compiler's own reference evaluator (ir_eval_node over the
 * composite's IR in id order, every root at once).  `--far-bake gpu` (and
 * auto with one) shades the same points with the same inputs on the
 * device instead: the splatc program links the runtime and hands its
 * device bake in desc->far_device (runtime/far_bake.c, abi.h "far atlas
 * bake"), which reads the pack written so far, before the swap; this
 * library stays free of Vulkan.  Both bakes reduce their points to texels
 * with far_atlas_reduce and share the mips and blocks below.  The inputs are the fragment
 * stage's at each point: height and normal from the heightfield
 * (splat_terrain_height / _normal, the ABI's twins), painted masks
 * bilinear from the dense rasters (a placed mask over its own rectangle,
 * 0 outside, as the runtime reads it), destruction 0, params at
 * their defaults; view.distance FAR_ATLAS_BAKE_DISTANCE and the view
 * straight down.  Textures are filtered as a GPU filters them at that
 * footprint: the composite is differentiated (ir_differentiate, as for the
 * compute stage) with the point spacing as the pixel step, and every
 * sample_grad picks its level from its gradients (trilinear over a
 * box-filtered chain in linear space, or the texture's stored mip files:
 * PACK.md), so a 4 m rock texture reads as its mean, not as aliased texels.
 *
 * Then a box-filtered mip chain (normals renormalised) and BC1 (sRGB) /
 * BC5 / BC4 blocks by stb_dxt.  Cost: proportional to texels x 4 points
 * (tests/bench/HISTORY.md "Shading LOD: far atlas" has colorado's).
 *
 * Not baked: craters (the runtime never uses the atlas over the
 * destructible area: runtime/DESIGN.md) and param edits (a rebuild). */
#include "build.h"
#include "far_atlas.h"

#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>

#include <stb_dxt.h>
#include <stb_image.h>

/* ---- textures on the CPU ---------------------------------------------------- */

typedef struct far_tex {
    int      levels;
    int     *w, *h;
    float  **rgba;          /* per level, linear                           */
    ir_filter filter, mip;
    ir_wrap  wrap;
} far_tex;

static double srgb_to_linear(double c)
{
    return c <= 0.04045 ? c / 12.92 : pow((c + 0.055) / 1.055, 2.4);
}

static float *load_rgba(const char *path, bool srgb, int *w, int *h)
{
    int n;
    char why[256];
    FILE *file = splat_input_fopen(path, SPLAT_MAX_IMAGE_BYTES, why, sizeof why);
    if (!file)
        return NULL;
    stbi_uc *px = stbi_load_from_file(file, w, h, &n, 4);
    fclose(file);
    if (!px)
        return NULL;
    size_t count = (size_t)*w * (size_t)*h * 4;
    float *f = xmalloc(count * sizeof *f);
    for (size_t i = 0; i < count; i++)
        f[i] = (float)(srgb && i % 4 != 3 ? srgb_to_linear(px[i] / 255.0) : px[i] / 255.0);
    stbi_image_free(px);
    return f;
}

static bool tex_load(far_tex *t, const ir_texture *src)
{
    memset(t, 0, sizeof *t);
    int w, h;
    float *base = load_rgba(src->file, src->srgb, &w, &h);
    if (!base)
        return false;
    t->filter = src->filter;
    t->mip = src->mip;
    t->wrap = src->wrap;
    t->levels = 1;
    while ((w >> t->levels) > 0 || (h >> t->levels) > 0)
        t->levels++;
    t->w = xcalloc((size_t)t->levels, sizeof *t->w);
    t->h = xcalloc((size_t)t->levels, sizeof *t->h);
    t->rgba = xcalloc((size_t)t->levels, sizeof *t->rgba);
    t->w[0] = w;
    t->h[0] = h;
    t->rgba[0] = base;
    int stored = build_mip_count(src->file);
    for (int l = 1; l < t->levels; l++) {
        int lw = w >> l ? w >> l : 1, lh = h >> l ? h >> l : 1;
        t->w[l] = lw;
        t->h[l] = lh;
        if (l <= stored) {   /* the texture's own level (texgen.h) */
            char *p = build_mip_path(src->file, l);
            int fw, fh;
            t->rgba[l] = load_rgba(p, src->srgb, &fw, &fh);
            free(p);
            if (t->rgba[l] && fw == lw && fh == lh)
                continue;
            free(t->rgba[l]);
        }
        /* box filter of the level above (what the runtime's blits do) */
        int pw = t->w[l - 1], ph = t->h[l - 1];
        const float *s = t->rgba[l - 1];
        float *d = t->rgba[l] = xmalloc((size_t)lw * (size_t)lh * 4 * sizeof *d);
        for (int y = 0; y < lh; y++)
            for (int x = 0; x < lw; x++)
                for (int c = 0; c < 4; c++) {
                    int x0 = 2 * x < pw ? 2 * x : pw - 1, x1 = 2 * x + 1 < pw ? 2 * x + 1 : x0;
                    int y0 = 2 * y < ph ? 2 * y : ph - 1, y1 = 2 * y + 1 < ph ? 2 * y + 1 : y0;
                    d[((size_t)y * lw + x) * 4 + c] =
                        0.25f * (s[((size_t)y0 * pw + x0) * 4 + c] + s[((size_t)y0 * pw + x1) * 4 + c] +
                                 s[((size_t)y1 * pw + x0) * 4 + c] + s[((size_t)y1 * pw + x1) * 4 + c]);
                }
    }
    return true;
}

static void tex_free(far_tex *t)
{
    for (int l = 0; l < t->levels; l++)
        free(t->rgba[l]);
    free(t->rgba);
    free(t->w);
    free(t->h);
}

static void tex_level(const far_tex *t, int l, double u, double v, double out[4])
{
    int w = t->w[l], h = t->h[l];
    const float *px = t->rgba[l];
    if (!isfinite(u) || !isfinite(v) || fabs(u) > 1e9 || fabs(v) > 1e9) {
        out[0] = out[1] = out[2] = out[3] = 0.0;
        return;
    }
    if (t->filter == IR_FILTER_NEAREST) {
        int x = ir_wrap_index((int)floor(u * w), w, t->wrap), y = ir_wrap_index((int)floor(v * h), h, t->wrap);
        for (int c = 0; c < 4; c++)
            out[c] = px[((size_t)y * w + x) * 4 + c];
        return;
    }
    double fx = u * w - 0.5, fy = v * h - 0.5;
    double x0f = floor(fx), y0f = floor(fy), ax = fx - x0f, ay = fy - y0f;
    int x0 = ir_wrap_index((int)x0f, w, t->wrap), x1 = ir_wrap_index((int)x0f + 1, w, t->wrap);
    int y0 = ir_wrap_index((int)y0f, h, t->wrap), y1 = ir_wrap_index((int)y0f + 1, h, t->wrap);
    for (int c = 0; c < 4; c++) {
        double a = px[((size_t)y0 * w + x0) * 4 + c], b = px[((size_t)y0 * w + x1) * 4 + c];
        double d = px[((size_t)y1 * w + x0) * 4 + c], e = px[((size_t)y1 * w + x1) * 4 + c];
        out[c] = (a * (1 - ax) + b * ax) * (1 - ay) + (d * (1 - ax) + e * ax) * ay;
    }
}

typedef struct far_bake {
    build       *b;
    far_tex     *tex;          /* per layout texture                        */
    bool        *tex_ok;
    splat_composite *comp;     /* per combination, differentiated           */
    int        **tex_of;       /* per combination: its ir texture -> layout */
    int        **painted_of;   /* per combination: its ir painted -> scene  */
    ir_ref      (*roots)[3];   /* albedo, normal, roughness per combination */
    int          W, H;         /* atlas texels                              */
    float       *albedo, *normal, *rough;   /* level 0: 3, 3, 1 per texel   */
    int          next_row, nthreads;
    pthread_mutex_t lock;
} far_bake;

typedef struct far_sampler { far_bake *fb; int combo; } far_sampler;

static void sample_grad(void *user, int texture, const double uv[2], const double dx[2],
                        const double dy[2], double rgba[4])
{
    const far_sampler *s = user;
    int lt = s->fb->tex_of[s->combo][texture];
    if (lt < 0 || !s->fb->tex_ok[lt]) {
        rgba[0] = rgba[1] = rgba[2] = 0.5;
        rgba[3] = 1.0;
        return;
    }
    const far_tex *t = &s->fb->tex[lt];
    double w = t->w[0], h = t->h[0];
    double lx = hypot(dx[0] * w, dx[1] * h), ly = hypot(dy[0] * w, dy[1] * h);
    double rho = lx > ly ? lx : ly;
    double lod = rho > 0 && isfinite(rho) ? log2(rho) : 0.0;
    if (!(lod > 0))
        lod = 0;
    if (lod > t->levels - 1)
        lod = t->levels - 1;
    if (t->mip == IR_FILTER_NEAREST) {
        tex_level(t, (int)floor(lod + 0.5), uv[0], uv[1], rgba);
        return;
    }
    int l0 = (int)floor(lod), l1 = l0 + 1 < t->levels ? l0 + 1 : l0;
    double a[4], b[4], f = lod - l0;
    tex_level(t, l0, uv[0], uv[1], a);
    tex_level(t, l1, uv[0], uv[1], b);
    for (int c = 0; c < 4; c++)
        rgba[c] = a[c] * (1 - f) + b[c] * f;
}

/* The composite at heightfield uv (u, v), with a pixel step of (sx, sz)
 * metres for the texture gradients: albedo, unit normal, roughness.  False
 * where the leaf cell is all hole (never drawn). */
static bool eval_point(far_bake *fb, double u, double v, double sx, double sz,
                       double (*vals)[4], double al[3], double nrm[3], double *ro)
{
    build *b = fb->b;
    const splat_terrain *t = &b->scene.terrain;
    const splat_analysis *a = &b->analysis;
    const splat_scene *s = &b->scene;
    int cx = (int)(u * t->width) / a->cell_texels, cz = (int)(v * t->height) / a->cell_texels;
    cx = cx < 0 ? 0 : cx < a->cells_x ? cx : a->cells_x - 1;
    cz = cz < 0 ? 0 : cz < a->cells_z ? cz : a->cells_z - 1;
    int id = a->levels[0].ids[(size_t)cz * a->cells_x + cx];
    if (id >= a->ncombos)
        return false;
    const splat_composite *c = &fb->comp[id];
    far_sampler smp = {fb, id};
    double painted[256] = {0};
    for (int k = 0; k < c->ir.npainted && k < 256; k++) {
        int sp = fb->painted_of[id][k];
        bool across;
        int vs = sp < 0 && s->vectors.words
                     ? splat_vector_find(s->desc, c->ir.painted[k].name, &across) : -1;
        if (vs >= 0) {   /* a vector shape (vector.c), as the shader reads it */
            double dist = splat_vector_distance_grid(&s->vectors, vs, u * t->size[0],
                                                     v * t->size[1]);
            painted[k] = splat_vector_profile(&s->vectors, vs, dist, across);
            continue;
        }
        if (sp < 0 || !s->painted || !s->painted[sp])
            continue;
        int pw = s->painted_size[sp][0], ph = s->painted_size[sp][1];
        double mu = u, mv = v;   /* the mask's own uv */
        const sg_scene_painted *pm = &s->desc->painted[sp];
        if (pm->place_loc.line > 0) {   /* placed: its rectangle, 0 outside (abi.c) */
            mu = (u * t->size[0] - pm->origin[0]) / pm->place[0];
            mv = (v * t->size[1] - pm->origin[1]) / pm->place[1];
            if (!(mu >= 0 && mu <= 1 && mv >= 0 && mv <= 1))
                continue;
        }
        double fx = mu * pw - 0.5, fy = mv * ph - 0.5;
        int x0 = (int)floor(fx), y0 = (int)floor(fy);
        double ax = fx - x0, ay = fy - y0, acc = 0;
        for (int dy = 0; dy < 2; dy++)
            for (int dx = 0; dx < 2; dx++) {
                int px = x0 + dx < 0 ? 0 : x0 + dx >= pw ? pw - 1 : x0 + dx;
                int py = y0 + dy < 0 ? 0 : y0 + dy >= ph ? ph - 1 : y0 + dy;
                acc += s->painted[sp][(size_t)py * pw + px] / 255.0 * (dx ? ax : 1 - ax) *
                       (dy ? ay : 1 - ay);
            }
        painted[k] = acc;
    }
    ir_env env;
    memset(&env, 0, sizeof env);
    env.height = splat_terrain_height(t, u, v);
    splat_terrain_normal(t, u, v, env.normal);
    env.slope = 1.0 - env.normal[1];
    env.position[0] = u * t->size[0];
    env.position[1] = env.height;
    env.position[2] = v * t->size[1];
    env.uv[0] = u;
    env.uv[1] = v;
    env.view_distance = FAR_ATLAS_BAKE_DISTANCE;
    env.view_direction[1] = 1.0;
    env.cavity = splat_terrain_cavity(t, u, v);
    env.painted = painted;
    env.sample_grad = sample_grad;
    env.sample_user = &smp;
    /* one step right / down, on the terrain's tangent plane */
    double ny = env.normal[1] > 0.05 ? env.normal[1] : 0.05;
    double dhx = -sx * env.normal[0] / ny, dhz = -sz * env.normal[2] / ny;
    double *px = env.d_input[0][IR_IN_POSITION], *pz = env.d_input[1][IR_IN_POSITION];
    px[0] = sx; px[1] = dhx;
    pz[1] = dhz; pz[2] = sz;
    env.d_input[0][IR_IN_HEIGHT][0] = dhx;
    env.d_input[1][IR_IN_HEIGHT][0] = dhz;
    env.d_input[0][IR_IN_UV][0] = sx / t->size[0];
    env.d_input[1][IR_IN_UV][1] = sz / t->size[1];
    /* normal and slope (footprints: .sg's fwidth) as the prelude's
     * splat_d_normal: the normal one step over minus this one */
    bool curv = false;
    for (uint32_t n = 1; n < c->ir.nnodes && !curv; n++)
        curv = c->ir.nodes[n].op == IR_OP_DINPUT &&
               (IR_DINPUT_INPUT(c->ir.nodes[n].imm) == IR_IN_NORMAL ||
                IR_DINPUT_INPUT(c->ir.nodes[n].imm) == IR_IN_SLOPE);
    for (int a = 0; a < 2 && curv; a++) {
        double n1[3];
        splat_terrain_normal(t, u + (a ? 0 : sx / t->size[0]), v + (a ? sz / t->size[1] : 0), n1);
        for (int k = 0; k < 3; k++)
            env.d_input[a][IR_IN_NORMAL][k] = n1[k] - env.normal[k];
        env.d_input[a][IR_IN_SLOPE][0] = -(n1[1] - env.normal[1]);
    }
    for (uint32_t n = 1; n < c->ir.nnodes; n++)
        ir_eval_node(&c->ir, n, &env, vals);
    const double *A = vals[fb->roots[id][0].id], *N = vals[fb->roots[id][1].id];
    const double *R = vals[fb->roots[id][2].id];
    double len = sqrt(N[0] * N[0] + N[1] * N[1] + N[2] * N[2]);
    for (int k = 0; k < 3; k++) {
        al[k] = A[k] < 0 ? 0 : A[k] > 1 ? 1 : A[k];
        nrm[k] = len > 0 ? N[k] / len : k == 1;
    }
    *ro = R[0] < 0 ? 0 : R[0] > 1 ? 1 : R[0];
    return true;
}

/* One row of atlas texels, from its FAR_ATLAS_SS rows of points (each
 * texel the mean of the composite at FAR_ATLAS_SS^2 points spread over
 * it: a box filter over the texel, which is what a far pixel covering the
 * texel should show; one point at the centre would keep the composite's
 * aliasing: a peak's texel centre has a flat normal). */
enum { FAR_SS = FAR_ATLAS_SS };

static void bake_row(far_bake *fb, int z, double (*vals)[4], float *pts)
{
    const splat_terrain *t = &fb->b->scene.terrain;
    int nx = FAR_SS * fb->W;
    double sx = t->size[0] / nx, sz = t->size[1] / (FAR_SS * fb->H);
    for (int r = 0; r < FAR_SS; r++)
        for (int i = 0; i < nx; i++) {
            double u = (i + 0.5) / nx, v = (FAR_SS * z + r + 0.5) / (FAR_SS * fb->H);
            double al[3], no[3], ro;
            float *p = pts + ((size_t)r * nx + i) * 8;
            bool shaded = eval_point(fb, u, v, sx, sz, vals, al, no, &ro);
            for (int c = 0; c < 3; c++) {
                p[c] = shaded ? (float)al[c] : 0.0f;
                p[3 + c] = shaded ? (float)no[c] : 0.0f;
            }
            p[6] = shaded ? (float)ro : 0.0f;
            p[7] = shaded ? 1.0f : 0.0f;
        }
    size_t i = (size_t)z * fb->W;
    far_atlas_reduce(pts, fb->W, fb->albedo + 3 * i, fb->normal + 3 * i, fb->rough + i);
}

static void *bake_worker(void *arg)
{
    far_bake *fb = arg;
    uint32_t cap = 0;
    for (int k = 0; k < fb->b->analysis.ncombos; k++)
        cap = fb->comp[k].ir.nnodes > cap ? fb->comp[k].ir.nnodes : cap;
    double (*vals)[4] = xcalloc(cap + 1, sizeof *vals);
    float *pts = xmalloc((size_t)FAR_SS * FAR_SS * fb->W * 8 * sizeof *pts);
    for (;;) {
        pthread_mutex_lock(&fb->lock);
        int z = fb->next_row++;
        pthread_mutex_unlock(&fb->lock);
        if (z >= fb->H)
            break;
        bake_row(fb, z, vals, pts);
    }
    free(pts);
    free(vals);
    return NULL;
}

/* ---- mips and blocks -------------------------------------------------------- */

static void app(ir_buf *o, const void *data, size_t n)
{
    if (o->len + n > o->cap) {
        size_t cap = o->cap ? o->cap : 1 << 16;
        while (cap < o->len + n)
            cap *= 2;
        o->s = xrealloc(o->s, cap);
        o->cap = cap;
    }
    memcpy(o->s + o->len, data, n);
    o->len += n;
}

static uint8_t unorm8(double v)
{
    v = v < 0 ? 0 : v > 1 ? 1 : v;
    return (uint8_t)lrint(v * 255.0);
}

static double linear_to_srgb(double c)
{
    return c <= 0.0031308 ? 12.92 * c : 1.055 * pow(c, 1.0 / 2.4) - 0.055;
}

/* Texel (x, y) of a w x h level, clamped: 4x4 blocks at the edges repeat
 * the last row / column. */
static size_t at(int x, int y, int w, int h)
{
    x = x < w ? x : w - 1;
    y = y < h ? y : h - 1;
    return (size_t)y * w + x;
}

static void encode_level(ir_buf *o, const float *al, const float *no, const float *ro, int w, int h)
{
    int bw = (w + 3) / 4, bh = (h + 3) / 4;
    uint8_t in[64], blk[16];
    for (int by = 0; by < bh; by++)
        for (int bx = 0; bx < bw; bx++) {
            for (int k = 0; k < 16; k++) {
                size_t i = at(bx * 4 + k % 4, by * 4 + k / 4, w, h);
                for (int c = 0; c < 3; c++)
                    in[4 * k + c] = unorm8(linear_to_srgb(al[3 * i + c]));
                in[4 * k + 3] = 255;
            }
            stb_compress_dxt_block(blk, in, 0, STB_DXT_HIGHQUAL);
            app(o, blk, 8);
        }
    for (int by = 0; by < bh; by++)
        for (int bx = 0; bx < bw; bx++) {
            for (int k = 0; k < 16; k++) {
                size_t i = at(bx * 4 + k % 4, by * 4 + k / 4, w, h);
                in[2 * k] = unorm8(no[3 * i] * 0.5 + 0.5);
                in[2 * k + 1] = unorm8(no[3 * i + 2] * 0.5 + 0.5);
            }
            stb_compress_bc5_block(blk, in);
            app(o, blk, 16);
        }
    for (int by = 0; by < bh; by++)
        for (int bx = 0; bx < bw; bx++) {
            for (int k = 0; k < 16; k++)
                in[k] = unorm8(ro[at(bx * 4 + k % 4, by * 4 + k / 4, w, h)]);
            stb_compress_bc4_block(blk, in);
            app(o, blk, 8);
        }
}

/* Halve a level (box filter; an odd last row / column folds in). */
static void halve(const float *s, int w, int h, int comps, float *d, int dw, int dh)
{
    for (int y = 0; y < dh; y++)
        for (int x = 0; x < dw; x++)
            for (int c = 0; c < comps; c++) {
                double acc = 0;
                for (int k = 0; k < 4; k++)
                    acc += s[at(2 * x + k % 2, 2 * y + k / 2, w, h) * comps + c];
                d[((size_t)y * dw + x) * comps + c] = (float)(acc / 4);
            }
}

static void put_u32(ir_buf *o, uint32_t v)
{
    uint8_t b[4] = {(uint8_t)v, (uint8_t)(v >> 8), (uint8_t)(v >> 16), (uint8_t)(v >> 24)};
    app(o, b, 4);
}

static void put_f64(ir_buf *o, double v)
{
    uint64_t u;
    memcpy(&u, &v, 8);
    put_u32(o, (uint32_t)u);
    put_u32(o, (uint32_t)(u >> 32));
}

/* ---- the phase ---------------------------------------------------------------- */

/* The mip chain of level 0 (fb's arrays) and its blocks, into b->far. */
static void encode_atlas(build *b, const far_bake *fb)
{
    const splat_terrain *t = &b->scene.terrain;
    ir_buf o = {0};
    app(&o, FAR_ATLAS_MAGIC, 8);
    int levels = far_atlas_levels_max((uint32_t)fb->W, (uint32_t)fb->H);
    put_u32(&o, FAR_ATLAS_VERSION);
    put_u32(&o, (uint32_t)fb->W);
    put_u32(&o, (uint32_t)fb->H);
    put_u32(&o, (uint32_t)levels);
    put_f64(&o, t->size[0] / fb->W);
    put_f64(&o, t->size[1] / fb->H);
    float *al = fb->albedo, *no = fb->normal, *ro = fb->rough;
    int w = fb->W, h = fb->H;
    for (int l = 0; l < levels; l++) {
        if (l > 0) {
            int dw = w >> 1 ? w >> 1 : 1, dh = h >> 1 ? h >> 1 : 1;
            float *nal = xmalloc((size_t)dw * dh * 3 * sizeof *nal);
            float *nno = xmalloc((size_t)dw * dh * 3 * sizeof *nno);
            float *nro = xmalloc((size_t)dw * dh * sizeof *nro);
            halve(al, w, h, 3, nal, dw, dh);
            halve(no, w, h, 3, nno, dw, dh);
            halve(ro, w, h, 1, nro, dw, dh);
            for (size_t i = 0; i < (size_t)dw * dh; i++) {
                double len = sqrt(nno[3 * i] * nno[3 * i] + nno[3 * i + 1] * nno[3 * i + 1] +
                                  nno[3 * i + 2] * nno[3 * i + 2]);
                for (int c = 0; c < 3; c++)
                    nno[3 * i + c] = len > 0 ? (float)(nno[3 * i + c] / len) : c == 1;
            }
            if (al != fb->albedo) {
                free(al);
                free(no);
                free(ro);
            }
            al = nal, no = nno, ro = nro, w = dw, h = dh;
        }
        encode_level(&o, al, no, ro, w, h);
    }
    if (al != fb->albedo) {
        free(al);
        free(no);
        free(ro);
    }
    b->far.data = (uint8_t *)o.s;
    b->far.n = o.len;
    b->far.width = fb->W;
    b->far.height = fb->H;
    b->far.levels = levels;
    b->far.texel[0] = t->size[0] / fb->W;
    b->far.texel[1] = t->size[1] / fb->H;
}

/* The atlas's level-0 size for desc->far_atlas; false past the limit. */
static bool atlas_size(build *b, int *w, int *h)
{
    const splat_terrain *t = &b->scene.terrain;
    int n = b->desc->far_atlas;
    *w = (t->width + n - 1) / n;
    *h = (t->height + n - 1) / n;
    if (*w <= FAR_ATLAS_MAX_SIDE && *h <= FAR_ATLAS_MAX_SIDE)
        return true;
    sg_errorf(b->d, b->loc, SG_E_OVER_LIMIT, "far atlas of %d x %d texels is over %d a side",
              *w, *h, FAR_ATLAS_MAX_SIDE);
    return false;
}

static void alloc_level0(far_bake *fb)
{
    size_t texels = (size_t)fb->W * fb->H;
    fb->albedo = xmalloc(texels * 3 * sizeof(float));
    fb->normal = xmalloc(texels * 3 * sizeof(float));
    fb->rough = xmalloc(texels * sizeof(float));
}

/* The CPU reference bake, then the blocks. */
static bool bake_on_cpu(build *b)
{
    const splat_analysis *a = &b->analysis;
    far_bake fb = {.b = b};
    if (!atlas_size(b, &fb.W, &fb.H))
        return false;
    int nt = b->layout.ntextures;
    fb.tex = xcalloc((size_t)nt + 1, sizeof *fb.tex);
    fb.tex_ok = xcalloc((size_t)nt + 1, sizeof *fb.tex_ok);
    for (int i = 0; i < nt; i++)
        fb.tex_ok[i] = tex_load(&fb.tex[i], &b->layout.src->textures[b->layout.textures[i]]);
    int nc = a->ncombos;
    fb.comp = xcalloc((size_t)nc + 1, sizeof *fb.comp);
    fb.tex_of = xcalloc((size_t)nc + 1, sizeof *fb.tex_of);
    fb.painted_of = xcalloc((size_t)nc + 1, sizeof *fb.painted_of);
    fb.roots = xcalloc((size_t)nc + 1, sizeof *fb.roots);
    bool ok = true;
    for (int k = 0; ok && k < nc; k++) {
        splat_compose_desc cd = {.materials = a->combos[k].materials,
                                 .nmaterials = a->combos[k].nmaterials};
        ok = splat_compose(&b->layout, &cd, &fb.comp[k], b->d);
        if (!ok)
            break;
        ir *ir = &fb.comp[k].ir;
        if (ir_pass_run(ir, "differentiate", NULL))
            ir_optimize(ir, NULL);
        static const char *names[3] = {"composite.albedo", "composite.normal",
                                       "composite.roughness"};
        for (int r = 0; r < 3; r++)
            fb.roots[k][r] = ir_find_root(ir, names[r]);
        fb.tex_of[k] = xcalloc((size_t)ir->ntextures + 1, sizeof(int));
        for (int i = 0; i < ir->ntextures; i++)
            fb.tex_of[k][i] = splat_layout_texture(&b->layout, &ir->textures[i]);
        fb.painted_of[k] = xcalloc((size_t)ir->npainted + 1, sizeof(int));
        for (int i = 0; i < ir->npainted; i++) {
            fb.painted_of[k][i] = -1;
            for (int j = 0; j < b->layout.npainted; j++)
                if (!strcmp(b->layout.painted[j], ir->painted[i].name))
                    fb.painted_of[k][i] = j;
        }
    }
    if (ok) {
        alloc_level0(&fb);
        pthread_mutex_init(&fb.lock, NULL);
        int nth = b->desc->jobs > 1 ? b->desc->jobs : 1;
        pthread_t th[64];
        int started = 0;
        for (int i = 1; i < nth && i < 64; i++)
            if (pthread_create(&th[started], NULL, bake_worker, &fb) == 0)
                started++;
        bake_worker(&fb);
        for (int i = 0; i < started; i++)
            pthread_join(th[i], NULL);
        pthread_mutex_destroy(&fb.lock);
        encode_atlas(b, &fb);
    }
    for (int k = 0; k < nc; k++) {
        if (fb.comp[k].layers || fb.comp[k].ir.nnodes)
            splat_composite_free(&fb.comp[k]);
        free(fb.tex_of[k]);
        free(fb.painted_of[k]);
    }
    for (int i = 0; i < nt; i++)
        if (fb.tex_ok[i])
            tex_free(&fb.tex[i]);
    free(fb.tex);
    free(fb.tex_ok);
    free(fb.comp);
    free(fb.tex_of);
    free(fb.painted_of);
    free(fb.roots);
    free(fb.albedo);
    free(fb.normal);
    free(fb.rough);
    return ok;
}

bool build_far_atlas(build *b)
{
    if (b->desc->far_atlas <= 0)
        return true;
    int w, h;
    if (!atlas_size(b, &w, &h))
        return false;
    if (b->desc->far_bake != SPLAT_FAR_BAKE_CPU && b->desc->far_device) {
        b->far.pending = true;   /* the pack first: the device reads it */
        return true;
    }
    if (b->desc->far_bake == SPLAT_FAR_BAKE_GPU) {
        sg_errorf(b->d, b->loc, SG_E_NO_DEVICE, "--far-bake gpu: this splatc was built "
                  "without the runtime, so it has no device to bake on");
        return false;
    }
    double t0 = splat_now();
    bool ok = bake_on_cpu(b);
    b->far.seconds = splat_now() - t0;
    return ok;
}

bool build_far_atlas_device(build *b, const char *dir)
{
    double t0 = splat_now();
    far_bake fb = {.b = b};
    bool ok = atlas_size(b, &fb.W, &fb.H);
    char msg[sizeof b->far.cpu_why] = "";
    if (ok) {
        alloc_level0(&fb);
        b->far.on_device = b->desc->far_device(b->desc->far_device_user, dir, fb.W, fb.H,
                                               fb.albedo, fb.normal, fb.rough, msg, sizeof msg);
        if (b->far.on_device)
            encode_atlas(b, &fb);
    }
    /* level 0's floats go before a CPU bake allocates its own */
    free(fb.albedo);
    free(fb.normal);
    free(fb.rough);
    if (ok && !b->far.on_device) {
        if (b->desc->far_bake == SPLAT_FAR_BAKE_GPU) {
            sg_errorf(b->d, b->loc, SG_E_NO_DEVICE, "--far-bake gpu: %s", msg);
            ok = false;
        } else {   /* auto: the CPU reference */
            snprintf(b->far.cpu_why, sizeof b->far.cpu_why, "%s", msg);
            ok = bake_on_cpu(b);
        }
    }
    b->far.pending = false;
    b->far.seconds = splat_now() - t0;
    return ok;
}

void build_report_far(const build *b, FILE *out)
{
    if (!b->far.data)
        return;
    fprintf(out, "far atlas: %d x %d texels (%.1f x %.1f m each), %d levels, %zu bytes "
            "(BC1 albedo + BC5 normal + BC4 roughness; RGBA8 + RG8 + R8 would be %.0f), "
            "baked in %.2f s on the %s\n", b->far.width, b->far.height, b->far.texel[0],
            b->far.texel[1], b->far.levels, b->far.n,
            (double)b->far.width * b->far.height * 7.0 * 4.0 / 3.0, b->far.seconds,
            b->far.on_device ? "device" : "CPU");
    if (b->far.cpu_why[0])
        fprintf(out, "far atlas: not baked on a device: %s\n", b->far.cpu_why);
}
