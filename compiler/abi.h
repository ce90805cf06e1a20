/* abi.h — the shader ABI: the one place where generated shaders and the
 * runtime agree on the vertex-to-fragment interface, descriptor sets and
 * bindings, the uniform blocks and the push constants.
 *
 * The compiler's emitter pastes SPLAT_GLSL_PRELUDE (abi.c) into every
 * fragment shader; the runtime fills the C structs below (std140 layout:
 * every member is a vec4 or a mat4, so C and GLSL agree without padding
 * rules) and compiles SPLAT_GLSL_VERTEX for the shared vertex shader.
 *
 * Descriptor set 0 ("terrain"), the same for every pipeline:
 *   binding 0  sampler2D       heightfield, R16_UNORM, linear, clamp to edge
 *   binding 1  uniform block   splat_frame (camera, lights, terrain)
 *   binding 2  sampler2DArray  painted masks, R8_UNORM, one layer per mask,
 *                              linear, clamp (dense until the sparse atlas)
 *              With SPLAT_PAINTED_SPARSE defined before the prelude, the
 *              painted masks are the sparse quad-tree of sparse.h instead:
 *   binding 2  sampler2D       painted atlas, R8_UNORM or BC4_UNORM_BLOCK,
 *                              linear, clamp, one mip level
 *   binding 5  usampler2DArray painted index, RGBA16_UINT, one layer per
 *                              4 masks (mask m: layer m/4, channel m%4)
 *   binding 6  usampler2DArray painted levels, RGBA8_UINT, same shape
 *              and splat_painted(layer) samples them (sparse_sample on the
 *              CPU); the masks must be heightfield-sized (u_frame.texel.xy).
 *   binding 11 sampler2D       sun visibility (fragment, compute), R8_UNORM,
 *                              heightfield-sized, linear, clamp: the
 *                              runtime's shadow map (runtime/shadow.c), read
 *                              by splat_light when u_frame.light.w > 0.
 *   binding 12 sampler2D       holes (vertex stage), R8_UNORM, heightfield-
 *                              sized, linear, clamp: 1 where the terrain is
 *                              cut (a 1x1 texel of 0 when it has none).  The
 *                              shared vertex shader writes gl_ClipDistance[0]
 *                              = 0.5 - holes(uv) (base level, bilinear), so
 *                              the terrain is cut along the 0.5 contour of the
 *                              hole texels -- at their edges on grids of one
 *                              quad per texel or finer, coarser further away
 *                              -- and a clipped pixel is never rasterised:
 *                              no fragment shading, its depth left clear
 *                              (any pass using the shared vertex shader,
 *                              depth-only ones included, sees the hole).
 *   binding 3  sampler2D       destruction atlas, R8_UNORM, linear, clamp
 *   binding 4  sampler2D       destruction indirection, RGBA8_UNORM, nearest:
 *                              .rg * 255 = tile x, y in the atlas; .a = 1 if
 *                              the cell has a tile, 0 if untouched
 * Descriptor set 1 ("material"), one for the whole pack:
 *   binding 0  uniform block   splat_params: every param of the scene, one
 *                              vec4 slot each, in manifest order
 *   binding 1+a sampler2DArray texture array a: the scene's textures of one
 *                              size, mip files and sampler state, one layer
 *                              each (manifest textures[i].array / .layer);
 *                              RGBA8, UNORM or SRGB
 * Push constants (vertex and fragment stages): struct splat_push.
 *
 * Vertex input: location 0, vec2 (R32G32_SFLOAT): the grid position 0..1
 * inside the patch (the shared 33x33 grid).
 * Varyings: location 0 vec3 camera-relative position (m), location 1 vec2
 * heightfield uv, location 2 vec3 terrain-local position (m).
 *
 * Fragment outputs: SPLAT_OUTPUT_* below.  A single-pass shader writes one
 * RGBA32F colour; a multi-pass reference pass (compiled with
 * SPLAT_MULTIPASS defined) writes three targets blended with
 * SRC_ALPHA / ONE_MINUS_SRC_ALPHA that the resolve pass lights.
 *
 * ---- compute stage (screen-space shading) ----------------
 * The compute variant of a composite (or of the über-shader) is the same
 * GLSL with `#define SPLAT_COMPUTE 1` before the prelude (pack: *.comp).
 * The prelude hides the stage:
 *   layout(local_size_x = 8, local_size_y = 8) in;  one workgroup = one
 *   8x8 pixel tile.  Set 0 gains (compute only):
 *   binding 7  sampler2D  u_depth: the geometry pass's depth (D32_SFLOAT,
 *              read with texelFetch, level 0; any sampler)
 *   binding 8  image2D    u_out: rgba32f storage image, the lit colour
 *              (written only for terrain pixels; the runtime writes sky and
 *              fog for empty pixels before the dispatches)
 *   binding 9  buffer     splat_tiles_block { uint tiles[]; } (std430,
 *              readonly): entry = tile_x | tile_y << 16, in tiles (pixel =
 *              tile * 8 + gl_LocalInvocationID.xy)
 *   binding 10 buffer     splat_counters_block (SPLAT_COUNT only, below)
 *   Push constants: struct splat_push; patch_xz / patch_uv are unused,
 *   info.x unused, info.y = combination id (the COMBOS view), info.z =
 *   scene material count, info.w = index of this combination's first tile
 *   in tiles[]: workgroup g shades tiles[info.w + g.x].
 *   main(): the prelude defines the real main(), which reads the tile and
 *   pixel, returns for pixels outside u_frame.screen.xy or whose depth is
 *   u_frame.screen.z (empty / sky), reconstructs the camera-relative
 *   position from depth with u_frame.inv_view_proj (NDC x, y = pixel
 *   centre * 2 / size - 1, Vulkan's downward y; z = depth), sets the
 *   globals that stand for the fragment varyings (v_rel, v_uv from the
 *   position's xz / terrain size, v_local = v_rel + camera), calls the
 *   composite's main (renamed splat_main by a #define), and imageStores
 *   the colour splat_finish left.  Height, slope and normal then come from
 *   the heightfield (Listing 1) through the same functions as in the
 *   fragment stage.  splat_quad_any(c) is c (no quads).
 *   Gradients (both stages): a material texture sample is
 *   splat_texture_grad(tex, uv, duv/dx, duv/dy) (textureLod at the level
 *   textureGrad would take), the gradients the compiler's derivatives
 *   (ir_differentiate.c) of splat_dpdx / splat_dpdy: FC5's plane step,
 *   the plane through the pixel with the terrain normal met by the rays
 *   through the next pixel right / down.  Compute's main sets them from
 *   the depth texel; a fragment composite that samples defines
 *   SPLAT_GRADIENTS before the prelude, whose main then sets them from
 *   gl_FragCoord (and the normal, once) before the composite's.
 *   Textures of the prelude (heightfield, painted, destruction: one mip
 *   level each) read through splat_texture0(s, uv): texture() in the
 *   fragment stage, textureLod(s, uv, 0.0) in compute.  New prelude code
 *   that samples must use it (compute has no implicit derivatives).
 *
 * Sorted variant (SPLAT_SORT, compute only): not stored in the pack
 *   either; the runtime inserts `#define SPLAT_SORT 1` as for SPLAT_COUNT
 *   (the two combine), and may define SPLAT_SORT_TILES, from
 *   SPLAT_SORT_TILES_MIN (the default) to _MAX.  A workgroup of 64 *
 *   SPLAT_SORT_TILES invocations takes SPLAT_SORT_TILES consecutive
 *   entries of tiles[] (workgroup g: tiles[info.w + g.x * SPLAT_SORT_TILES
 *   + i]; an entry of 0xffffffff is padding and shades nothing) and runs
 *   the composite twice per pixel.
 *   First with splat_sorting set: the composite's layer branches are
 *   written as splat_surface(j, w > 0.0) (layer j of the composite,
 *   front to back) and, for an opaque layer, splat_opaque(j); with
 *   splat_sorting they record bit j in splat_layer_bits and return false,
 *   so no surface runs, only the masks and the coverage guards, and
 *   splat_finish returns at once.  The pixels are then counting-sorted in
 *   shared memory by their layer set (folded to 8 bits: SPLAT_SORT_KEYS),
 *   and the second run shades pixel number gl_LocalInvocationIndex of that
 *   order, so the lanes of a subgroup need the same layers and skip the
 *   same surfaces.  The picture is the same (each pixel is computed as in
 *   the plain variant); the sort only decides which lane computes it.
 *   Needs GL_KHR_shader_subgroup_arithmetic and _vote (the runtime
 *   checks).  Counting: layers count in the second run only (the first
 *   runs no surface); samples and branches of both runs count.
 *   Elsewhere splat_surface(j, c) is splat_quad_any(c) and
 *   splat_opaque(j) is true.
 *
 * Counting variant (SPLAT_COUNT, both stages): not stored in the pack.
 *   The runtime compiles it on first use from the pack's GLSL (compute, or
 *   a composite's / the über-shader's fragment GLSL) with
 *   `#define SPLAT_COUNT 1` inserted after the #version line (glslang, as
 *   runtime/shader_compile.c does for its own).  It adds binding 10 and
 *   atomically adds, per terrain pixel, the fields of splat_counters
 *   below.  A fragment counts once it has passed the depth test
 *   (early_fragment_tests: the picture is the same, no shader writes
 *   depth or discards), helper invocations never: on the forward path
 *   "pixels" is the fragments shaded, overdraw included.  Its dynamic
 *   branches are subgroup-uniform in both stages (splat_quad_any is
 *   subgroupAny, GL_KHR_shader_subgroup_vote): a layer counts as evaluated
 *   for every pixel of a subgroup in which any pixel needs it (weight > 0),
 *   which is what the SIMD hardware pays; the picture is the same (a pixel
 *   of weight 0 adds 0 * surface).  "samples" counts the material texture
 *   samples (SAMPLE_GRAD, including the extra ones of noise-warped uvs) of
 *   the blocks the pixel ran, not the prelude's heightfield and painted
 *   reads.  The cost view's row (SPLAT_VIEWS) writes splat_cost_color():
 *   those samples as a heat colour (splat_heat: 0 black, 4 blue, 8 green,
 *   16 yellow, 32 red, 64+ white), black outside the counting variant.
 *   The layers view's row writes splat_layers_color(), numbers to read
 *   back rather than a picture: the set of layers the pixel needs
 *   (layer j as bit j, r bits 0-23, g bits 24-47) and in b 256 times 16
 *   plus its combination, plus the layers its lane evaluated (at most
 *   255), from which splatbench --lanes predicts
 *   the efficiency of other subgroup sizes and pixel-to-lane assignments.
 *
 * ---- undergrowth masks (seed 000 §5.5) ----------------------
 * A combination holding undergrowth-bearing materials also comes as an
 * undergrowth mask shader (pack: NNNN.ug.comp): its compute variant with
 * `#define SPLAT_UNDERGROWTH 1` too.  One invocation per texel of a
 * cell's SPLAT_UG_TEXELS^2 grid (8x8 workgroups, SPLAT_UG_TEXELS / 8
 * squared of them), the texel's centre in terrain-local metres at
 * patch_xz.xy + (texel + 0.5) * patch_xz.z / SPLAT_UG_TEXELS, written
 * only inside the rectangle patch_uv.xy (inclusive) to patch_uv.zw
 * (exclusive), terrain-local metres: the leaf cell whose combination
 * this is (a cell spanning several leaf cells runs each one's); height,
 * normal, painted and destruction masks as in the fragment stage; the
 * view distance is SPLAT_UG_DISTANCE and the view straight down, so the
 * masks depend on the cell alone (the runtime binds a frame block whose
 * camera is the origin).  Set 2 binding 0: buffer splat_ug_block { uint
 * words[]; } (std430), written at info.x + texel index * (info.z + 2):
 * info.z words of packUnorm4x8 composited weights (undergrowth slot s in
 * word s / 4, component s % 4: the weight after the compositor, so a
 * covered layer grows nothing), then packSnorm4x8(terrain normal, 0),
 * then packUnorm4x8(composite albedo, 1).
 *
 * ---- far atlas bake (splatc build --far-bake, far_atlas.h) --
 * Any combination's compute variant with `#define SPLAT_FAR_BAKE 1` too
 * bakes far atlas points on the device.  One invocation per point of the
 * rectangle info.xy (first point) + [0, info.zw) of the bake's point grid
 * (8x8 workgroups), point (i, j) at ((i, j) + 0.5) * patch_xz.xy
 * terrain-local metres (patch_xz.xy: the point spacing), the leaf cell
 * whose combination this is.  Height, normal, painted and destruction
 * masks as in the fragment stage; view.distance FAR_ATLAS_BAKE_DISTANCE,
 * the view straight down and its derivatives 0, the point spacing as the
 * pixel step: the CPU reference's inputs (far_atlas.c); the runtime binds
 * a frame block whose camera and world sites are the origin, as for the
 * undergrowth masks.  Set 2 binding 0:
 * buffer splat_far_block { float v[]; } (std430), 8 floats per point at
 * ((j - info.y + patch_xz.w) * patch_xz.z + i) * 8: albedo rgb and
 * roughness clamped to [0, 1], the unit normal, then 1 (a point shaded).
 */
#ifndef SPLAT_ABI_H
#define SPLAT_ABI_H

#include <math.h>
#include <stdint.h>

#define SPLAT_ABI_VERSION 7   /* 2: splat_frame.light; 3: GGX lighting, screen.w;
                                 4: splat_surface / splat_opaque, SPLAT_SORT;
                                 5: set 1's textures are sampler2DArray layers;
                                    terrain vertices on the lattice (splat_push);
                                    SPLAT_BIND_VECTORS, SPLAT_VECTORS;
                                 6: the prelude's splat_layers_color (view 9)
                                    and SPLAT_SPEC_LOD (the CPU shading LOD):
                                    the runtime cuts a pack's GLSL at the
                                    prelude it carries, so a new prelude is a
                                    new ABI;
                                 7: the prelude's splat_shading_lod()
                                    (view.shading_lod) */
/* The pack's format version (manifest.json "version", PACK.md): 2 adds
 * vectors.bin, the scene's spline and polygon shapes. */
#define SPLAT_PACK_VERSION 3

/* Undergrowth masks (above): texels per cell side, undergrowth-bearing
 * materials at most (4 per word), the fixed view distance (m). */
#define SPLAT_UG_TEXELS 64
#define SPLAT_UG_SLOTS 16
#define SPLAT_UG_DISTANCE 2.0

enum {
    SPLAT_SET_TERRAIN = 0,
    SPLAT_SET_MATERIAL = 1,

    SPLAT_BIND_HEIGHTFIELD = 0,
    SPLAT_BIND_FRAME = 1,
    SPLAT_BIND_PAINTED = 2,
    SPLAT_BIND_DESTRUCTION_ATLAS = 3,
    SPLAT_BIND_DESTRUCTION_INDEX = 4,
    SPLAT_BIND_PAINTED_INDEX = 5,  /* only with SPLAT_PAINTED_SPARSE */
    SPLAT_BIND_PAINTED_LEVEL = 6,  /* only with SPLAT_PAINTED_SPARSE */
    SPLAT_BIND_HOLES = 12,         /* vertex stage: terrain holes         */

    SPLAT_BIND_DEPTH = 7,          /* compute only */
    SPLAT_BIND_OUT = 8,            /* compute only: rgba32f storage image */
    SPLAT_BIND_TILES = 9,          /* compute only: uint tiles[]          */
    SPLAT_BIND_COUNTERS = 10,      /* fragment + compute, SPLAT_COUNT only */
    SPLAT_BIND_SHADOW = 11,        /* fragment + compute: sun visibility,
                                      R8 per heightfield texel (shadow.c) */
    SPLAT_BIND_VECTORS = 13,       /* fragment + compute: the vector shapes'
                                      buffer (below; a 1-word dummy when
                                      the pack has none)                  */

    SPLAT_TILE = 8,                /* compute: pixels per tile side = local size */
    SPLAT_SORT_TILES_MIN = 4,      /* compute, SPLAT_SORT: tiles per workgroup: */
    SPLAT_SORT_TILES_MAX = 16,     /* GLSL's default and the most (1024 lanes)   */
    SPLAT_SORT_KEYS = 256,         /* SPLAT_SORT: layer-set keys (8 bits) */

    SPLAT_BIND_PARAMS = 0,
    SPLAT_BIND_TEXTURE0 = 1,   /* texture i at binding 1 + i */

    SPLAT_GRID = 33,           /* vertices per patch side */
    SPLAT_LATTICE = 32,        /* vertex lattice points per texel (splat_push) */
};

/* Pack limits (compiler/PACK.md "Limits"): what every pack promises and
 * both sides check — splatc build refuses a scene beyond them with a
 * located error, the runtime's loader refuses a pack beyond them, and at
 * renderer creation each size is also checked against the device's own
 * limits (maxImageDimension2D, maxImageArrayLayers, ...). */
enum {
    SPLAT_MAX_HEIGHTFIELD = 16384,  /* texels per heightfield side           */
    SPLAT_MAX_TEXTURE = 16384,      /* texels per side of a texture          */
    SPLAT_MAX_CELLS = 4096,         /* leaf cells per side (heightfield side
                                       / cell); combos.bin <= 45 MB         */
    SPLAT_MAX_PAINTED = 256,        /* painted masks (Vulkan's minimum
                                       maxImageArrayLayers: a dense pack's
                                       layers fit every device)             */
    SPLAT_MAX_DESTRUCTION_CELLS = 1024, /* destruction grid cells per side  */
    SPLAT_MAX_TEXTURES = 4096,      /* textures of a scene (array layers)    */
    SPLAT_MAX_TEXTURE_ARRAYS = 20,  /* set 1 texture arrays (bindings): with
                                       the 9 sampler bindings of set 0, within
                                       the 32 samplers a stage lavapipe has */
    SPLAT_MAX_ARRAY_LAYERS = 256,   /* textures in one array (Vulkan's
                                       guaranteed maxImageArrayLayers)       */
    SPLAT_MAX_MESH_VERTICES = 65536,  /* vertices of one undergrowth mesh    */
    SPLAT_MAX_MESH_INDICES = 196608,  /* indices of one (a triangle list)     */
    SPLAT_MAX_UG_BLOCKS = 64,       /* undergrowth blocks of a pack          */
    SPLAT_MAX_VECTORS = 32,         /* spline and polygon shapes of a scene
                                       (a polygon's inside bit per cell: one
                                       uint of the vector buffer)           */
    SPLAT_MAX_VECTOR_POINTS = 4096, /* control points of one shape           */
    SPLAT_MAX_VECTOR_SEGMENTS = 1 << 20, /* segments of every shape, after a
                                       spline is flattened                  */
    SPLAT_MAX_VECTOR_CELL = 64,     /* segments listed in one grid cell: a
                                       pixel's cost bound                    */
    SPLAT_MAX_VECTOR_GRID = 2048,   /* vector grid cells per side            */
    SPLAT_MAX_VECTOR_WORDS = 1 << 25, /* words of the vector buffer: 128 MiB,
                                       Vulkan's minimum maxStorageBufferRange */
};

/* |width| and |falloff| of a vector shape (m). */
#define SPLAT_MAX_VECTOR_WIDTH 1.0e4

/* The vector shapes' buffer (set 0 binding SPLAT_BIND_VECTORS, std430
 * `uint w[]`, floats as their bits; compiler/vector.c builds it, the pack
 * stores it in vectors.bin, PACK.md).  Words:
 *   header  0 cells_x, 1 cells_z, 2 nshapes, 3 nsegments, 4 nentries,
 *           5 f32 origin x, 6 f32 origin z (terrain-local m), 7 f32 cell (m)
 *   shapes  SPLAT_VEC_SHAPE words each: f32 half width (0 for a polygon),
 *           f32 falloff, u32 profile | kind << 8, 0
 *   cells   SPLAT_VEC_CELL words each, row-major: u32 first entry, u32
 *           count (<= SPLAT_MAX_VECTOR_CELL), u32 inside bits (bit s: the
 *           reference point is inside polygon s), 0, f32 reference x, z
 *           (a point of the cell)
 *   entries u32 segment index, nentries of them
 *   segments SPLAT_VEC_SEG words each: f32 ax, az, bx, bz, u32 shape, 0
 * A cell lists every segment whose distance to the cell (grown by a
 * margin) is at most its shape's reach, half width + falloff. */
enum {
    SPLAT_VEC_HEADER = 8, SPLAT_VEC_SHAPE = 4, SPLAT_VEC_CELL = 6, SPLAT_VEC_SEG = 6,
    SPLAT_VEC_SPLINE = 0, SPLAT_VEC_POLYGON = 1,          /* kinds    */
    SPLAT_VEC_LINEAR = 0, SPLAT_VEC_SMOOTHSTEP = 1,       /* profiles */
};

/* Values of a pack, bounded on both sides (PACK.md "Limits"); every
 * number in the manifest and meshes.bin is finite, too. */
#define SPLAT_MAX_EXTENT 1.0e8      /* |size|, |max_height|, |height_offset|
                                       (m): exact enough as floats on the
                                       GPU, and far past any planet      */
#define SPLAT_MAX_MESH_VALUE 1000.0 /* |each float of a mesh vertex|:
                                       position (m), normal, uv          */
#define SPLAT_MAX_UG_DENSITY 64.0   /* instances per m^2 of one block     */
#define SPLAT_MAX_UG_TEXTURE 1024   /* texels per side of an undergrowth
                                       block's `texture`                 */
#define SPLAT_MAX_UG_TEXTURES 8     /* distinct undergrowth textures     */
#define SPLAT_MAX_UG_WIND 2.0       /* a block's `wind`: sway (m) at 1 m above
                                       the root (runtime/undergrowth.c)  */

/* The undergrowth's instance buffer (runtime/undergrowth.c): a pool of
 * cells SPLAT_UG_CELL metres wide, every cell within the radius around
 * the camera (SPLAT_UG_RADIUS unless the viewer asks for another), each
 * with room for every block's candidates (a jittered grid of
 * splat_ug_candidates(density) points), SPLAT_UG_INSTANCE_BYTES each.
 * The runtime refuses a buffer over the device's maxStorageBufferRange
 * or SPLAT_UG_MAX_INSTANCE_BYTES; splatc refuses a scene whose buffer at
 * the default radius is over SPLAT_UG_PACK_INSTANCE_BYTES, Vulkan's
 * minimum maxStorageBufferRange (lavapipe's), so that every pack's
 * undergrowth fits every device: about 83 instances per m^2 in all. */
#define SPLAT_UG_CELL 16.0
#define SPLAT_UG_RADIUS 96.0
#define SPLAT_UG_INSTANCE_BYTES 32u
#define SPLAT_UG_MAX_INSTANCE_BYTES ((uint64_t)256 << 20)
#define SPLAT_UG_PACK_INSTANCE_BYTES ((uint64_t)128 << 20)

/* Candidates per cell of a block of `density` (a square grid, enough
 * that each is kept with probability density * cell^2 / n^2 <= 1). */
static inline uint32_t splat_ug_candidates(double density)
{
    uint32_t n = (uint32_t)ceil(sqrt(density * SPLAT_UG_CELL * SPLAT_UG_CELL));
    return n * n;
}
/* Cells of the pool for a radius (m): a square of them around the camera. */
static inline uint32_t splat_ug_pool(double radius)
{
    uint32_t side = (uint32_t)ceil(2 * radius / SPLAT_UG_CELL) + 2;
    return side * side;
}

/* Periodic sites of terrain.position (compiler/precision.c): at most this
 * many per pack, each a vec4 of splat_frame.world. */
#define SPLAT_WORLD_SITES 16

/* combos.bin id of a quadtree node that is all hole (PACK.md): it has no
 * combination and is not drawn. */
#define SPLAT_COMBO_HOLE 0xFFFFu
/* combos.bin id of a coarse quadtree node (level >= 1) that no compiled
 * combination covers (PACK.md "combos.bin"): compositions come from leaf
 * cells only, so the runtime shades it from the far atlas where it may,
 * else with the über-shader, and counts it (--stats). */
#define SPLAT_COMBO_UBER 0xFFFEu

/* Specialization constant of every fragment shader that includes the
 * prelude: constant_id SPLAT_SPEC_VIEW, a uint, default
 * SPLAT_SPEC_VIEW_DYNAMIC.  splat_view() returns it, or u_frame.view.x when
 * it is left at the default.  A pipeline specialised to SPLAT_VIEW_FINAL
 * carries no debug-view code at all (lavapipe executes both sides of every
 * branch, so the dead MASK-view block alone cost ~40% of a frame); one left
 * dynamic serves every debug view. */
#define SPLAT_SPEC_VIEW         0
#define SPLAT_SPEC_VIEW_DYNAMIC 0xffffffffu
/* Specialization constant of every shader that includes the prelude:
 * constant_id SPLAT_SPEC_LOD, a uint, default 0 (the full shading).  The
 * runtime sets it to 1 on CPU devices (lavapipe), where every branch's
 * both sides run (llvmpipe masks lanes, it does not jump): the prelude
 * then drops what costs much there and little in the picture, the
 * footprint filter's neighbour normals (splat_fp of splat_d_normal is 0:
 * fwidth of terrain.slope and of the normal's facing take no heightfield
 * gathers; runtime/DESIGN.md "CPU shading LOD"), and graphs read it as
 * the input view.shading_lod (splat_shading_lod(): 1.0 or 0.0), so the
 * node library can draw a cheaper version of itself there (nodes/detile.sg:
 * one hex-tile read instead of three).  Left at 0 the code is the same
 * as without it (GPUs): the LOD side of a mix or select on it is dead
 * once the constant is known. */
#define SPLAT_SPEC_LOD          1
/* A macro's value as a GLSL literal string (the prelude pastes these). */
#define SPLAT_STR_(x) #x
#define SPLAT_STR(x)  SPLAT_STR_(x)

/* Debug views (splat_view(): splat_frame.view.x or the spec constant):
 * one row each.  The prelude's colour switch (abi.c), the multipass
 * resolve (runtime pipelines.c), the runtime's name/key/tone-map tables
 * and the CLI lists are all generated from these rows.
 *
 *   X(id, num, name, key, tonemap, where, glsl)
 *     num      its value in splat_frame.view.x (ABI: never renumber; the
 *              next row takes the next number, rows stay in number order)
 *     name     the --view name
 *     key      the viewer's key that selects it
 *     tonemap  how a screenshot encodes it: FILMIC, SRGB or NONE (rt_tonemap)
 *     where    ALL: the single-pass prelude and the multipass resolve show
 *              it; FORWARD: the single-pass prelude only (the resolve
 *              shows the lit colour); COMPOSITE: the composite writes it
 *              itself before splat_finish (compose.c)
 *     glsl     its colour (vec3) from splat_finish's albedo, n (unit
 *              normal), rough and dist; in the resolve only those four
 *              are available
 *
 * A new view: a row here (and its colour's inputs, if new, in abi.c). */
#define SPLAT_VIEWS(X)                                                              \
    X(FINAL,  0, "final",  '1', FILMIC, ALL,       "splat_light(albedo, n, rough, dist, to_cam)") \
    X(COMBOS, 1, "combos", '2', NONE,   FORWARD,   "splat_combo_color(u_push.info.y)") \
    X(LOD,    2, "lod",    '3', NONE,   FORWARD,   "splat_combo_color(u_push.info.x + 1000u)") \
    X(NORMAL, 3, "normal", '4', NONE,   ALL,       "n * 0.5 + 0.5")                    \
    X(SLOPE,  4, "slope",  '5', NONE,   FORWARD,   "vec3(splat_slope())")              \
    X(MASK,   5, "mask",   '7', NONE,   COMPOSITE, "vec3(0.0)") /* material view.y */  \
    X(ALBEDO, 6, "albedo", '6', SRGB,   ALL,       "albedo")                           \
    X(TILES,  7, "tiles",  '8', NONE,   FORWARD,   "splat_tile_color()")               \
    X(COST,   8, "cost",   '9', NONE,   FORWARD,   "splat_cost_color()")               \
    X(LAYERS, 9, "layers", '0', NONE,   FORWARD,   "splat_layers_color()")

typedef enum splat_view {
#define X(id, num, ...) SPLAT_VIEW_##id = num,
    SPLAT_VIEWS(X)
#undef X
#define X(...) +1
    SPLAT_VIEW_COUNT = 0 SPLAT_VIEWS(X)
#undef X
} splat_view;
/* Rows numbered 0, 1, … in order (the runtime's tables index by number). */
#define X(id, num, ...) _Static_assert(SPLAT_VIEW_##id < SPLAT_VIEW_COUNT, "view " #id);
SPLAT_VIEWS(X)
#undef X

/* GLSL `case` lines of a switch on the view setting `c`, for the rows
 * whose `where` is in the given set (used by abi.c and pipelines.c). */
#define SPLAT_VIEW_CASE_(num, glsl) "    case " #num "u: c = " glsl "; break;\n"
#define SPLAT_VIEW_IN_FORWARD_ALL(num, glsl)       SPLAT_VIEW_CASE_(num, glsl)
#define SPLAT_VIEW_IN_FORWARD_FORWARD(num, glsl)   SPLAT_VIEW_CASE_(num, glsl)
#define SPLAT_VIEW_IN_FORWARD_COMPOSITE(num, glsl)
#define SPLAT_VIEW_IN_RESOLVE_ALL(num, glsl)       SPLAT_VIEW_CASE_(num, glsl)
#define SPLAT_VIEW_IN_RESOLVE_FORWARD(num, glsl)
#define SPLAT_VIEW_IN_RESOLVE_COMPOSITE(num, glsl)
#define SPLAT_VIEW_CASE_FORWARD(id, num, name, key, tm, where, glsl) \
    SPLAT_VIEW_IN_FORWARD_##where(num, glsl)
#define SPLAT_VIEW_CASE_RESOLVE(id, num, name, key, tm, where, glsl) \
    SPLAT_VIEW_IN_RESOLVE_##where(num, glsl)

/* The scene's `light { sun = AZIMUTH ELEVATION, sun_color = R G B,
 * intensity = X, sky = R G B, fog_density = D, fog_height = H, exposure =
 * EV }`, as the parser reads it, the manifest's scene.light carries it and
 * runtime/light.c's rt_light holds it, in this order (runtime/light.c has
 * the defaults of keys left out).  X(id, key, numbers, lo, hi): every
 * number within [lo, hi], the sun's azimuth within -360..360. */
#define SPLAT_LIGHT_KEYS(X)                                                 \
    X(SUN,         "sun",         2, -90.0, 90.0)                           \
    X(SUN_COLOR,   "sun_color",   3, 0.0, 1e4)                              \
    X(INTENSITY,   "intensity",   1, 0.0, 1e4)                              \
    X(SKY,         "sky",         3, 0.0, 1e4)                              \
    X(FOG_DENSITY, "fog_density", 1, 0.0, 1.0)                              \
    X(FOG_HEIGHT,  "fog_height",  1, -1e9, 1e9)                             \
    X(EXPOSURE,    "exposure",    1, -20.0, 20.0)

enum {
#define X(id, key, n, lo, hi) SPLAT_LIGHT_##id,
    SPLAT_LIGHT_KEYS(X)
#undef X
    SPLAT_LIGHT_COUNT
};

typedef struct splat_light_key {
    const char *key;
    int         n;          /* numbers                                    */
    double      lo, hi;
} splat_light_key;

extern const splat_light_key splat_light_keys[SPLAT_LIGHT_COUNT];
/* Number i of key k within its range (the sun's azimuth: -360..360). */
void splat_light_range(int k, int i, double *lo, double *hi);

/* Per-frame uniform block, set 0 binding 1. */
typedef struct splat_frame {
    float view_proj[16];     /* camera-relative world -> clip (column-major) */
    float camera[4];         /* xyz: camera, terrain-local metres            */
    float sun_dir[4];        /* xyz: unit vector towards the sun             */
    float sun_color[4];      /* rgb: sun radiance                            */
    float sky_color[4];      /* rgb: sky ambient (hemisphere, up) and the
                                analytic sky's zenith; a: 1 when that sky
                                is drawn behind the terrain (splat_sky)     */
    float fog[4];            /* rgb: fog colour; a: density per metre        */
    float terrain[4];        /* x: size x (m), y: size z (m), z: max height
                                (m), w: height offset (m)                   */
    float texel[4];          /* x: hf width, y: hf height (texels),
                                z: 1/width, w: 1/height                     */
    float destruction[4];    /* xy: area origin (terrain-local m), z: cell
                                size (m), w: cells per side                  */
    float destruction_atlas[4]; /* x: tile size (px), y: atlas size (px),
                                   z: tiles per atlas row, w: 0            */
    uint32_t view[4];        /* x: splat_view, y: material for MASK view   */
    /* Appended members (std140: vec4 / mat4 only; new ones go last). */
    float inv_view_proj[16]; /* clip -> camera-relative world (inverse of
                                view_proj; compute: depth reconstruction) */
    float screen[4];         /* x: width, y: height (px), z: depth value of
                                empty / sky pixels (0 with reversed Z), w:
                                radians per pixel (vertical field of view /
                                height, for the footprint of a pixel)      */
    /* Site k of the pack's "world_sites" (PACK.md, precision.c): xy =
     * floor(c / S), zw = c / S - xy, with c the camera's two position
     * components of the site and S its scale (c * S for a product),
     * computed in double on the CPU every frame. */
    float world[4 * SPLAT_WORLD_SITES];
    /* Lighting (the scene's `light` block, splatview's options): x: fog
     * base height (terrain-local m), y: fog height falloff (1/m; 0: the
     * same density at every height), z: exposure (a linear factor applied
     * to the lit colour), w: 1 to darken the sun by the shadow map
     * (SPLAT_BIND_SHADOW), 0: no shadows. */
    float light[4];
} splat_frame;

/* Counters of the counting variant (SPLAT_COUNT), set 0 binding 10, std430;
 * every field is a uint atomically added to, summed over the frame's
 * terrain pixels.  The runtime zeroes it before the dispatches. */
typedef struct splat_counters {
    uint32_t pixels;           /* terrain pixels shaded                       */
    uint32_t layers_evaluated; /* layers whose surface block ran              */
    uint32_t layers_needed;    /* layers whose weight is > 0 at the pixel     */
    uint32_t samples;          /* material texture samples taken              */
    uint32_t branches;         /* dynamic branches (splat_quad_any) reached   */
    uint32_t branches_uniform; /* of them, where the whole subgroup agreed    */
} splat_counters;

/* Push constants, vertex + fragment.  The terrain's vertex stage places
 * every vertex on one lattice, SPLAT_LATTICE points per heightfield
 * texel (the finest patch's grid step at cell = 1), by whole lattice
 * index: a vertex's index is the corner's plus a_grid times the side,
 * exact in float (at most SPLAT_MAX_HEIGHTFIELD * SPLAT_LATTICE = 2^19),
 * so a vertex two patches share is computed from the same number by both
 * and comes out bit-identical; camera-relative, it is (index - the
 * camera's cell) * the lattice step - the camera's offset in that cell,
 * the cell and offset computed in double on the CPU (issue 34: patch
 * corners rounded to float relative to the camera left seams along the
 * patch edges).  Other stages read these fields as abi.h says there. */
typedef struct splat_push {
    float    patch_xz[4];  /* xy: patch corner x, z (lattice index, whole);
                              z: patch side (lattice steps); w: 0          */
    float    patch_uv[4];  /* xy: the lattice point at or below the camera
                              (x, z: whole); zw: camera - that point (m)   */
    uint32_t info[4];      /* x: quadtree level, y: combination id,
                              z: scene material count, w: 0              */
} splat_push;

/* The shared GLSL text (abi.c).
 * SPLAT_GLSL_PRELUDE: version line excluded; declares set 0, push
 *   constants, varyings, fragment outputs and these functions:
 *     float splat_height()   vec3 splat_normal()   float splat_slope()
 *     vec3 splat_position()  vec2 splat_uv()        float splat_view_distance()
 *     vec3 splat_offset()  surface - camera, terrain-local metres (precise
 *                          at any distance: precision.c builds on it)
 *     vec3 splat_view_direction() (unit, surface -> camera, terrain-local)
 *     float splat_destruction()   float splat_painted(int layer)
 *     float splat_height_at(vec2 uv)  the mesh's height (bilinear, metres)
 *     float splat_height_smooth_at(vec2 uv)  vec3 splat_normal_at(vec2 uv)
 *     void splat_terrain_at(vec2 uv, out float h, out vec3 n)
 *                          the shading inputs' height and normal: the cubic
 *                          B-spline over the texels and Listing 1 on it
 *     float splat_cavity()  terrain.cavity: the heightfield's mean at 4
 *                          diagonal taps 2 texels away minus the height
 *                          here, metres (4 more height reads)
 *     float splat_shading_lod()  view.shading_lod: 1.0 under the CPU
 *                          shading LOD (SPLAT_SPEC_LOD), else 0.0
 *     void splat_finish(vec3 albedo, vec3 normal, float roughness,
 *                       float height, float coverage)
 *     uint splat_view()   the debug view (SPLAT_SPEC_VIEW above)
 *   splat_finish writes the outputs for the current view (single pass) or
 *   the three blend targets (SPLAT_MULTIPASS).
 * SPLAT_GLSL_LIGHTING: vec3 splat_light(vec3 albedo, vec3 n, float rough,
 *   float dist, vec3 to_camera): sun + sky ambient + (height) fog, times
 *   the exposure (abi.c explains).  Used by the prelude and by the
 *   runtime's resolve pass.
 * SPLAT_GLSL_VERTEX: the complete shared vertex shader (#version included).
 * SPLAT_GLSL_COMBO_COLOR: vec3 splat_combo_color(uint id).
 * SPLAT_GLSL_TERRAIN: set 0's heightfield and frame block, the push block
 *   and splat_height_at(uv), for the runtime's own compute passes (the
 *   screen-space tile classification). */
extern const char SPLAT_GLSL_PRELUDE[];
extern const char SPLAT_GLSL_LIGHTING[];
/* vec3 splat_sky(vec3 d): the analytic sky's radiance along d (abi.c),
 * reading only u_frame: for the runtime's background passes. */
extern const char SPLAT_GLSL_SKY[];
extern const char SPLAT_GLSL_VERTEX[];
extern const char SPLAT_GLSL_COMBO_COLOR[];
extern const char SPLAT_GLSL_TERRAIN[];

/* The normal filter of Andersson 2007 Listing 1, honouring texel aspect, on the
 * CPU, from the heights one texel either side (normalised, 0..1):
 *   n = normalize((hl - hr) * maxh / dx, 2, (hd - hu) * maxh / dz)
 * where dx, dz are the texel spacings in metres (hl, hr: x-1, x+1; hd, hu:
 * z-1, z+1).  splat_normal_at() applies it to the B-spline surface, whose
 * differences hl - hr and hd - hu terrain.c passes as (a, 0, b, 0).
 * Shared by terrain.c and the tests. */
void splat_normal_filter(double hl, double hr, double hd, double hu,
                         double maxh, double dx, double dz, double n[3]);

#endif
