/* texgen.c — deterministic tileable noise and detail textures, mip
 * reduction, and PNG files (8-bit through stb_image_write, 16-bit through a
 * small writer of our own: stb_image_write has no 16-bit PNG).
 *
 * All fields are evaluated in double precision from integer hashes, so the
 * pixels depend only on (size, seed).  See texgen.h for the mip contract.
 */
#include "texgen.h"
#include "util.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <stb_image_write.h>

/* libstb exports stb_image_write's zlib compressor; its declaration sits in
 * the header's implementation part, so declare it here.  Result: malloc'd,
 * freed with free(). */
unsigned char *stbi_zlib_compress(unsigned char *data, int data_len,
                                  int *out_len, int quality);

static const double TAU = 6.28318530717958647692;

/* ---- errors ------------------------------------------------------------ */

static bool fail(char **err, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));
static bool fail(char **err, const char *fmt, ...)
{
    if (!err)
        return false;
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(NULL, 0, fmt, ap);
    va_end(ap);
    *err = malloc((size_t)n + 1);
    if (*err) {
        va_start(ap, fmt);
        vsnprintf(*err, (size_t)n + 1, fmt, ap);
        va_end(ap);
    }
    return false;
}

/* ---- hashing and lattice noise ----------------------------------------- */

static uint32_t mix32(uint32_t h)
{
    h ^= h >> 16;
    h *= 0x7feb352du;
    h ^= h >> 15;
    h *= 0x846ca68bu;
    h ^= h >> 16;
    return h;
}

uint32_t texgen_hash(int32_t x, int32_t y, uint32_t seed)
{
    uint32_t h = mix32(seed * 0x9e3779b9u + 0x632be5abu);
    h = mix32(h ^ ((uint32_t)x * 0x85ebca6bu));
    h = mix32(h ^ ((uint32_t)y * 0xc2b2ae35u));
    return h;
}

/* A hash of two integers to [0, 1) (texgen_value_noise's lattice values). */
static double hash01(int x, int z)
{
    uint32_t h = (uint32_t)x * 0x8da6b343u ^ (uint32_t)z * 0xd8163841u;
    h ^= h >> 13;
    h *= 0x85ebca6bu;
    h ^= h >> 16;
    return (h & 0xffffff) / 16777216.0;
}

double texgen_value_noise(double x, double z, double cell)
{
    double fx = x / cell, fz = z / cell;
    int ix = (int)floor(fx), iz = (int)floor(fz);
    double ax = fx - ix, az = fz - iz;
    ax = ax * ax * (3 - 2 * ax);
    az = az * az * (3 - 2 * az);
    double a = hash01(ix, iz) + (hash01(ix + 1, iz) - hash01(ix, iz)) * ax;
    double b = hash01(ix, iz + 1) + (hash01(ix + 1, iz + 1) - hash01(ix, iz + 1)) * ax;
    return a + (b - a) * az;
}

static uint32_t hash_str(const char *s)
{
    uint32_t h = 2166136261u;                      /* FNV-1a */
    for (; *s; s++)
        h = (h ^ (uint8_t)*s) * 16777619u;
    return h;
}

static int wrap(int i, int p)
{
    int r = i % p;
    return r < 0 ? r + p : r;
}

static double fade(double t) { return t * t * t * (t * (t * 6 - 15) + 10); }
static double lerp(double a, double b, double t) { return a + (b - a) * t; }

static double smooth(double e0, double e1, double x)
{
    double t = (x - e0) / (e1 - e0);
    t = t < 0 ? 0 : t > 1 ? 1 : t;
    return t * t * (3 - 2 * t);
}

/* Dot of the unit gradient at lattice point (ix, iy) with (dx, dy). */
static double corner(int ix, int iy, uint32_t seed, double dx, double dy)
{
    double a = (double)(texgen_hash(ix, iy, seed) >> 8) * (TAU / 16777216.0);
    return cos(a) * dx + sin(a) * dy;
}

double texgen_gradient(double x, double y, int px, int py, uint32_t seed)
{
    /* A seed-dependent sub-cell shift keeps the lattices of different
     * octaves and layers from lining up (all would otherwise have a lattice
     * line at the texture's edges); a shift keeps the period. */
    uint32_t sh = texgen_hash(-1, -1, seed);
    x += (double)(sh & 0xffff) / 65536.0;
    y += (double)(sh >> 16) / 65536.0;
    double fx0 = floor(x), fy0 = floor(y);
    double fx = x - fx0, fy = y - fy0;
    int x0 = wrap((int)fx0, px), x1 = wrap((int)fx0 + 1, px);
    int y0 = wrap((int)fy0, py), y1 = wrap((int)fy0 + 1, py);
    double n00 = corner(x0, y0, seed, fx, fy);
    double n10 = corner(x1, y0, seed, fx - 1, fy);
    double n01 = corner(x0, y1, seed, fx, fy - 1);
    double n11 = corner(x1, y1, seed, fx - 1, fy - 1);
    double u = fade(fx), v = fade(fy);
    return lerp(lerp(n00, n10, u), lerp(n01, n11, u), v);
}

double texgen_fbm(double x, double y, int px, int py, int octaves,
                  double gain, uint32_t seed)
{
    double sum = 0, norm = 0, amp = 1, f = 1;
    for (int k = 0; k < octaves; k++) {
        sum += amp * texgen_gradient(x * f, y * f, px * (int)f, py * (int)f,
                                     seed + (uint32_t)k * 0x68e31da4u);
        norm += amp;
        amp *= gain;
        f *= 2;
    }
    return norm > 0 ? sum / norm : 0;
}

void texgen_worley(double x, double y, int period, uint32_t seed, double f[2])
{
    double cx = floor(x), cy = floor(y);
    f[0] = f[1] = 1e9;
    for (int dy = -1; dy <= 1; dy++)
        for (int dx = -1; dx <= 1; dx++) {
            int ix = (int)cx + dx, iy = (int)cy + dy;
            uint32_t h = texgen_hash(wrap(ix, period), wrap(iy, period), seed);
            double ox = (double)(h & 0xffff) / 65536.0;
            double oy = (double)(h >> 16) / 65536.0;
            double ddx = ix + ox - x, ddy = iy + oy - y;
            double d = sqrt(ddx * ddx + ddy * ddy);
            if (d < f[0]) {
                f[1] = f[0];
                f[0] = d;
            } else if (d < f[1]) {
                f[1] = d;
            }
        }
}

/* ---- images ------------------------------------------------------------ */

bool texgen_image_alloc(texgen_image *img, int width, int height, int channels)
{
    memset(img, 0, sizeof *img);
    if (width < 1 || height < 1 || channels < 1 || channels > 4)
        return false;
    img->pixels = calloc((size_t)width * height * channels, 1);
    if (!img->pixels)
        return false;
    img->width = width;
    img->height = height;
    img->channels = channels;
    return true;
}

void texgen_image_free(texgen_image *img)
{
    free(img->pixels);
    memset(img, 0, sizeof *img);
}

/* Store field f (size*size doubles) into channel c of img, stretched so
 * its minimum maps to lo and its maximum to hi (0..1), rounded. */
static void store_stretched(texgen_image *img, int c, const double *f,
                            double lo, double hi)
{
    size_t n = (size_t)img->width * img->height;
    double mn = f[0], mx = f[0];
    for (size_t i = 1; i < n; i++) {
        mn = f[i] < mn ? f[i] : mn;
        mx = f[i] > mx ? f[i] : mx;
    }
    for (size_t i = 0; i < n; i++) {
        double t = mx > mn ? (f[i] - mn) / (mx - mn) : 0.5;
        double v = (lo + (hi - lo) * t) * 255.0;
        img->pixels[i * img->channels + c] = (uint8_t)floor(v + 0.5);
    }
}

/* Texel centre of (i, j) in unit coordinates. */
#define UNIT(i, size) (((double)(i) + 0.5) / (double)(size))

bool texgen_perlin(texgen_image *out, int size, int channels, int period,
                   int octaves, uint32_t seed)
{
    if (!texgen_image_alloc(out, size, size, channels))
        return false;
    double *f = malloc(sizeof(double) * size * size);
    if (!f) {
        texgen_image_free(out);
        return false;
    }
    for (int c = 0; c < channels; c++) {
        uint32_t s = seed + (uint32_t)c * 0x3c6ef372u;
        for (int j = 0; j < size; j++)
            for (int i = 0; i < size; i++)
                f[(size_t)j * size + i] =
                    texgen_fbm(UNIT(i, size) * period, UNIT(j, size) * period,
                               period, period, octaves, 0.5, s);
        store_stretched(out, c, f, 0.0, 1.0);
    }
    free(f);
    return true;
}

bool texgen_uniform(texgen_image *out, int size, int channels, uint32_t seed)
{
    if (!texgen_image_alloc(out, size, size, channels))
        return false;
    for (int j = 0; j < size; j++)
        for (int i = 0; i < size; i++)
            for (int c = 0; c < channels; c++)
                out->pixels[((size_t)j * size + i) * channels + c] =
                    (uint8_t)(texgen_hash(i, j, seed + (uint32_t)c) >> 24);
    return true;
}

/* One detail field value at unit coordinates (u, v). */
static double detail_at(texgen_detail kind, double u, double v, uint32_t s)
{
    double w[2];
    switch (kind) {
    case TEXGEN_ROCK: {
        double r = 0, amp = 1, norm = 0;
        for (int k = 0, p = 4; k < 6; k++, p *= 2) {
            r += amp * (1 - fabs(texgen_gradient(u * p, v * p, p, p, s + k)) * 1.41);
            norm += amp;
            amp *= 0.5;
        }
        double crack = fabs(texgen_gradient(u * 8, v * 8, 8, 8, s + 101));
        return r / norm * (0.3 + 0.7 * smooth(0.0, 0.09, crack));
    }
    case TEXGEN_GRASS: {
        double g = texgen_fbm(u * 48, v * 12, 48, 12, 3, 0.6, s);
        double fine = (double)(texgen_hash((int)(u * 4096), (int)(v * 4096), s + 7) >> 8) / 16777216.0;
        return g + 0.12 * fine;
    }
    case TEXGEN_DIRT: {
        double d = texgen_fbm(u * 6, v * 6, 6, 6, 5, 0.55, s);
        texgen_worley(u * 24, v * 24, 24, s + 3, w);
        return d + 0.35 * (1 - smooth(0.0, 0.3, w[0]));
    }
    case TEXGEN_SAND: {
        double warp = texgen_fbm(u * 4, v * 4, 4, 4, 3, 0.5, s);
        double r = 0.5 + 0.5 * sin(TAU * (22 * u + 5 * v) + 9.0 * warp);
        return pow(r, 1.5) + 0.25 * texgen_fbm(u * 32, v * 32, 32, 32, 2, 0.5, s + 9);
    }
    case TEXGEN_SNOW:
        return texgen_fbm(u * 4, v * 4, 4, 4, 4, 0.5, s);
    case TEXGEN_GRAVEL: {
        texgen_worley(u * 16, v * 16, 16, s, w);
        double edge = smooth(0.0, 0.12, w[1] - w[0]);
        return edge * (0.55 + 0.45 * (1 - w[0])) +
               0.1 * texgen_fbm(u * 32, v * 32, 32, 32, 2, 0.5, s + 5);
    }
    case TEXGEN_LEAVES: {
        texgen_worley(u * 20, v * 20, 20, s, w);
        return 0.6 * smooth(0.0, 0.5, w[1] - w[0]) +
               0.4 * texgen_fbm(u * 8, v * 8, 8, 8, 4, 0.5, s + 11);
    }
    case TEXGEN_DETAIL_COUNT:
        break;
    }
    return 0;
}

bool texgen_detail_image(texgen_image *out, int size, texgen_detail kind,
                         uint32_t seed)
{
    if (kind < 0 || kind >= TEXGEN_DETAIL_COUNT || !texgen_image_alloc(out, size, size, 1))
        return false;
    double *f = malloc(sizeof(double) * size * size);
    if (!f) {
        texgen_image_free(out);
        return false;
    }
    for (int j = 0; j < size; j++)
        for (int i = 0; i < size; i++)
            f[(size_t)j * size + i] = detail_at(kind, UNIT(i, size), UNIT(j, size), seed);
    /* Snow stays bright and soft; the others use the full range. */
    if (kind == TEXGEN_SNOW)
        store_stretched(out, 0, f, 0.7, 1.0);
    else
        store_stretched(out, 0, f, 0.0, 1.0);
    free(f);
    return true;
}

bool texgen_normal_map(texgen_image *out, const texgen_image *height,
                       double strength)
{
    int w = height->width, h = height->height, ch = height->channels;
    if (!texgen_image_alloc(out, w, h, 3))
        return false;
#define H(x, y) (height->pixels[((size_t)wrap(y, h) * w + wrap(x, w)) * ch] / 255.0)
    for (int j = 0; j < h; j++)
        for (int i = 0; i < w; i++) {
            double dx = (H(i + 1, j) - H(i - 1, j)) * 0.5 * strength;
            double dy = (H(i, j + 1) - H(i, j - 1)) * 0.5 * strength;
            double n[3] = {-dx, -dy, 1};
            double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
            for (int c = 0; c < 3; c++)
                out->pixels[((size_t)j * w + i) * 3 + c] =
                    (uint8_t)floor((n[c] / len * 0.5 + 0.5) * 255.0 + 0.5);
        }
#undef H
    return true;
}

/* ---- mips -------------------------------------------------------------- */

int texgen_mip_levels(int width, int height)
{
    int m = width > height ? width : height, n = 1;
    while (m > 1) {
        m >>= 1;
        n++;
    }
    return n;
}

bool texgen_mip(const texgen_image *src, texgen_image *dst, texgen_reduce how)
{
    int w = src->width > 1 ? src->width / 2 : 1;
    int h = src->height > 1 ? src->height / 2 : 1;
    int ch = src->channels;
    if (!texgen_image_alloc(dst, w, h, ch))
        return false;
#define S(x, y, c) src->pixels[((size_t)(y) * src->width + (x)) * ch + (c)]
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            int x0 = 2 * x < src->width ? 2 * x : src->width - 1;
            int y0 = 2 * y < src->height ? 2 * y : src->height - 1;
            int x1 = x0 + 1 < src->width ? x0 + 1 : x0;
            int y1 = y0 + 1 < src->height ? y0 + 1 : y0;
            for (int c = 0; c < ch; c++) {
                uint8_t v;
                if (how == TEXGEN_REDUCE_NEAREST)
                    v = S(x0, y0, c);
                else
                    v = (uint8_t)((S(x0, y0, c) + S(x1, y0, c) + S(x0, y1, c) +
                                   S(x1, y1, c) + 2) / 4);
                dst->pixels[((size_t)y * w + x) * ch + c] = v;
            }
        }
#undef S
    return true;
}

/* ---- files ------------------------------------------------------------- */

typedef struct membuf { unsigned char *p; size_t len, cap; bool oom; } membuf;

static void membuf_put(membuf *b, const void *data, size_t n)
{
    if (b->oom)
        return;
    if (b->len + n > b->cap) {
        size_t cap = b->cap ? b->cap : 4096;
        while (cap < b->len + n)
            cap *= 2;
        unsigned char *p = realloc(b->p, cap);
        if (!p) {
            b->oom = true;
            return;
        }
        b->p = p;
        b->cap = cap;
    }
    memcpy(b->p + b->len, data, n);
    b->len += n;
}

static void png_sink(void *ctx, void *data, int size)
{
    membuf_put(ctx, data, (size_t)size);
}

/* Write `n` bytes to `path` atomically (util.h). */
static bool write_atomic(const char *path, const void *data, size_t n, char **err)
{
    if (splat_write_atomic(path, data, n))
        return true;
    return fail(err, "cannot write '%s': %s", path, strerror(errno));
}

bool texgen_write_png(const char *path, const texgen_image *img, char **err)
{
    membuf b = {0};
    int stride = img->width * img->channels;
    if (!stbi_write_png_to_func(png_sink, &b, img->width, img->height,
                                img->channels, img->pixels, stride) || b.oom) {
        free(b.p);
        return fail(err, "%s: PNG encoding failed", path);
    }
    bool ok = write_atomic(path, b.p, b.len, err);
    free(b.p);
    return ok;
}

static uint32_t crc32_of(const unsigned char *p, size_t n, uint32_t crc)
{
    crc = ~crc;
    for (size_t i = 0; i < n; i++) {
        crc ^= p[i];
        for (int k = 0; k < 8; k++)
            crc = (crc >> 1) ^ (0xedb88320u & (0u - (crc & 1)));
    }
    return ~crc;
}

static void put_be32(unsigned char *p, uint32_t v)
{
    p[0] = (unsigned char)(v >> 24);
    p[1] = (unsigned char)(v >> 16);
    p[2] = (unsigned char)(v >> 8);
    p[3] = (unsigned char)v;
}

static void png_chunk(membuf *b, const char *type, const unsigned char *data, size_t n)
{
    unsigned char hdr[8], crc[4];
    put_be32(hdr, (uint32_t)n);
    memcpy(hdr + 4, type, 4);
    membuf_put(b, hdr, 8);
    if (n)
        membuf_put(b, data, n);
    uint32_t c = crc32_of(hdr + 4, 4, 0);
    c = crc32_of(data, n, c);
    put_be32(crc, c);
    membuf_put(b, crc, 4);
}

bool texgen_write_png16(const char *path, int width, int height,
                        const uint16_t *texels, char **err)
{
    if (width < 1 || height < 1)
        return fail(err, "%s: bad image size %dx%d", path, width, height);
    /* Rows: filter byte 2 ("Up") then big-endian samples minus the row above. */
    size_t row = (size_t)width * 2 + 1;
    unsigned char *raw = malloc(row * height);
    if (!raw)
        return fail(err, "%s: out of memory", path);
    for (int y = 0; y < height; y++) {
        unsigned char *r = raw + row * y;
        r[0] = 2;
        for (int x = 0; x < width; x++) {
            uint16_t v = texels[(size_t)y * width + x];
            uint16_t a = y ? texels[(size_t)(y - 1) * width + x] : 0;
            r[1 + 2 * x] = (unsigned char)((v >> 8) - (a >> 8));
            r[2 + 2 * x] = (unsigned char)((v & 255) - (a & 255));
        }
    }
    int zlen = 0;
    unsigned char *z = stbi_zlib_compress(raw, (int)(row * height), &zlen, 8);
    free(raw);
    if (!z)
        return fail(err, "%s: PNG compression failed", path);
    static const unsigned char sig[8] = {137, 80, 78, 71, 13, 10, 26, 10};
    unsigned char ihdr[13];
    put_be32(ihdr, (uint32_t)width);
    put_be32(ihdr + 4, (uint32_t)height);
    ihdr[8] = 16;   /* bit depth            */
    ihdr[9] = 0;    /* greyscale            */
    ihdr[10] = ihdr[11] = ihdr[12] = 0; /* deflate, adaptive filter, no interlace */
    membuf b = {0};
    membuf_put(&b, sig, 8);
    png_chunk(&b, "IHDR", ihdr, 13);
    png_chunk(&b, "IDAT", z, (size_t)zlen);
    png_chunk(&b, "IEND", NULL, 0);
    free(z);
    bool ok = !b.oom ? write_atomic(path, b.p, b.len, err)
                     : fail(err, "%s: out of memory", path);
    free(b.p);
    return ok;
}

static char *join_path(const char *dir, const char *name, int mip)
{
    size_t n = strlen(dir) + strlen(name) + 32;
    char *p = malloc(n);
    if (!p)
        return NULL;
    if (mip)
        snprintf(p, n, "%s/%s.mip%d.png", dir, name, mip);
    else
        snprintf(p, n, "%s/%s.png", dir, name);
    return p;
}

bool texgen_write_chain(const char *dir, const char *name,
                        const texgen_image *img, texgen_reduce how,
                        bool mip_files, char **err)
{
    char *path = join_path(dir, name, 0);
    if (!path)
        return fail(err, "out of memory");
    bool ok = texgen_write_png(path, img, err);
    free(path);
    if (!ok || !mip_files)
        return ok;
    texgen_image cur = *img, next;
    bool owned = false;
    int levels = texgen_mip_levels(img->width, img->height);
    for (int k = 1; ok && k < levels; k++) {
        if (!texgen_mip(&cur, &next, how)) {
            ok = fail(err, "out of memory");
            break;
        }
        if (owned)
            texgen_image_free(&cur);
        cur = next;
        owned = true;
        path = join_path(dir, name, k);
        ok = path ? texgen_write_png(path, &cur, err) : fail(err, "out of memory");
        free(path);
    }
    if (owned)
        texgen_image_free(&cur);
    return ok;
}

/* ---- the example set --------------------------------------------------- */

typedef enum ex_kind { EX_PERLIN, EX_UNIFORM, EX_DETAIL, EX_NORMAL } ex_kind;

static const struct example {
    const char   *name;
    const char   *about;
    ex_kind       kind;
    int           arg;        /* detail kind / channels                  */
    int           period, octaves;
    texgen_reduce reduce;
} examples[] = {
    {"noise", "gradient noise, 8 cells, one octave: the octave source of texture fBm",
     EX_PERLIN, 1, 8, 1, TEXGEN_REDUCE_BOX},
    {"perlin", "RGBA, four independent fBm channels (16 cells, 2 octaves; Billingsley 2009's Perlin texture)",
     EX_PERLIN, 4, 16, 2, TEXGEN_REDUCE_BOX},
    {"uniform", "white noise with nearest-neighbour mips (Billingsley 2009 §2.2)",
     EX_UNIFORM, 1, 0, 0, TEXGEN_REDUCE_NEAREST},
#define X(id, name, about) {name, about, EX_DETAIL, TEXGEN_##id, 0, 0, TEXGEN_REDUCE_BOX},
    TEXGEN_DETAILS(X)
#undef X
    {"rock_normal", "tangent-space normal map of the rock detail",
     EX_NORMAL, TEXGEN_ROCK, 0, 0, TEXGEN_REDUCE_BOX},
};
enum { NEXAMPLES = (int)(sizeof examples / sizeof examples[0]) };

int texgen_example_count(void) { return NEXAMPLES; }
const char *texgen_example_name(int i) { return i >= 0 && i < NEXAMPLES ? examples[i].name : NULL; }
const char *texgen_example_about(int i) { return i >= 0 && i < NEXAMPLES ? examples[i].about : NULL; }
texgen_reduce texgen_example_reduce(int i)
{
    return i >= 0 && i < NEXAMPLES ? examples[i].reduce : TEXGEN_REDUCE_BOX;
}

bool texgen_example_image(int i, int size, uint32_t seed, texgen_image *out)
{
    memset(out, 0, sizeof *out);
    if (i < 0 || i >= NEXAMPLES || size < 1)
        return false;
    const struct example *e = &examples[i];
    uint32_t s = seed ^ hash_str(e->name);
    switch (e->kind) {
    case EX_PERLIN:
        return texgen_perlin(out, size, e->arg, e->period, e->octaves, s);
    case EX_UNIFORM:
        return texgen_uniform(out, size, e->arg, s);
    case EX_DETAIL:
        return texgen_detail_image(out, size, (texgen_detail)e->arg, s);
    case EX_NORMAL: {
        /* The same field as the "rock" example, so the two line up. */
        texgen_image h;
        const char *src = NULL;
#define X(id, name, about) if (e->arg == TEXGEN_##id) src = name;
        TEXGEN_DETAILS(X)
#undef X
        uint32_t hs = seed ^ hash_str(src);
        if (!texgen_detail_image(&h, size, (texgen_detail)e->arg, hs))
            return false;
        bool ok = texgen_normal_map(out, &h, (double)size / 64.0);
        texgen_image_free(&h);
        return ok;
    }
    }
    return false;
}

bool texgen_write_examples(const char *dir, int size, uint32_t seed,
                           bool all_mips, FILE *log, char **err)
{
    for (int i = 0; i < NEXAMPLES; i++) {
        texgen_image img;
        if (!texgen_example_image(i, size, seed, &img))
            return fail(err, "cannot generate texture '%s'", examples[i].name);
        bool files = all_mips || examples[i].reduce == TEXGEN_REDUCE_NEAREST;
        bool ok = texgen_write_chain(dir, examples[i].name, &img,
                                     examples[i].reduce, files, err);
        if (ok && log)
            fprintf(log, "%s/%s.png  %dx%d, %d channel%s%s  (%s)\n", dir,
                    examples[i].name, img.width, img.height, img.channels,
                    img.channels > 1 ? "s" : "",
                    files ? (examples[i].reduce == TEXGEN_REDUCE_NEAREST
                                 ? ", nearest mip files" : ", box mip files") : "",
                    examples[i].about);
        texgen_image_free(&img);
        if (!ok)
            return false;
    }
    return true;
}
