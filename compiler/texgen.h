/* texgen.h — deterministic, tileable textures for the examples (no
 * third-party art): noise fields, images, mip reduction and PNG files.
 *
 * Everything here is a pure function of (size, seed): same inputs give the
 * same pixels on any machine with IEEE doubles, so `splatc texgen` can be
 * re-run and compared with the committed files.
 *
 * Tileability: every field is periodic over the image.  Lattice noise wraps
 * its integer lattice with the period, and every octave uses an integer
 * multiple of the base period, so texel (0, y) continues texel (W-1, y).
 *
 * Mipmaps (the contract with the pack writer and the runtime): a texture
 * "X.png" whose mips must not be box-filtered comes with its reduced levels
 * as "X.mip1.png", "X.mip2.png" … down to 1×1.  A loader that finds
 * "X.mip1.png" uploads those files as the mip chain; otherwise it builds the
 * mips itself by box filtering (2×2 average, what vkCmdBlitImage with a
 * linear filter gives), which is what texgen_reduce TEXGEN_REDUCE_BOX
 * computes.  Today only the uniform-noise texture needs the files: its mips
 * are nearest-neighbour reductions (Billingsley 2009 §2.2: averaging white noise
 * flattens its peaks, so a material that is "highest" on a few texels
 * vanishes in the distance; picking one texel per 2×2 block keeps the
 * value distribution of the level above).
 *
 * Sections: texgen.c (fields, images, examples, PNG), texgen_surfaces.c
 * (the colour PBR surface sets and their swatch sheet); the CLI command is
 * cli_texgen.c (cli.h).
 */
#ifndef SPLAT_TEXGEN_H
#define SPLAT_TEXGEN_H

#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>

/* ---- texgen.c: fields -------------------------------------------------- */

/* 32-bit integer hash of (x, y, seed); a pure function. */
uint32_t texgen_hash(int32_t x, int32_t y, uint32_t seed);

/* Smooth value noise at (x, y), a lattice every `cell` units: values of an
 * integer hash in [0, 1) blended with smoothstep weights (the examples'
 * generated heightfields: examples/minimal, splatc init); not tileable. */
double texgen_value_noise(double x, double y, double cell);

/* Perlin-style 2D gradient noise at (x, y) in lattice units, periodic with
 * px cells in x and py cells in y; unit gradients, quintic fade.  Range
 * about [-0.71, 0.71].  The lattice is shifted by a seed-dependent fraction
 * of a cell so that octaves do not share lattice lines. */
double texgen_gradient(double x, double y, int px, int py, uint32_t seed);

/* fBm of texgen_gradient: `octaves` octaves, octave k at frequency 2^k
 * (periods px·2^k, py·2^k, so still tileable) and amplitude gain^k; the
 * sum is divided by the sum of the amplitudes. */
double texgen_fbm(double x, double y, int px, int py, int octaves,
                  double gain, uint32_t seed);

/* Tileable Worley (cellular) distances at (x, y) in cell units, `period`
 * cells across: f[0] = nearest feature point, f[1] = second nearest. */
void texgen_worley(double x, double y, int period, uint32_t seed, double f[2]);

/* ---- texgen.c: images -------------------------------------------------- */

typedef struct texgen_image {
    int      width, height;
    int      channels;       /* 1 grey, 2 grey+alpha, 3 RGB, 4 RGBA          */
    uint8_t *pixels;         /* row-major, channels bytes per texel          */
} texgen_image;

bool texgen_image_alloc(texgen_image *img, int width, int height, int channels);
void texgen_image_free(texgen_image *img);

/* A square noise image: each channel an independent fBm of gradient noise
 * (period cells across, `octaves`, gain 0.5), stretched to the full 0..255
 * range of that channel. */
bool texgen_perlin(texgen_image *out, int size, int channels, int period,
                   int octaves, uint32_t seed);
/* White noise: every texel of every channel uniform in 0..255. */
bool texgen_uniform(texgen_image *out, int size, int channels, uint32_t seed);

/* Greyscale detail masks for the example materials (values 0..255). */
#define TEXGEN_DETAILS(X)                                                    \
    X(ROCK,   "rock",   "ridged fBm with dark cracks")                       \
    X(GRASS,  "grass",  "anisotropic high-frequency fBm (blades along v)")   \
    X(DIRT,   "dirt",   "fBm clods with small pebbles")                      \
    X(SAND,   "sand",   "wind ripples warped by fBm")                        \
    X(SNOW,   "snow",   "soft, low-contrast fBm")                            \
    X(GRAVEL, "gravel", "cellular stones (Worley F1) with shading")          \
    X(LEAVES, "leaves", "cellular litter (Worley F2-F1) over fBm")

typedef enum texgen_detail {
#define X(id, name, about) TEXGEN_##id,
    TEXGEN_DETAILS(X)
#undef X
    TEXGEN_DETAIL_COUNT
} texgen_detail;

bool texgen_detail_image(texgen_image *out, int size, texgen_detail kind,
                         uint32_t seed);

/* Tangent-space normal map (RGB, 0.5-centred, +z up) from a tileable height
 * image's first channel by central differences (wrapping); `strength`
 * scales the slopes (height 0..1 over one texel per unit). */
bool texgen_normal_map(texgen_image *out, const texgen_image *height,
                       double strength);

/* ---- texgen.c: mips ---------------------------------------------------- */

typedef enum texgen_reduce {
    TEXGEN_REDUCE_BOX,       /* 2x2 average, rounded to nearest             */
    TEXGEN_REDUCE_NEAREST,   /* the texel (2x, 2y) of each 2x2 block        */
} texgen_reduce;

/* Levels in a full chain, the base included: 1 + floor(log2(max(w, h))). */
int  texgen_mip_levels(int width, int height);
/* Next level: each side halved (at least 1); odd sides clamp to the edge. */
bool texgen_mip(const texgen_image *src, texgen_image *dst, texgen_reduce how);

/* ---- texgen.c: files --------------------------------------------------- */

/* 8-bit PNG (img->channels channels), written atomically (temp + rename).
 * On failure returns false and sets *err (malloc'd). */
bool texgen_write_png(const char *path, const texgen_image *img, char **err);
/* 16-bit greyscale PNG of width*height texels (row 0 first). */
bool texgen_write_png16(const char *path, int width, int height,
                        const uint16_t *texels, char **err);
/* "DIR/NAME.png" and, with `mip_files`, "DIR/NAME.mipK.png" for every
 * reduced level (reduced with `how`). */
bool texgen_write_chain(const char *dir, const char *name,
                        const texgen_image *img, texgen_reduce how,
                        bool mip_files, char **err);

/* ---- texgen.c: the example texture set --------------------------------- */

/* The textures the example graphs use, by name ("rock", "uniform" …). */
int         texgen_example_count(void);
const char *texgen_example_name(int i);
const char *texgen_example_about(int i);
/* How the example's mips must be reduced (NEAREST: write the files). */
texgen_reduce texgen_example_reduce(int i);
/* Generate example i at `size` texels square from `seed` (each texture
 * derives its own seed from `seed` and its name). */
bool texgen_example_image(int i, int size, uint32_t seed, texgen_image *out);
/* Write every example into `dir` (which must exist); one line per file to
 * `log` if non-NULL.  `all_mips` also writes box-filtered mip files for the
 * textures that do not need them. */
bool texgen_write_examples(const char *dir, int size, uint32_t seed,
                           bool all_mips, FILE *log, char **err);

/* ---- texgen_surfaces.c: colour PBR surface sets ------------------------ */

/* Procedural ground surfaces, each a set of five images from one height
 * field (tileable, deterministic):
 *   NAME_albedo.png     RGBA: sRGB-encoded colour, its mean linear luminance
 *                       set inside the surface's measured albedo range; the
 *                       height (linear) in alpha, for one-sample materials
 *   NAME_normal.png     RGB tangent-space normal, 0.5-centred, +z out, +x
 *                       along u (columns), +y along v (rows), from the height
 *   NAME_height.png     grey, linear, 0 low .. 255 high
 *   NAME_roughness.png  grey, linear perceptual roughness
 *   NAME_ao.png         grey, linear ambient occlusion (1 open) from the
 *                       height's horizons
 * The albedo ranges and their sources are the table in texgen_surfaces.c. */
typedef struct texgen_surface_set {
    texgen_image albedo, normal, height, roughness, ao;
} texgen_surface_set;

int         texgen_surface_count(void);
const char *texgen_surface_name(int i);     /* "grass", "dry_grass" …       */
const char *texgen_surface_about(int i);
/* The measured range of the surface's mean albedo (linear, 0..1). */
void        texgen_surface_albedo_range(int i, double *lo, double *hi);
/* Generate surface i at `size` texels square (a power of two >= 16). */
bool texgen_surface_make(int i, int size, uint32_t seed, texgen_surface_set *out);
void texgen_surface_free(texgen_surface_set *set);
/* Mean linear luminance (Rec. 709) of an sRGB-encoded RGB(A) image. */
double texgen_mean_albedo(const texgen_image *srgb);
/* Write every surface set into `dir` (which must exist), one log line per
 * surface. */
bool texgen_write_surfaces(const char *dir, int size, uint32_t seed,
                           FILE *log, char **err);
/* The swatch sheet: one row per surface (albedo, normal, height, roughness,
 * AO and a lit preview), labelled, `cell` texels per swatch, as an RGB PNG. */
bool texgen_write_sheet(const char *path, int size, uint32_t seed, int cell,
                        char **err);

#endif
