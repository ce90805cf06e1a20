/* compose.h — the compositor that turns a combination into one composite
 * shader (compiler/DESIGN.md §6; compose.c).
 */
#ifndef SPLAT_COMPOSE_H
#define SPLAT_COMPOSE_H

#include "analysis.h"

/* ---- compose.c: composite shaders (compiler/DESIGN.md §6) -------------- */

/* The material-set resources every shader of a pack shares (abi.h, set 1):
 * one uniform slot per param of the source ir (in its order), one binding
 * per distinct texture (file + sampler state, in order of first use), one
 * painted layer per name.  The strings stay owned by the caller. */
typedef struct splat_layout {
    const ir      *src;        /* every material lowered: "<name>.mask", …    */
    sg_program    *prog;       /* holds the compositor; NULL: built-in alpha  */
    const char    *compositor; /* shader name; NULL = "linear_alpha"          */
    const char   **materials;  /* names, bottom (0) first                     */
    int            nmaterials;
    const char   **painted;    /* painted mask names, layer order             */
    int            npainted;
    const char   **vectors;    /* the scene's spline and polygon names, shape
                                  order (vector.c); a painted leaf named
                                  "vector.NAME[.across]" reads one       */
    int            nvectors;
    int           *texture_of; /* src texture index -> layout texture index   */
    int           *textures;   /* layout texture -> its first src texture     */
    int            ntextures;
    /* Texture arrays (abi.h set 1): layout texture t is layer tex_layer[t]
     * of array tex_array[t], bound at SPLAT_BIND_TEXTURE0 + tex_array[t].
     * splat_layout_init gives each texture an array of its own;
     * splat_layout_group_textures shares arrays. */
    int           *tex_array, *tex_layer;
    int            narrays;
    int            nparams;    /* = src->nparams; slot i = src param i        */
    /* every material's precise sites, u_frame.world[k] (precision.c) */
    splat_site     sites[SPLAT_WORLD_SITES];
    int            nsites;
} splat_layout;

/* precision.c.  Find the layout's sites (splat_layout_init calls it). */
bool   splat_sites_find(splat_layout *L);
/* glsl_names.override for `ir` (a composite's emission copy; param_of:
 * its params -> layout slots, -1 for none; input_of: the terrain input a
 * param stands for, -1 for none): the camera-relative forms of the uses
 * of L's sites; free with splat_sites_overrides_free. */
char **splat_sites_overrides(const splat_layout *L, const ir *ir,
                             const int *param_of, const int *input_of,
                             const glsl_names *names);
void   splat_sites_overrides_free(const ir *ir, char **ov);
/* A warning per material whose terrain.position uses stay absolute fp32,
 * with the distance at which their error passes a quarter texel, where
 * the scene's terrain reaches that far from the origin; at the node that
 * reads position (sg_node_reading_input), else at the material. */
struct splat_scene;
void   splat_sites_warn(const struct splat_scene *s, sg_diags *d);

/* `materials` and `painted` arrays are copied (not the strings). */
bool splat_layout_init(splat_layout *L, const ir *src, sg_program *prog,
                       const char *compositor,
                       const char *const *materials, int nmaterials,
                       const char *const *painted, int npainted, sg_diags *d);
bool splat_layout_from_scene(splat_layout *L, const splat_scene *s, sg_diags *d);
/* Compositor shader `name` of `prog` keeps its soundness contract (DESIGN
 * §6): weight 0 where m = 0, T_next 0 where m = 1, over T in [0, 1] —
 * proved with the interval evaluator, or a COMPOSITOR_CONTRACT error at
 * `at` where it proves the contract broken (compose.c says how; slack it
 * can neither prove nor refute passes).  splat_scene_load checks the
 * scene's compositor. */
bool splat_compositor_check(sg_program *prog, const char *name, sg_loc at, sg_diags *d);
/* Whether compositor `name` (NULL: linear_alpha) is normalised: it has a
 * `blend` output, which the composite adds in place of `weight` and divides
 * by the sum of at the end (compiler/DESIGN.md §6.2). */
bool splat_compositor_normalised(const sg_program *prog, const char *name);
void splat_layout_free(splat_layout *L);
/* Share texture arrays: layout textures of one size (w[t] x h[t]), one
 * count of their own mip files (mips[t]) and one sampler state (filter,
 * mip filter, wrap, sRGB) become layers of one array, in first-use order
 * (deterministic), at most SPLAT_MAX_ARRAY_LAYERS to an array. */
void splat_layout_group_textures(splat_layout *L, const int *w, const int *h, const int *mips);
/* Index of the layout texture equal (file + sampler state) to `t`, or -1. */
int  splat_layout_texture(const splat_layout *L, const ir_texture *t);

typedef struct splat_compose_desc {
    const int *materials;  /* scene material indices, top first; the last is
                              the bottom layer: opaque wherever the
                              combination is used, so its mask is taken as 1 */
    int        nmaterials;
    bool       reference;  /* one material alone: a multi-pass reference pass
                              (mask 1 only for scene material 0)             */
} splat_compose_desc;

typedef struct splat_layer {
    int    material;       /* scene material index                          */
    ir_ref T;              /* coverage left before this layer               */
    ir_ref mask;           /* the mask the compositor sees (clamped 0..1)   */
    ir_ref weight;         /* compositor weight                             */
    ir_ref T_next;         /* coverage left after it (NONE for the last)    */
    ir_ref view_mask;      /* its own mask, clamped, for SPLAT_VIEW_MASK    */
    ir_ref out[SG_OUT_COUNT];   /* mask (= .mask) and the surface outputs  */
} splat_layer;

/* One composite: the combination's materials imported into one ir (shared
 * subtrees are one node, duplicate textures merged, params by name), the
 * compositor inlined once per layer, then optimised.  Roots:
 *   "layer<j>.{T,mask,weight,T_next,view_mask,albedo,normal,roughness,height}"
 *   "composite.{albedo,normal,roughness,height}" = sum_j weight_j * s_j
 *   (the normal not yet normalised), for the CPU reference.  With a
 *   normalised compositor (splat_compositor_normalised) layer<j>.weight is
 *   its `blend`, "composite.wsum" = sum_j blend_j and the composite outputs
 *   are divided by it. */
typedef struct splat_composite {
    ir           ir;
    splat_layer *layers;      /* top first                                   */
    int          nlayers;
    bool         reference;
    int         *textures;    /* layout textures used, ascending             */
    int          ntextures;
    int         *params;      /* layout params used, ascending               */
    int          nparams;
} splat_composite;

bool splat_compose(const splat_layout *L, const splat_compose_desc *desc,
                   splat_composite *c, sg_diags *d);
void splat_composite_free(splat_composite *c);

/* After a pass rewrote c->ir (distance.c): the layers' refs found again
 * by their root names, the textures and params used collected again. */
void splat_composite_refresh(const splat_layout *L, splat_composite *c, sg_diags *d);

/* Estimated per-pixel cost of shading with `c` when every layer runs
 * (the most a pixel pays): ir_cost over all its values, in the op table's
 * cost units (ir.h IR_OPS), on a GPU: the side of a mix or select on
 * view.shading_lod that a GPU does not draw (the CPU shading LOD's, dead
 * code once its constant is 0) is not counted, so the LOD's cheaper
 * versions in the node library leave the costs, the distance classes and
 * the runtime's choices as they were.  The manifest's "cost": the runtime
 * picks the cheapest combination covering a tile. */
double splat_composite_cost(const splat_composite *c);

typedef struct splat_glsl_desc {
    const char *title;        /* first header comment line                   */
    bool        flat;         /* no dynamic branches (benchmark variant)     */
    bool        no_mask_view; /* leave out the SPLAT_VIEW_MASK branch        */
    bool        painted_sparse; /* #define SPLAT_PAINTED_SPARSE before the
                                 prelude: painted masks read the sparse
                                 quad-tree (abi.h bindings 2, 5, 6)         */
    const char *painted_places; /* sparse_glsl_places: placed masks' rects
                                 and sizes before the prelude, or NULL      */
    bool        compute;      /* the compute variant: #define SPLAT_COMPUTE
                                 before the prelude (abi.h "compute stage") */
    const int  *ug_slot;      /* with compute: the undergrowth mask variant
                                 (abi.h "undergrowth masks"); per scene
                                 material its slot, -1 for none         */
    bool        no_lazy;      /* no lazy branches (compose.c; benchmark
                                 variant): every mix/select/mul operand
                                 evaluated where its layer is            */
    int        *lazy_branches; /* non-NULL: += the lazy branches made    */
    uint8_t    *lazy_sides;   /* non-NULL (not with compute): per node of
                                 c->ir, bit k set where operand k became
                                 a lazy branch (tests)                   */
} splat_glsl_desc;

/* A mix/select/mul operand side gets its own branch (compose.c "lazy
 * branches") when the work only it needs costs more than this, in ir_cost
 * units (ir.h): one vec4 texture sample (16) with nothing around it stays
 * eager; a sample with its uv arithmetic, or anything dearer, is skipped
 * where its weight is 0. */
#define SPLAT_LAZY_MIN_COST 16

/* The complete Vulkan GLSL 450 fragment shader of `c`: for a composite,
 * front-to-back with every value placed in the innermost region that
 * dominates its uses (`if (T > 0.0)` per layer, nested; the surface under
 * `if (w > 0.0)`); for a reference, one pass under SPLAT_MULTIPASS. */
void splat_composite_glsl(const splat_layout *L, const splat_composite *c,
                          const splat_glsl_desc *desc, ir_buf *out);

/* ---- distance.c: distance classes --------------------------------------- */

/* A variant of a composite valid wherever view.distance lies in [lo, hi]:
 * its values that the interval evaluator proves constant there pinned
 * (opt_pin.c) and folded away.  Cheaper than the composite by ir_cost. */
typedef struct splat_dclass {
    double          lo, hi;    /* metres; hi = INFINITY for "and beyond"    */
    splat_composite comp;
    double          cost;      /* splat_composite_cost(&comp)               */
} splat_dclass;

/* At most this many classes per composite. */
enum { SPLAT_MAX_DCLASSES = 4 };

/* A class is kept only if it saves at least this share of the composite's
 * cost, and at least SPLAT_LAZY_MIN_COST units, against the composite and
 * the class kept before it: each class is one more shader to compile on
 * first use and one more tile list per combination in the screen path's
 * classification (a stochastic compositor's footprint cell gave every
 * combination two classes saving 2 %, and the pass cost 3.5x as much). */
#define SPLAT_DCLASS_MIN_SAVING 0.05

/* The distance classes of composite `c` (distance.c says how the
 * boundaries are found): *out malloc'd (NULL when none), the count
 * returned, cheapest last within each direction. */
int  splat_distance_classes(const splat_layout *L, const splat_composite *c,
                            splat_dclass **out, sg_diags *d);
void splat_dclasses_free(splat_dclass *v, int n);

#endif
