/* gen_world.c — a synthetic studio-style world for the scale tests and
 * the benchmark (issue 29): B biomes of M materials each over one base,
 * on an fBm heightfield, each biome's materials confined to it by a
 * painted biome mask.
 *
 *   gen_world [--textures] [--view K] [--only K] OUTDIR BIOMES MATERIALS [SIZE [CELL]]
 *
 * writes OUTDIR/scene.sg, OUTDIR/heightfield.png (SIZE x SIZE texels,
 * 16-bit, default 512) and OUTDIR/biome_K.png (8-bit masks, one per biome).
 * The biomes are the cells of a jittered grid (nearest centre), each mask
 * 255 inside its biome and falling to 0 over a 24-texel band across the
 * border, so leaf cells on a border hold two or three biomes' materials and
 * coarse quadtree nodes the union of many (the node-only unions issue 29
 * removes).  Material i of biome b (stack order: base, then biome 0's
 * materials bottom to top, then biome 1's, ...): i = 0 is the biome's
 * ground (its mask alone), the others the mask times a slope, height or
 * noise-free facing rule with thresholds spread over i, so within a biome
 * the materials overlap as a real stack does.  Colours are ALU tints (the
 * structure tests compile nothing).  With --textures every material but
 * the base samples its own texture instead (issue 29: "their own textures,
 * texgen variants, tinted"): OUTDIR/textures/bB_mI.png, an RGB texgen fBm
 * variant (its own seed, period and octaves) tinted with the material's
 * own hue, 64 x 64 for even I and 128 x 128 for odd I (so the build puts
 * them into two texture arrays per 256 layers), sRGB, projected straight
 * down every 4-11 m, times the material's colour constant (the vec3 a
 * one-material edit changes).  Without --textures the output is what it
 * was before the flag existed, byte for byte.  Deterministic: same
 * arguments, same bytes.  --view K adds camera 'biome' above biome K's
 * centre, looking steeply down into it; --only K writes the same terrain and
 * masks but keeps only the base and biome K's materials, with that camera:
 * the world that issue 29's presence comparison holds the full one to. */
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "texgen.h"

static int usage(void)
{
    fprintf(stderr, "usage: gen_world [--textures] [--view K] [--only K] OUTDIR BIOMES MATERIALS "
                    "[SIZE [CELL]]\n"
                    "  BIOMES 1..64, MATERIALS 1..64 per biome (BIOMES x MATERIALS <= 511),\n"
                    "  SIZE 64..4096 texels (default 512), CELL leaf cell texels (default 16);\n"
                    "  --view K adds camera 'biome' looking down into biome K, --only K keeps\n"
                    "  only biome K's materials (and adds that camera)\n");
    return 2;
}

static bool write_text(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    if (!f || fputs(text, f) < 0 || fclose(f) != 0) {
        fprintf(stderr, "gen_world: cannot write %s\n", path);
        return false;
    }
    return true;
}

/* Appends printf output to a growing buffer. */
typedef struct text { char *s; size_t n, cap; } text;

static void put(text *t, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void put(text *t, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    int need = vsnprintf(NULL, 0, fmt, ap);
    va_end(ap);
    if (t->n + (size_t)need + 1 > t->cap) {
        t->cap = (t->n + (size_t)need + 1) * 2;
        t->s = realloc(t->s, t->cap);
        if (!t->s) abort();
    }
    va_start(ap, fmt);
    vsnprintf(t->s + t->n, (size_t)need + 1, fmt, ap);
    va_end(ap);
    t->n += (size_t)need;
}

static double unit(uint32_t h) { return (h & 0xFFFFFF) / 16777216.0; }

/* Material (b, i)'s texture: OUTDIR/textures/bB_mI.png, a one-channel
 * texgen fBm (seeded by b and i, 2-5 cells across, 3-5 octaves) turned into
 * RGB with a hue of the material's own: texel = (0.35 + 0.65 d) * tint,
 * tint in [0.7, 1] per channel. */
static bool write_texture(const char *dir, int b, int i)
{
    uint32_t h = texgen_hash(b, i, 11);
    int size = i % 2 ? 128 : 64, period = 2 + (int)(h % 4), octaves = 3 + (int)(h >> 4) % 3;
    texgen_image grey, rgb;
    if (!texgen_perlin(&grey, size, 1, period, octaves, h)) return false;
    if (!texgen_image_alloc(&rgb, size, size, 3)) {
        texgen_image_free(&grey);
        return false;
    }
    double tint[3] = { 0.7 + 0.3 * unit(h >> 5), 0.7 + 0.3 * unit(h * 2246822519u),
                       0.7 + 0.3 * unit(h * 3266489917u) };
    for (size_t k = 0; k < (size_t)size * size; k++)
        for (int c = 0; c < 3; c++)
            rgb.pixels[3 * k + c] =
                (uint8_t)lrint(255.0 * (0.35 + 0.65 * grey.pixels[k] / 255.0) * tint[c]);
    char path[4096], *err = NULL;
    snprintf(path, sizeof path, "%s/textures/b%d_m%d.png", dir, b, i);
    bool ok = texgen_write_png(path, &rgb, &err);
    if (!ok) fprintf(stderr, "gen_world: %s: %s\n", path, err ? err : "cannot write");
    free(err);
    texgen_image_free(&grey);
    texgen_image_free(&rgb);
    return ok;
}

/* The heightfield at texel coordinates (x, z) of N, 0..1: fBm, ridged a
 * little so slopes vary. */
static double world_height(double x, double z, int N)
{
    double h = 0.5 + 0.9 * texgen_fbm(x / N * 4, z / N * 4, 4, 4, 6, 0.5, 29u);
    return h < 0 ? 0 : h > 1 ? 1 : h;
}

/* What the command line asks for. */
typedef struct world {
    const char *dir;
    int         B, M, N, cell;   /* biomes, materials each, texels, cell */
    bool        textures;
    int         view, only;      /* --view K, --only K; -1 without       */
    double      metres, max_height;
    double     *cx, *cz;         /* biome centres, in texels             */
} world;

static bool wanted(const world *w, int b) { return w->only < 0 || b == w->only; }

static bool parse_world(int argc, char **argv, world *w)
{
    *w = (world){ .view = -1, .only = -1 };
    while (argc > 1 && !strncmp(argv[1], "--", 2)) {
        if (!strcmp(argv[1], "--textures")) {
            w->textures = true;
        } else if (argc > 2 && (!strcmp(argv[1], "--view") || !strcmp(argv[1], "--only"))) {
            char *end;
            long k = strtol(argv[2], &end, 10);
            if (*end || k < 0 || k > 63) return false;
            w->view = (int)k;
            if (argv[1][2] == 'o') w->only = (int)k;
            argv++;
            argc--;
        } else {
            return false;
        }
        argv++;
        argc--;
    }
    if (argc < 4 || argc > 6) return false;
    w->dir = argv[1];
    w->B = atoi(argv[2]), w->M = atoi(argv[3]);
    w->N = argc > 4 ? atoi(argv[4]) : 512, w->cell = argc > 5 ? atoi(argv[5]) : 16;
    w->metres = 4.0 * w->N, w->max_height = 0.25 * w->metres;
    return w->B >= 1 && w->B <= 64 && w->M >= 1 && w->M <= 64 && w->B * w->M <= 511 &&
           w->N >= 64 && w->N <= 4096 && w->cell >= 1 && !(w->cell & (w->cell - 1)) &&
           w->cell <= w->N && w->view < w->B;
}

/* OUTDIR/heightfield.png: 16-bit, world_height at texel centres. */
static bool write_heightfield(const world *w)
{
    int N = w->N;
    uint16_t *hf = malloc((size_t)N * N * sizeof *hf);
    if (!hf) return false;
    for (int z = 0; z < N; z++)
        for (int x = 0; x < N; x++)
            hf[(size_t)z * N + x] = (uint16_t)lrint(world_height(x + 0.5, z + 0.5, N) * 65535.0);
    char path[4096], *err = NULL;
    snprintf(path, sizeof path, "%s/heightfield.png", w->dir);
    bool ok = texgen_write_png16(path, N, N, hf, &err);
    if (!ok) fprintf(stderr, "gen_world: %s: %s\n", path, err ? err : "cannot write");
    free(hf);
    return ok;
}

/* Biome centres on a jittered g x g grid (g = ceil(sqrt(B))), and
 * OUTDIR/biome_K.png: 255 inside biome K (nearest centre), falling to 0
 * over a 24-texel band across the border. */
static bool write_biomes(world *w)
{
    int B = w->B, N = w->N, g = (int)ceil(sqrt((double)B));
    w->cx = malloc((size_t)B * sizeof *w->cx), w->cz = malloc((size_t)B * sizeof *w->cz);
    texgen_image mask;
    if (!w->cx || !w->cz || !texgen_image_alloc(&mask, N, N, 1)) return false;
    for (int b = 0; b < B; b++) {
        int gx = b % g, gz = b / g;
        w->cx[b] = (gx + 0.2 + 0.6 * unit(texgen_hash(gx, gz, 1))) * N / g;
        w->cz[b] = (gz + 0.2 + 0.6 * unit(texgen_hash(gx, gz, 2))) * N / g;
    }
    const double band = 24.0;
    bool ok = true;
    for (int b = 0; b < B && ok; b++) {
        for (int z = 0; z < N; z++)
            for (int x = 0; x < N; x++) {
                double own = hypot(x + 0.5 - w->cx[b], z + 0.5 - w->cz[b]), other = INFINITY;
                for (int k = 0; k < B; k++)
                    if (k != b)
                        other = fmin(other, hypot(x + 0.5 - w->cx[k], z + 0.5 - w->cz[k]));
                /* the distance to the bisector, signed: > 0 inside */
                double v = B == 1 ? 1.0 : 0.5 + (other - own) / band;
                v = v < 0 ? 0 : v > 1 ? 1 : v;
                mask.pixels[(size_t)z * N + x] = (uint8_t)lrint(v * 255.0);
            }
        char path[4096], *err = NULL;
        snprintf(path, sizeof path, "%s/biome_%d.png", w->dir, b);
        ok = texgen_write_png(path, &mask, &err);
        if (!ok) fprintf(stderr, "gen_world: %s: %s\n", path, err ? err : "cannot write");
    }
    texgen_image_free(&mask);
    return ok;
}

/* The textures and their declarations (--textures). */
static bool put_textures(text *t, const world *w)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/textures", w->dir);
    if (mkdir(path, 0777) != 0 && errno != EEXIST) {
        fprintf(stderr, "gen_world: cannot make %s: %s\n", path, strerror(errno));
        return false;
    }
    for (int b = 0; b < w->B; b++)
        for (int i = 0; i < w->M && wanted(w, b); i++) {
            if (!write_texture(w->dir, b, i)) return false;
            put(t, "texture tex_b%d_m%d { file = \"textures/b%d_m%d.png\", filter = linear, "
                   "mip = linear, wrap = repeat, srgb = true }\n", b, i, b, i);
        }
    put(t, "\n");
    return true;
}

/* Material i of biome b: its mask (the biome's alone for i = 0, else times
 * a slope, height or flat-ground rule with thresholds spread over i) and
 * its colour (an ALU tint, or --textures' texture times it). */
static void put_material(text *t, const world *w, int b, int i)
{
    uint32_t h = texgen_hash(b, i, 7);
    double r = 0.15 + 0.6 * unit(h), gr = 0.15 + 0.6 * unit(h >> 3 ^ 0x9e3779b9u),
           bl = 0.1 + 0.5 * unit(h * 2654435761u);
    put(t, "material b%d_m%d {\n    node p : painted { mask = \"biome_%d\" }\n", b, i, b);
    double f = w->M > 1 ? (double)(i - 1) / (w->M - 1) : 0;   /* spread over i */
    if (i == 0) {
        put(t, "    out mask      = p.out\n");
    } else {
        switch (i % 3) {
        case 0:   /* steep ground */
            put(t, "    node r : slope_ramp { lo = %.3f, hi = %.3f }\n", 0.05 + 0.35 * f,
                0.12 + 0.35 * f);
            break;
        case 1:   /* a height band */
            put(t, "    node r : height_ramp { lo = %.1f, hi = %.1f }\n",
                w->max_height * (0.2 + 0.6 * f), w->max_height * (0.25 + 0.6 * f));
            break;
        default:  /* flat ground below a height */
            put(t, "    node s : slope_ramp { lo = %.3f, hi = %.3f }\n"
                   "    node r : sub { a = 1.0, b = s.out }\n", 0.02 + 0.1 * f, 0.08 + 0.1 * f);
            break;
        }
        put(t, "    node k : mul { a = p.out, b = r.out }\n    out mask      = k.out\n");
    }
    if (w->textures) {
        /* the colour constant times the material's own texture,
         * projected straight down every 4-11 m */
        put(t, "    node uv : div { a = terrain.position.xz, b = %.1f }\n"
               "    node tx : sample { tex = tex_b%d_m%d, uv = uv.out }\n"
               "    node c : mul { a = tx.out.rgb, b = vec3(%.3f, %.3f, %.3f) }\n"
               "    out albedo    = c.out\n    out roughness = %.2f\n}\n\n",
            4.0 + (h >> 11) % 8, b, i, 1.5 * r, 1.5 * gr, 1.5 * bl, 0.5 + 0.4 * unit(h >> 7));
    } else {
        put(t, "    out albedo    = vec3(%.3f, %.3f, %.3f)\n    out roughness = %.2f\n}\n\n",
            r, gr, bl, 0.5 + 0.4 * unit(h >> 7));
    }
}

/* The scene block: terrain, materials, painted masks, cameras. */
static void put_scene(text *t, const world *w)
{
    put(t, "scene world_%dx%d {\n    heightfield = \"heightfield.png\"\n", w->B, w->M);
    put(t, "    size = %.0f %.0f\n    max_height = %.0f\n    cell = %d\n", w->metres, w->metres,
        w->max_height, w->cell);
    put(t, "    compositor = linear_alpha\n    materials = [base");
    for (int b = 0; b < w->B; b++)
        for (int i = 0; i < w->M && wanted(w, b); i++) put(t, ", b%d_m%d", b, i);
    put(t, "]\n");
    for (int b = 0; b < w->B; b++)
        if (wanted(w, b)) put(t, "    painted biome_%d = \"biome_%d.png\"\n", b, b);
    put(t, "    camera overview { position = %.0f %.0f %.0f, look = %.0f 0 %.0f }\n",
        -0.2 * w->metres, 0.8 * w->metres, -0.2 * w->metres, 0.5 * w->metres, 0.5 * w->metres);
    if (w->view >= 0) {
        /* above biome K's centre by 0.12 of the biomes' spacing, a quarter
         * of that off it, looking at the ground there: a view inside the
         * biome (issue 29's presence comparison) */
        double x = w->cx[w->view] * 4.0, z = w->cz[w->view] * 4.0;
        double y = world_height(w->cx[w->view], w->cz[w->view], w->N) * w->max_height;
        double up = 0.12 * w->metres / ceil(sqrt((double)w->B));
        put(t, "    camera biome { position = %.1f %.1f %.1f, look = %.1f %.1f %.1f }\n",
            x - 0.25 * up, y + up, z, x, y, z);
    }
    put(t, "}\n");
}

/* OUTDIR/scene.sg (and the textures). */
static bool write_scene(const world *w)
{
    text t = { 0 };
    put(&t, "# gen_world %s%s %d %d %d %d: %d biomes x %d materials over a base "
            "(tests/bench/gen_world.c)\n", w->textures ? "--textures " : "", w->dir, w->B, w->M,
        w->N, w->cell, w->B, w->M);
    if (w->view >= 0)
        put(&t, "# %s %d: %s\n", w->only >= 0 ? "--only" : "--view", w->view,
            w->only >= 0 ? "only this biome's materials, camera 'biome' inside it"
                         : "camera 'biome' inside this biome");
    bool ok = !w->textures || put_textures(&t, w);
    put(&t, "import \"nodes/compositors.sg\"\nimport \"nodes/masks.sg\"\n\n");
    put(&t, "material base {\n    out mask      = 1.0\n    out albedo    = vec3(0.30, 0.28, 0.25)\n"
            "    out roughness = 0.9\n}\n\n");
    for (int b = 0; b < w->B; b++)
        for (int i = 0; i < w->M && wanted(w, b); i++) put_material(&t, w, b, i);
    put_scene(&t, w);
    char path[4096];
    snprintf(path, sizeof path, "%s/scene.sg", w->dir);
    ok = ok && write_text(path, t.s);
    free(t.s);
    return ok;
}

int main(int argc, char **argv)
{
    world w;
    if (!parse_world(argc, argv, &w)) return usage();
    bool ok = write_heightfield(&w) && write_biomes(&w) && write_scene(&w);
    free(w.cx);
    free(w.cz);
    if (ok) printf("gen_world: %s: %d materials (%d biomes x %d + base), %d x %d texels%s\n",
                   w.dir, w.only >= 0 ? w.M + 1 : w.B * w.M + 1, w.only >= 0 ? 1 : w.B, w.M, w.N,
                   w.N, w.textures ? ", a texture each" : "");
    return ok ? 0 : 1;
}
