/* analysis.h — the interval analysis that finds the material combinations
 * a scene really has (compiler/DESIGN.md §7; analysis.c), and shading far
 * from the origin (precision.c).
 */
#ifndef SPLAT_ANALYSIS_H
#define SPLAT_ANALYSIS_H

#include "scene_load.h"

/* ---- analysis.c: combinations ------------------------------------------ */

typedef struct splat_combo {
    int     *materials;    /* scene material indices, top first             */
    int      nmaterials;
    int      ncells;       /* leaf cells shaded by it: those with exactly
                              this combination, or (merged) a subset of it */
    int      nnodes;       /* quadtree nodes (all levels) using it           */
} splat_combo;

typedef struct splat_level {
    int       width, height;   /* nodes at this level                        */
    uint16_t *ids;             /* combination id per node, row-major        */
} splat_level;

typedef struct splat_analysis {
    int          cells_x, cells_z, cell_texels;
    splat_combo *combos;       /* the combinations compiled, in a
                                  deterministic order: leaf cells' only     */
    int          ncombos;
    splat_level *levels;       /* 0 = leaf cells, up to a single root node;
                                  a coarse node holds the smallest compiled
                                  combination covering its leaves' union,
                                  or SPLAT_COMBO_UBER where none does       */
    int          nlevels;
    int          largest;      /* most materials in one combination          */
    int          nleaf;        /* distinct leaf-cell combinations found
                                  (ncombos unless merged)                   */
    int          leaf_largest; /* most materials in one leaf cell: the
                                  largest overlap a pixel can need          */
    int          max_combos;   /* the merge's bound P (0: no merging)        */
    int          cover_nodes;  /* coarse nodes whose combination is a strict
                                  superset of their leaves' union           */
    int          uber_nodes;   /* coarse nodes no combination covers         */
    int          hole_cells;   /* leaf cells entirely hole (with their one-
                                  texel ring): id SPLAT_COMBO_HOLE (abi.h),
                                  no combination; nodes all of whose
                                  children are holes are holes too         */
    double       naive_subsets; /* 2^(n-1): every subset above the base       */
    double       seconds;      /* wall time of the analysis                  */
} splat_analysis;

bool splat_analyze(const splat_scene *s, splat_analysis *a, sg_diags *d);
/* splat_analyze, then the leaf combinations covered by at most
 * `max_combos` supersets (0: none merged; analysis.c "merging"). */
bool splat_analyze_merged(const splat_scene *s, int max_combos, splat_analysis *a,
                          sg_diags *d);
void splat_analysis_free(splat_analysis *a);
void splat_analysis_report(const splat_scene *s, const splat_analysis *a, FILE *out);

/* ---- precision.c: shading far from the origin -------------------------- */

/* A periodic site: terrain.position.AB / S (or * S), S a constant or a
 * float param; see precision.c. */
typedef struct splat_site {
    uint32_t swz;        /* IR_SWZ of the two position components         */
    bool     mul;        /* position * S; else position / S               */
    int      param;      /* layout param slot of S (a float), or -1       */
    double   value[2];   /* constant S per component (param: unused)      */
} splat_site;

#endif
