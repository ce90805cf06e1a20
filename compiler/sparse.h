/* sparse.h — painted masks as sparse quad-tree textures (Andersson 2007 §5.2.4,
 * Listing 3; slides 003 "Static sparse mask textures").
 *
 * A painted mask is an 8-bit raster (W x H texels, row-major, row 0 =
 * z 0, sampled bilinearly with clamp to edge at its uv: texel i has its
 * centre at (i + 0.5) / W).  By default it has the heightfield's size and
 * covers the whole terrain; a placed mask has any size and covers a
 * rectangle of the terrain (sparse_place), reading 0 outside it.  It is cut into
 * SPARSE_TILE x SPARSE_TILE tiles ("cells", one indirection texel each).
 * A cell whose values can never be anything but 0 (or 1) is a constant and
 * costs no atlas space; the other cells point into an atlas of unique,
 * padded slots; identical slots (XXH3 hash, then the bytes) are stored
 * once, across all masks.  A mask may store areas at a lower resolution:
 * a cell at quad-tree level L reads a slot that holds the 32 x 32
 * reduced texels of the level-L block containing it (32 * 2^L raster
 * texels per side, each reduced texel the rounded mean of a 2^L x 2^L
 * block of the original).
 *
 * ---- The exact layout (what the pack stores and the runtime uploads) ----
 *
 * cells_x = ceil(W / 32), cells_z = ceil(H / 32), layers = ceil(nmasks / 4).
 * Mask m lives in layer m / 4, channel m % 4 (R, G, B, A) of:
 *
 *   index   uint16 [layers][cells_z][cells_x][4]   VK_FORMAT_R16G16B16A16_UINT,
 *           2D array, nearest, read with texelFetch (usampler2DArray).
 *           0 = constant 0, 0xFFFF = constant 1, otherwise slot + 1.
 *   level   uint8  [layers][cells_z][cells_x][4]   VK_FORMAT_R8G8B8A8_UINT,
 *           2D array, texelFetch: the quad-tree level L (0 = full res).
 *   atlas   atlas_cols x atlas_rows slots of SPARSE_SLOT x SPARSE_SLOT
 *           texels (atlas_width = 36 * cols, atlas_height = 36 * rows);
 *           slot k at (k % cols, k / cols).  SPARSE_R8: R8_UNORM, row-major
 *           bytes.  SPARSE_BC4: BC4_UNORM_BLOCK, (width/4) x (height/4)
 *           8-byte blocks, row-major.  Linear filter, clamp, no mipmaps.
 *
 * A slot's 36 x 36 texels hold the 32 x 32 texels of its tile (or reduced
 * block) at offset SPARSE_PAD = 2, the neighbouring texels of the raster
 * (or of the reduced raster) in the first ring around them (clamped
 * duplicates at the raster's edge) and a copy of that ring in the outer
 * ring, which only pads the slot to a multiple of 4 for BC4.  So bilinear
 * filtering never reads a neighbouring slot, and in R8 a sample equals the
 * raster's bilinear sample, also across tile borders (no seams).
 *
 * Sampling (SPARSE_GLSL_FUNCTIONS and its CPU twin sparse_sample):
 *   t    = uv * vec2(W, H)                    raster texel units
 *   cell = clamp(floor(t / 32), 0, cells - 1); e, L = index, level at cell
 *   e == 0 -> 0.0, e == 0xFFFF -> 1.0, otherwise
 *   q    = clamp(t / 2^L - 32 * (cell >> L), 0, 32)
 *   value = bilinear(atlas, texel coords slot_origin + 2 + q)
 *
 * Against Listing 3: the index is an integer slot (texelFetch, exact at
 * any atlas size) with two reserved constants instead of a normalised
 * XZ index; the level texture holds L, not the scale 2^L; slots carry
 * the padding the listing leaves out; the cell comes from the raster
 * position, so the indirection texel is one 32-texel tile everywhere.
 */
#ifndef SPLAT_SPARSE_H
#define SPLAT_SPARSE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

enum {
    SPARSE_TILE = 32,          /* raster texels per cell side                */
    SPARSE_PAD = 2,            /* padding texels on each side of a slot      */
    SPARSE_SLOT = 36,          /* SPARSE_TILE + 2 * SPARSE_PAD               */
    SPARSE_MAX_LEVEL = 7,      /* coarsest quad-tree level a mask may use    */
    SPARSE_MAX_TEXELS = 65536, /* a mask raster's side, at most               */
    SPARSE_CONST0 = 0,         /* index value of a constant-0 cell           */
    SPARSE_CONST1 = 0xFFFF,    /* index value of a constant-1 cell           */
    SPARSE_MAX_SLOTS = 0xFFFE, /* slots an index can address                 */
};

typedef enum sparse_format {
    SPARSE_BC4 = 0,            /* default: 0.5 byte per texel (stb_dxt)      */
    SPARSE_R8,                 /* 1 byte per texel, exact                    */
} sparse_format;

/* Error identities: X(id, printf format). */
#define SPARSE_ERRORS(X)                                                      \
    X(OK,         "no error")                                                 \
    X(IO,         "cannot read '%s': %s")                                     \
    X(BAD_SIZE,   "mask raster '%s' is %dx%d, the heightfield is %dx%d")      \
    X(BAD_CHANNELS, "mask raster '%s' has %d channels, expected 1 (greyscale)") \
    X(BAD_DEPTH,  "mask raster '%s' is 16-bit, expected 8-bit greyscale")     \
    X(BAD_OPTION, "mask '%s': %s")                                            \
    X(TOO_MANY_TILES, "%d unique mask tiles, at most %d fit an index")        \
    X(BAD_FILE,   "'%s' is not a sparse mask file: %s")

typedef enum sparse_error_id {
#define X(id, fmt) SPARSE_E_##id,
    SPARSE_ERRORS(X)
#undef X
    SPARSE_E_COUNT
} sparse_error_id;

typedef struct sparse_error {
    sparse_error_id id;
    char            msg[512];  /* formatted message, no location: the caller
                                  prefixes the scene file's file:line:col */
} sparse_error;

/* ---- sparse.c: builder, CPU sampler, ranges, memory report --------------- */

/* One mask.  Zero-initialised = full resolution everywhere, the
 * heightfield's size, over the whole terrain. */
typedef struct sparse_mask_desc {
    const char    *name;       /* for reports and errors                     */
    const uint8_t *texels;     /* width*height bytes, row-major, 255 = 1.0   */
    int    width, height;      /* the mask's raster; 0: the desc's (heightfield) */
    double rect[4];            /* terrain uv u0 v0 u1 v1 the raster covers;
                                  all 0: 0 0 1 1 (see sparse_place)          */
    int    max_level;          /* coarsest level allowed, 0..SPARSE_MAX_LEVEL */
    double max_error;          /* a block is reduced to level L only if its
                                  max |reduced - original| bilinear sample
                                  error is <= this (0..1; 1 = always)        */
    int    near[4];            /* texel rect x0, z0, x1, z1 kept at level 0
                                  (the area seen from close); x1 <= x0: none */
} sparse_mask_desc;

typedef struct sparse_desc {
    int width, height;               /* the heightfield's texels             */
    const sparse_mask_desc *masks;
    int nmasks;
    sparse_format format;
} sparse_desc;

/* Per-mask figures of a build. */
typedef struct sparse_mask_info {
    char  *name;
    int    max_level;
    int    const0, const1;   /* cells that are constant 0 / constant 1       */
    int    stored;           /* cells that read an atlas slot                */
    int    reduced;          /* of those, cells at a level > 0               */
    int    new_slots;        /* slots this mask added (not shared earlier)   */
    double reduce_error;     /* max bilinear error of its reduced blocks
                                against the original (exact, before BC4)     */
} sparse_mask_info;

/* Where mask m lies (painted NAME = "FILE" { origin = X Z, size = W H }):
 * its width x height raster covers the terrain-uv rectangle rect, so a
 * fragment at terrain uv reads the mask at
 *   muv = (uv - rect.xy) / (rect.zw - rect.xy),  t = muv * (width, height)
 * and 0 where muv leaves [0, 1].  A mask that is not placed has the
 * heightfield's size and rect 0 0 1 1: muv = uv, clamp to edge as before.
 * Its cells are the first cells_x x cells_z of the shared index grid. */
typedef struct sparse_place {
    int    width, height;
    int    cells_x, cells_z;
    double rect[4];
} sparse_place;

typedef struct sparse_masks {
    int width, height, nmasks;       /* width, height: the heightfield's     */
    sparse_format format;
    int cells_x, cells_z, layers;    /* the index grid: the largest mask's   */
    sparse_place *place;             /* nmasks                               */
    uint16_t *index;         /* [layers][cells_z][cells_x][4]                */
    uint8_t  *level;         /* [layers][cells_z][cells_x][4]                */
    int nslots, atlas_cols, atlas_rows, atlas_width, atlas_height;
    uint8_t  *atlas;         /* R8 bytes or BC4 blocks (see above)           */
    size_t    atlas_bytes;
    float    *lo, *hi;       /* [nmasks][cells_z][cells_x]: bounds of every
                                value sampled in the cell (see sparse_range) */
    sparse_mask_info *info;  /* nmasks; empty after sparse_read              */
} sparse_masks;

/* Build the sparse representation.  Deterministic: the same desc gives
 * byte-identical data.  On error returns false with err filled and *s
 * zeroed. */
bool sparse_build(sparse_masks *s, const sparse_desc *d, sparse_error *err);
void sparse_free(sparse_masks *s);

/* Whether mask m is placed (not heightfield-sized over the whole terrain). */
bool sparse_placed(const sparse_masks *s, int mask);

/* CPU twin of the GLSL: mask m at terrain uv, bilinear in the atlas
 * (BC4 decoded with the format's palette, in float), 0 outside a placed
 * mask's rectangle. */
double sparse_sample(const sparse_masks *s, int mask, double u, double v);

/* The reference: the raster's bilinear sample at uv, clamp to edge. */
double sparse_raster_bilinear(const uint8_t *texels, int width, int height,
                              double u, double v);

/* Bounds of mask m over every fragment whose mask raster position t
 * lies in the texel rectangle [x0, x1) x [z0, z1): the union of the cells'
 * bounds, each the min/max over (a) the original raster's bilinear
 * footprint of the cell (so the CPU reference is inside), (b) the stored
 * data the GPU reads for the cell (decoded BC4, reduced levels), and (c)
 * the border texels of the neighbouring cells' data, which a fragment on
 * the shared edge may read after float rounding.  Exact per tile: a cell
 * whose footprint is all 0 gives [0, 0].  Requires x0 < x1, z0 < z1. */
void sparse_range(const sparse_masks *s, int mask, int x0, int z0, int x1,
                  int z1, double *lo, double *hi);
/* The same over fragments whose heightfield raster position uv * (W, H)
 * lies in [x0, x1) x [z0, z1) (heightfield texels, as the analysis cuts
 * cells): sparse_range for a mask that is not placed; for a placed one the
 * rectangle mapped into the mask's texels, widened by one texel for the
 * float rounding of the mapping, with 0 joined where it reaches outside
 * the mask's rectangle. */
void sparse_range_terrain(const sparse_masks *s, int mask, int x0, int z0, int x1,
                          int z1, double *lo, double *hi);

/* The GLSL a placed pack defines before the prelude (NULL when no mask is
 * placed): SPLAT_PAINTED_PLACED and, per mask, splat_painted_rect[m] =
 * (u0, v0, 1 / (u1 - u0), 1 / (v1 - v0)) and splat_painted_size[m], as
 * float literals that parse to the floats sparse_sample uses.  Malloc'd. */
char *sparse_glsl_places(const sparse_masks *s);

/* Memory report.  atlas_r8 / atlas_bc4: the atlas in each encoding, so the
 * report can show the option not taken. */
typedef struct sparse_stats {
    int    nmasks, cells, nslots;
    size_t dense_bytes;      /* nmasks * W * H, the dense 8-bit rasters       */
    size_t index_bytes, level_bytes, atlas_bytes, total_bytes;
    size_t atlas_r8, atlas_bc4;
    int    const_cells, stored_cells, reduced_cells;  /* over all masks      */
    double fraction;         /* total_bytes / dense_bytes                     */
} sparse_stats;

void sparse_get_stats(const sparse_masks *s, sparse_stats *st);
/* A short table: one line per mask, then the totals next to dense. */
void sparse_print_stats(const sparse_masks *s, FILE *out);

/* Load an 8-bit greyscale PNG (or any format stb_image reads) that must
 * be width x height, into a malloc'd buffer.  Errors: IO, BAD_SIZE,
 * BAD_CHANNELS, BAD_DEPTH. */
bool sparse_load_raster(const char *path, int width, int height,
                        uint8_t **texels, sparse_error *err);

/* The pack file "painted.sparse" (little-endian): "SPLATSPM", u32 version
 * (2), u32 width, height, nmasks, format, cells_x, cells_z, layers, nslots,
 * atlas_cols, atlas_rows; per mask u32 width, height and f64 rect[4]; then
 * index (u16), level, atlas bytes, and the per-cell bounds lo, hi
 * (float32, [nmasks][cells_z][cells_x]).  sparse_read parses a file's `size`
 * bytes: the header is checked for consistency and against `size` before
 * anything is allocated; any mismatch is SPARSE_E_BAD_FILE. */
bool sparse_write(const sparse_masks *s, FILE *f);
bool sparse_read(sparse_masks *s, const uint8_t *data, size_t size, const char *name,
                 sparse_error *err);

/* BC4 (bc4.c): encode one 4x4 block of bytes (row-major) with stb_dxt;
 * decode a block to 16 values in 0..1 with the BC4_UNORM palette. */
void sparse_bc4_encode(uint8_t out[8], const uint8_t in[16]);
void sparse_bc4_decode(const uint8_t in[8], float out[16]);

/* ---- the GLSL sampler ----------------------------------------------------
 * SPARSE_GLSL_FUNCTIONS defines
 *   float splat_sparse_painted(vec2 uv, vec2 size, int mask)
 * with `size` the raster's W, H.  The includer declares (bindings its own):
 *   uniform sampler2D u_painted_atlas;       (R8 or BC4, linear, clamp)
 *   uniform usampler2DArray u_painted_index;  (RGBA16UI)
 *   uniform usampler2DArray u_painted_level;  (RGBA8UI)
 * SPLAT_GLSL_SPARSE is the same text as an array. */
#define SPARSE_GLSL_FUNCTIONS                                                 \
    "float splat_sparse_painted(vec2 uv, vec2 size, int mask) {\n"            \
    "    ivec3 n = textureSize(u_painted_index, 0);\n"                        \
    "    vec2 t = uv * size;\n"                                               \
    "    ivec2 last = min(n.xy, (ivec2(size) + 31) / 32) - 1;\n"                \
    "    ivec2 cell = clamp(ivec2(floor(t * (1.0 / 32.0))), ivec2(0), last);\n" \
    "    ivec3 at = ivec3(cell, mask >> 2);\n"                                \
    "    uint e = texelFetch(u_painted_index, at, 0)[mask & 3];\n"            \
    "    if (e == 0u) return 0.0;\n"                                          \
    "    if (e == 65535u) return 1.0;\n"                                      \
    "    int level = int(texelFetch(u_painted_level, at, 0)[mask & 3]);\n"    \
    "    vec2 q = t * exp2(-float(level)) - vec2(cell >> level) * 32.0;\n"    \
    "    q = clamp(q, vec2(0.0), vec2(32.0));\n"                              \
    "    int slot = int(e) - 1;\n"                                            \
    "    ivec2 asz = textureSize(u_painted_atlas, 0);\n"                      \
    "    int cols = asz.x / 36;\n"                                            \
    "    vec2 px = vec2(float(slot % cols), float(slot / cols)) * 36.0 + 2.0 + q;\n" \
    "    return textureLod(u_painted_atlas, px / vec2(asz), 0.0).r;\n"        \
    "}\n"

extern const char SPLAT_GLSL_SPARSE[];

#endif
