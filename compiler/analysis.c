/* analysis.c — the material combinations a scene really has (compiler/DESIGN.md §7).
 *
 * Leaf cells are cell_texels x cell_texels heightfield texels.  For each
 * cell: splat_terrain_ranges bounds height, slope, normal, position and uv
 * (terrain.c says why soundly), the painted masks are bounded by the min and
 * max of their texels in the bilinear footprint (the cell plus a one-texel
 * ring) or, when the scene carries the sparse masks the pack stores, by
 * sparse_range (the exact bounds of the stored tiles the cell reads, sound
 * for BC4 and reduced levels too), the destruction mask is [0, 1] where the destructible area reaches
 * the cell and 0 elsewhere; where the area comes within two texels of the
 * cell, craters may change the heights the cell's filters read, so height,
 * normal and slope take every value they can (splat_terrain_any_shape).  Then, from the top of the stack down, ir_interval bounds
 * each material's "<name>.mask": the material is present if the upper bound
 * is above 0, opaque if the lower bound is at least 1; the cell's
 * combination is the present materials down to the first opaque one (the
 * bottom material counts as mask 1: always present and opaque).
 *
 * Only leaf cells make combinations: no pixel needs more than the materials
 * that overlap in its own leaf cell, so a coarse quadtree node's union is
 * never compiled (at 256 materials such unions were 317 of 1,140
 * combinations, the largest with 252 layers; issue 29).  A coarse node
 * (level L+1 halves each side, rounding up, until one node remains) gets
 * the union of its leaves' member sets, a material in it if in any leaf's
 * combination, and is drawn with the smallest compiled combination whose
 * set holds that union (fewest materials, then the lowest id); where none
 * does it gets SPLAT_COMBO_UBER and the runtime shades it from the far
 * atlas or with the über-shader.  A superset is sound on every fragment:
 * a material of the superset that a leaf's combination lacks is either
 * absent there (w = 0) or below the leaf's first opaque material (T = 0),
 * and the superset's bottom layer, whose mask the composite takes as 1, is
 * either that leaf's own opaque end or below it.  The screen path picks
 * its tiles' combinations by the same rule (runtime/screen.c).
 *
 * Merging (splat_analyze_merged, `splatc build --max-combinations P`):
 * with P > 0 and more leaf combinations than P, clusters of leaf
 * combinations are merged greedily, each step the pair whose union adds
 * the least work over the cells it shades: merging A and B costs
 * cells(A) W(B \ A) + cells(B) W(A \ B), where W sums each layer's
 * weight, 1 + the ir_cost of its mask: what those cells evaluate for
 * layers that are absent there (the mask, to find w = 0; the surface is
 * skipped), against one pipeline and one dispatch fewer.  Weighing by
 * the mask's cost keeps layers whose masks sample textures out of
 * supersets first.  Each cluster's union is compiled and its leaf cells
 * point at it.  A subset merged into its superset is the cheapest case:
 * {snow} into {snow, dirt, grass} costs W(dirt) + W(grass) per snow cell.
 *
 * Example: stack [grass, dirt, cliff] (bottom first), cliff opaque on a steep
 * cell, dirt partial on a sloped one:
 *     leaf A: {cliff}            leaf B: {dirt, grass}
 *     parent: union {cliff, dirt, grass}, compiled by no leaf: über-shader
 *
 * Holes (scene.h, terrain.holes): a cell whose texels and one-texel ring
 * are all hole is drawn nowhere (the vertex shader clips every vertex that
 * samples only holes, abi.c), so it gets no combination: id
 * SPLAT_COMBO_HOLE, and a node all of whose children are holes is one too
 * (the runtime does not draw them).  A cell partly hole is bounded as
 * usual: its hole texels hold heights filled in from their neighbours
 * (terrain.c), which the filters near the hole's edge really read.
 *
 * Combination ids follow first occurrence in level 0, row-major, so the
 * same scene always gives the same ids.
 *
 * Cost: each cell's terrain and painted ranges are O(its footprint), so the
 * whole analysis is linear in texels; masks are bounded once per cell and
 * material (not per texel), on an ir holding only the masks, and only down
 * to the cell's first opaque material.  Covering a coarse node scans the
 * compiled combinations (after an exact lookup); merging n leaf
 * combinations computes n^2 pair costs once, then per merge step O(n) and
 * a rescan of each cluster whose cheapest partner was merged (at 257
 * materials, 315 combinations merged to 64: 2 s of wall time on the
 * loaded 2-core VM, against 0.5 s for the rest of the analysis).
 */
#include "analysis.h"
#include "util.h"

#include "abi.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* ---- combination table -------------------------------------------------- */

/* Combinations interned by their member bitset (bit i = scene material i). */
typedef struct combo_set {
    splat_analysis *a;
    int             words;     /* uint64 words per member bitset          */
    uint64_t       *keys;      /* ncombos * words, the members of each    */
    int            *slots;     /* hash table: combo index + 1, 0 = empty  */
    int             capslots, capcombos;
} combo_set;

static uint64_t hash_bits(const uint64_t *bits, int words)
{
    uint64_t h = 0xcbf29ce484222325ull;
    for (int w = 0; w < words; w++) {
        h ^= bits[w];
        h *= 0x100000001b3ull;
        h ^= h >> 29;
    }
    return h;
}

static bool set_grow(combo_set *cs)
{
    int cap = cs->capslots ? cs->capslots * 2 : 64;
    int *slots = calloc((size_t)cap, sizeof *slots);
    if (!slots) return false;
    for (int i = 0; i < cs->a->ncombos; i++) {
        uint64_t h = hash_bits(cs->keys + (size_t)i * cs->words, cs->words);
        size_t k = h & (size_t)(cap - 1);
        while (slots[k]) k = (k + 1) & (size_t)(cap - 1);
        slots[k] = i + 1;
    }
    free(cs->slots);
    cs->slots = slots;
    cs->capslots = cap;
    return true;
}

/* The slot of the combination with members `bits`, or the empty slot
 * where it would go (linear probing; the table is never full). */
static size_t set_probe(const combo_set *cs, const uint64_t *bits)
{
    size_t k = hash_bits(bits, cs->words) & (size_t)(cs->capslots - 1);
    size_t bytes = (size_t)cs->words * sizeof *bits;
    while (cs->slots[k] &&
           memcmp(cs->keys + (size_t)(cs->slots[k] - 1) * cs->words, bits, bytes) != 0)
        k = (k + 1) & (size_t)(cs->capslots - 1);
    return k;
}

/* The id of the combination with members `bits`, or -1. */
static int set_lookup(const combo_set *cs, const uint64_t *bits)
{
    if (!cs->capslots) return -1;
    return cs->slots[set_probe(cs, bits)] - 1;
}

/* The id of the combination with members `bits`, added if new; -1 on
 * allocation failure. */
static int set_intern(combo_set *cs, const uint64_t *bits, int nmaterials)
{
    splat_analysis *a = cs->a;
    if ((a->ncombos + 1) * 2 > cs->capslots && !set_grow(cs)) return -1;
    size_t k = set_probe(cs, bits), bytes = (size_t)cs->words * sizeof *bits;
    if (cs->slots[k]) return cs->slots[k] - 1;
    if (a->ncombos == cs->capcombos) {
        int cap = cs->capcombos ? cs->capcombos * 2 : 16;
        uint64_t *keys = realloc(cs->keys, (size_t)cap * bytes);
        if (!keys) return -1;
        cs->keys = keys;
        splat_combo *combos = realloc(a->combos, (size_t)cap * sizeof *combos);
        if (!combos) return -1;
        a->combos = combos;
        cs->capcombos = cap;
    }
    int id = a->ncombos;
    splat_combo *c = &a->combos[id];
    memset(c, 0, sizeof *c);
    int n = 0;
    for (int m = 0; m < nmaterials; m++)
        n += (int)(bits[m / 64] >> (m % 64) & 1);
    c->materials = malloc((size_t)(n ? n : 1) * sizeof *c->materials);
    if (!c->materials) return -1;
    for (int m = nmaterials - 1; m >= 0; m--)      /* top first */
        if (bits[m / 64] >> (m % 64) & 1)
            c->materials[c->nmaterials++] = m;
    memcpy(cs->keys + (size_t)id * cs->words, bits, bytes);
    cs->slots[k] = id + 1;
    a->ncombos++;
    return id;
}

/* set_intern with the errors reported: ids are uint16 (PACK.md). */
static int intern_checked(combo_set *cs, const uint64_t *bits, int nmaterials,
                          const sg_scene *sc, sg_diags *d)
{
    int id = set_intern(cs, bits, nmaterials);
    if (id < 0) {
        sg_error(d, sc->loc, SG_E_OUT_OF_MEMORY, "out of memory in the analysis");
    } else if (id >= (int)SPLAT_COMBO_UBER) {
        sg_error(d, sc->loc, SG_E_OVER_LIMIT,
                 "the scene has more than 65534 material combinations");
        id = -1;
    }
    return id;
}

/* ---- per-cell ranges ---------------------------------------------------- */

static inline int clampi(int v, int lo, int hi)
{
    return v < lo ? lo : v > hi ? hi : v;
}

/* Painted mask bounds over the bilinear footprint of [x0,x1) x [z0,z1).
 * Constant footprints stay exact (a convex combination of equal 8-bit
 * values is that value), so all-0 and all-1 areas stay absent / opaque. */
static ir_iv painted_range(const uint8_t *px, int w, int h,
                           int x0, int z0, int x1, int z1)
{
    int lo = 255, hi = 0;
    for (int j = z0 - 1; j <= z1; j++) {
        const uint8_t *row = px + (size_t)clampi(j, 0, h - 1) * (size_t)w;
        for (int i = x0 - 1; i <= x1; i++) {
            int v = row[clampi(i, 0, w - 1)];
            if (v < lo) lo = v;
            if (v > hi) hi = v;
        }
    }
    ir_iv r = { lo / 255.0, hi / 255.0 };
    if (lo != hi) {             /* filtering arithmetic in float */
        r.lo -= 1e-6;
        r.hi += 1e-6;
    }
    return r;
}

/* Whether the destructible area, grown by `mx`, `mz` metres, meets env's
 * x/z range.  The runtime's indirection grid covers whole cells, as many
 * per side as the longer side needs, so the area is rounded up to that. */
static bool destruction_reaches(const sg_scene *sc, const ir_ienv *env,
                                double mx, double mz)
{
    double cell = sc->destruction_cell;
    double side = fmax(sc->destruction_size[0], sc->destruction_size[1]);
    double extent = ceil(side / cell) * cell;
    double ox = sc->destruction_origin[0], oz = sc->destruction_origin[1];
    return env->position[0].hi >= ox - mx && env->position[0].lo <= ox + extent + mx &&
           env->position[2].hi >= oz - mz && env->position[2].lo <= oz + extent + mz;
}

/* Everything block_combo needs about the scene. */
/* A placed mask (not heightfield-sized over the terrain): without the
 * sparse data the analysis bounds it by [0, 1]. */
static bool placed(const splat_scene *s, int j)
{
    return s->desc->painted[j].place_loc.line > 0;
}

typedef struct block_ctx {
    const splat_scene *s;
    const ir          *mir;         /* the masks alone                     */
    const ir_ref      *masks;       /* mask root of each material (0 unused) */
    const int         *painted_src; /* mir painted k -> scene raster, or -1 */
    const int         *vector_src;  /* mir painted k -> 2 * scene vector shape
                                       + 1 if its across value, or -1    */
    ir_iv             *painted;     /* scratch, one per mir painted mask   */
    double             texel_x, texel_z;
} block_ctx;

/* OR into `bits` the combination of texels [x0, x1) x [z0, z1).  (Bounding
 * sub-blocks of a cell separately and taking their union is sound too, but
 * on colorado 8 x 8 sub-blocks changed 137 leaf combinations to 136 at 14
 * times the cost: the combinations there are real, not interval slack.) */
static void block_combo(const block_ctx *bc, int x0, int z0, int x1, int z1,
                        uint64_t *bits)
{
    const splat_scene *s = bc->s;
    const sg_scene *sc = s->desc;
    const splat_terrain *t = &s->terrain;
    ir_ienv env;
    memset(&env, 0, sizeof env);
    splat_terrain_ranges(t, x0, z0, x1, z1, &env);
    /* The mask is read where the area is; craters lower texels in it,
     * which the filters read from up to two texels (footprint ring + cross
     * taps) outside the block. */
    if (sc->has_destruction) {
        if (destruction_reaches(sc, &env, 0, 0))
            env.destruction = (ir_iv){ 0.0, 1.0 };
        if (destruction_reaches(sc, &env, 2 * bc->texel_x, 2 * bc->texel_z))
            splat_terrain_any_shape(t, &env);
    }
    for (int k = 0; k < bc->mir->npainted; k++) {
        if (bc->painted_src[k] >= 0 && s->sparse) {
            double lo, hi;
            sparse_range_terrain(s->sparse, bc->painted_src[k], x0, z0, x1, z1, &lo,
                                 &hi);
            bc->painted[k] = (ir_iv){ lo, hi };
        } else if (bc->painted_src[k] >= 0 && !placed(s, bc->painted_src[k]))
            bc->painted[k] = painted_range(s->painted[bc->painted_src[k]], t->width,
                                           t->height, x0, z0, x1, z1);
        else if (bc->vector_src[k] >= 0) {
            /* a vector shape: its distance bounded over the block (one
             * texel wider: any texel-centre convention) and the profile,
             * monotone in the distance, at both ends */
            int vs = bc->vector_src[k] >> 1;
            bool across = bc->vector_src[k] & 1;
            double rect[4] = { (x0 - 1) * bc->texel_x, (z0 - 1) * bc->texel_z,
                               (x1 + 1) * bc->texel_x, (z1 + 1) * bc->texel_z };
            double dlo, dhi;
            splat_vector_range(&s->vectors, vs, rect, &dlo, &dhi);
            double a = splat_vector_profile(&s->vectors, vs, dlo, across);
            double b = splat_vector_profile(&s->vectors, vs, dhi, across);
            ir_iv r = { fmin(a, b), fmax(a, b) };
            /* the shader's fp32 profile: interior values within 1e-6 (0
             * and 1 are exact: the clamps) */
            if (r.lo > 0 && r.lo < 1) r.lo = fmax(r.lo - 1e-6, 0.0);
            if (r.hi > 0 && r.hi < 1) r.hi = fmin(r.hi + 1e-6, 1.0);
            bc->painted[k] = r;
        } else
            bc->painted[k] = (ir_iv){ 0.0, 1.0 };   /* no raster: any */
    }
    env.painted = bc->painted;
    env.params = NULL;      /* every param over its [lo, hi] */

    int m = s->nmaterials - 1;
    for (; m > 0; m--) {
        ir_iv out[4];
        ir_interval(bc->mir, bc->masks[m], &env, out);
        bool present = !(out[0].hi <= 0.0);     /* NaN: present */
        bool opaque = out[0].lo >= 1.0;
        if (present) bits[m / 64] |= 1ull << (m % 64);
        if (present && opaque) return;
    }
    if (s->nmaterials > 0) bits[0] |= 1ull;     /* the base: mask 1 */
}

static sg_loc loc_hole(const sg_scene *sc)
{
    if (sc->holes_loc.line > 0) return sc->holes_loc;
    return sc->heightfield_loc.line > 0 ? sc->heightfield_loc : sc->loc;
}

/* Whether texels [x0, x1) x [z0, z1) and their one-texel ring are all
 * holes: then every vertex a patch over them has, at any level, samples
 * holes only (abi.c's clip distance is negative there), so nothing of the
 * cell is drawn and it needs no combination. */
static bool all_hole(const splat_terrain *t, int x0, int z0, int x1, int z1)
{
    if (!t->holes) return false;
    for (int j = z0 - 1; j <= z1; j++)
        for (int i = x0 - 1; i <= x1; i++)
            if (!splat_terrain_hole(t, i, j)) return false;
    return true;
}

static bool bits_empty(const uint64_t *bits, int words)
{
    for (int w = 0; w < words; w++)
        if (bits[w]) return false;
    return true;
}

/* ---- the analysis ------------------------------------------------------- */

/* The masks alone, imported into a small ir of their own (the interval
 * evaluator's cost per call grows with the ir below the root, and the
 * scene's ir is mostly surfaces the analysis never reads): masks[m] is
 * material m's mask root in *mir, painted_src[k] the scene raster of
 * mir's painted mask k (-1: none).  False (error at the scene) if a
 * material has no mask root. */
static bool mask_ir(const splat_scene *s, ir *mir, ir_ref *masks, int **painted_src,
                    int **vector_src, sg_diags *d)
{
    const sg_scene *sc = s->desc;
    bool ok = true;
    ir_import_map *map = ir_import_begin(mir, &s->ir);
    for (int m = 1; m < s->nmaterials; m++) {
        char name[512];
        snprintf(name, sizeof name, "%s.mask", sc->materials[m]);
        ir_ref root = ir_find_root(&s->ir, name);
        if (!ir_ref_ok(root)) {
            char msg[600];
            snprintf(msg, sizeof msg, "material '%s' has no mask root", sc->materials[m]);
            sg_error(d, sc->loc, SG_E_INTERNAL, msg);
            ok = false;
            break;
        }
        masks[m] = ir_import(map, root);
    }
    ir_import_end(map);
    *painted_src = xcalloc((size_t)(mir->npainted ? mir->npainted : 1), sizeof **painted_src);
    for (int k = 0; k < mir->npainted; k++) {
        (*painted_src)[k] = -1;
        for (int j = 0; j < sc->npainted; j++)
            if (s->painted && s->painted[j] &&
                strcmp(mir->painted[k].name, sc->painted[j].name) == 0)
                (*painted_src)[k] = j;
    }
    *vector_src = xcalloc((size_t)(mir->npainted ? mir->npainted : 1), sizeof **vector_src);
    for (int k = 0; k < mir->npainted; k++) {
        bool across;
        int vs = s->vectors.words ? splat_vector_find(sc, mir->painted[k].name, &across) : -1;
        (*vector_src)[k] = vs >= 0 ? 2 * vs + across : -1;
    }
    return ok;
}

/* Levels: 0 = cells, each next one halves the sides (rounding up). */
static void alloc_levels(splat_analysis *a)
{
    int nlevels = 1;
    for (int w = a->cells_x, h = a->cells_z; w > 1 || h > 1; nlevels++) {
        w = (w + 1) / 2;
        h = (h + 1) / 2;
    }
    a->levels = xcalloc((size_t)nlevels, sizeof *a->levels);
    a->nlevels = nlevels;
    for (int L = 0, w = a->cells_x, h = a->cells_z; L < nlevels; L++) {
        a->levels[L].width = w;
        a->levels[L].height = h;
        a->levels[L].ids = xcalloc((size_t)w * (size_t)h, sizeof(uint16_t));
        w = (w + 1) / 2;
        h = (h + 1) / 2;
    }
}

/* Level 0: each cell's combination from its bounds (block_combo), its
 * member bits into bits[cell]. */
static bool analyze_cells(const block_ctx *bc, combo_set *cs, uint64_t *bits, sg_diags *d)
{
    const splat_scene *s = bc->s;
    const splat_terrain *t = &s->terrain;
    splat_analysis *a = cs->a;
    int T = a->cell_texels;
    for (int cz = 0; cz < a->cells_z; cz++)
        for (int cx = 0; cx < a->cells_x; cx++) {
            int x0 = cx * T, z0 = cz * T;
            int x1 = x0 + T < t->width ? x0 + T : t->width;
            int z1 = z0 + T < t->height ? z0 + T : t->height;
            uint64_t *cell = bits + ((size_t)cz * a->cells_x + cx) * cs->words;
            if (all_hole(t, x0, z0, x1, z1)) {     /* no members: a hole */
                a->levels[0].ids[(size_t)cz * a->cells_x + cx] = SPLAT_COMBO_HOLE;
                a->hole_cells++;
                continue;
            }
            block_combo(bc, x0, z0, x1, z1, cell);
            int id = intern_checked(cs, cell, s->nmaterials, s->desc, d);
            if (id < 0)
                return false;
            a->levels[0].ids[(size_t)cz * a->cells_x + cx] = (uint16_t)id;
            a->combos[id].ncells++;
            a->combos[id].nnodes++;
        }
    return true;
}

static bool bits_subset(const uint64_t *a, const uint64_t *b, int words)
{
    for (int w = 0; w < words; w++)
        if (a[w] & ~b[w]) return false;
    return true;
}

/* The smallest compiled combination whose members hold `u` (fewest
 * materials, then the lowest id), or -1; *exact: it is `u` itself. */
static int cover(const combo_set *cs, const uint64_t *u, bool *exact)
{
    int id = set_lookup(cs, u);
    *exact = id >= 0;
    if (id >= 0) return id;
    const splat_analysis *a = cs->a;
    int best = -1;
    for (int i = 0; i < a->ncombos; i++)
        if ((best < 0 || a->combos[i].nmaterials < a->combos[best].nmaterials) &&
            bits_subset(u, cs->keys + (size_t)i * cs->words, cs->words))
            best = i;
    return best;
}

/* Level L from level L - 1: each node the union of its (up to four)
 * children's bits, which *bits holds and is replaced by level L's; its id
 * the compiled combination that covers the union (cover), else
 * SPLAT_COMBO_UBER.  Nothing is interned here: no node-only unions. */
static void analyze_level(combo_set *cs, int L, uint64_t **bits)
{
    splat_analysis *a = cs->a;
    const splat_level *below = &a->levels[L - 1];
    splat_level *lv = &a->levels[L];
    size_t nn = (size_t)lv->width * (size_t)lv->height;
    uint64_t *up = xcalloc(nn * (size_t)cs->words, sizeof *up);
    for (int z = 0; z < lv->height; z++)
        for (int x = 0; x < lv->width; x++) {
            uint64_t *node = up + ((size_t)z * lv->width + x) * cs->words;
            for (int dz = 0; dz < 2; dz++)
                for (int dx = 0; dx < 2; dx++) {
                    int bx = 2 * x + dx, bz = 2 * z + dz;
                    if (bx >= below->width || bz >= below->height) continue;
                    const uint64_t *child = *bits + ((size_t)bz * below->width + bx) * cs->words;
                    for (int w = 0; w < cs->words; w++) node[w] |= child[w];
                }
            uint16_t *id = &lv->ids[(size_t)z * lv->width + x];
            if (bits_empty(node, cs->words)) {    /* every child a hole */
                *id = SPLAT_COMBO_HOLE;
                continue;
            }
            bool exact;
            int c = cover(cs, node, &exact);
            if (c < 0) {
                *id = SPLAT_COMBO_UBER;
                a->uber_nodes++;
                continue;
            }
            *id = (uint16_t)c;
            a->combos[c].nnodes++;
            a->cover_nodes += !exact;
        }
    free(*bits);
    *bits = up;
}

/* ---- merging ------------------------------------------------------------- */

/* Clusters of leaf combinations, merged greedily (the file's comment). */
typedef struct merger {
    int        n, words;
    const int64_t *weight; /* per scene material: its layer's cost where
                              it is absent (1 + its mask's ir_cost)       */
    uint64_t  *u;          /* n * words: each cluster's union            */
    int64_t   *cells;      /* leaf cells the cluster shades               */
    int       *parent;     /* union-find: the cluster a combination is in */
    bool      *alive;
    int       *best;       /* each cluster's cheapest partner             */
    int64_t   *bestd;      /* and that merge's cost                       */
} merger;

/* The weight of the materials in `a` but not in `b`. */
static int64_t extra(const merger *m, const uint64_t *a, const uint64_t *b)
{
    int64_t sum = 0;
    for (int w = 0; w < m->words; w++)
        for (uint64_t x = a[w] & ~b[w]; x; x &= x - 1)
            sum += m->weight[64 * w + __builtin_ctzll(x)];
    return sum;
}

/* What merging clusters i and j adds: each cluster's cells evaluate the
 * other's layers that it lacks (their masks, mostly to find w = 0), in
 * weight units per cell. */
static int64_t merge_cost(const merger *m, int i, int j)
{
    const uint64_t *a = m->u + (size_t)i * m->words, *b = m->u + (size_t)j * m->words;
    return extra(m, b, a) * m->cells[i] + extra(m, a, b) * m->cells[j];
}

static void rescan(merger *m, int i)
{
    m->best[i] = -1;
    for (int j = 0; j < m->n; j++) {
        if (j == i || !m->alive[j]) continue;
        int64_t c = merge_cost(m, i, j);
        if (m->best[i] < 0 || c < m->bestd[i]) {
            m->best[i] = j;
            m->bestd[i] = c;
        }
    }
}

static int find(int *parent, int i)
{
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
}

/* Merge cs's leaf combinations into at most `max` clusters, then replace
 * them by the clusters' unions (ids by first occurrence in level 0) and
 * point level 0 at them.  The leaf member bits (`cells`) are left as they
 * are: coarse nodes cover their exact leaves' union. */
static bool merge(combo_set *cs, int max, const int64_t *weight, const splat_scene *s,
                  sg_diags *d)
{
    splat_analysis *a = cs->a;
    int n = a->ncombos, words = cs->words;
    merger m = { .n = n, .words = words, .weight = weight };
    m.u = xcalloc((size_t)n * words, sizeof *m.u);
    memcpy(m.u, cs->keys, (size_t)n * words * sizeof *m.u);
    m.cells = xcalloc((size_t)n, sizeof *m.cells);
    m.parent = xcalloc((size_t)n, sizeof *m.parent);
    m.alive = xcalloc((size_t)n, sizeof *m.alive);
    m.best = xcalloc((size_t)n, sizeof *m.best);
    m.bestd = xcalloc((size_t)n, sizeof *m.bestd);
    for (int i = 0; i < n; i++) {
        m.cells[i] = a->combos[i].ncells;
        m.parent[i] = i;
        m.alive[i] = true;
    }
    for (int i = 0; i < n; i++) rescan(&m, i);
    for (int left = n; left > max; left--) {
        int r = -1;
        for (int i = 0; i < n; i++)
            if (m.alive[i] && m.best[i] >= 0 && (r < 0 || m.bestd[i] < m.bestd[r])) r = i;
        int i = r < m.best[r] ? r : m.best[r], j = r < m.best[r] ? m.best[r] : r;
        uint64_t *ui = m.u + (size_t)i * words;
        const uint64_t *uj = m.u + (size_t)j * words;
        for (int w = 0; w < words; w++) ui[w] |= uj[w];
        m.cells[i] += m.cells[j];
        m.alive[j] = false;
        m.parent[j] = i;
        rescan(&m, i);
        for (int k = 0; k < n; k++) {
            if (!m.alive[k] || k == i) continue;
            if (m.best[k] == i || m.best[k] == j) {
                rescan(&m, k);
                continue;
            }
            int64_t c = merge_cost(&m, k, i);
            if (c < m.bestd[k] || (c == m.bestd[k] && i < m.best[k])) {
                m.best[k] = i;
                m.bestd[k] = c;
            }
        }
    }

    /* The clusters' unions become the combinations. */
    splat_combo *leaf = a->combos;
    a->combos = NULL;
    a->ncombos = 0;
    free(cs->keys);
    free(cs->slots);
    cs->keys = NULL;
    cs->slots = NULL;
    cs->capslots = cs->capcombos = 0;
    int *to = xcalloc((size_t)n, sizeof *to);
    for (int i = 0; i < n; i++) to[i] = -1;
    bool ok = true;
    splat_level *l0 = &a->levels[0];
    for (size_t c = 0; ok && c < (size_t)l0->width * l0->height; c++) {
        int old = l0->ids[c];
        if (old == (int)SPLAT_COMBO_HOLE) continue;
        int root = find(m.parent, old);
        if (to[root] < 0) {
            to[root] = intern_checked(cs, m.u + (size_t)root * words, s->nmaterials,
                                      s->desc, d);
            ok = to[root] >= 0;
            if (!ok) break;
        }
        l0->ids[c] = (uint16_t)to[root];
        a->combos[to[root]].ncells++;
        a->combos[to[root]].nnodes++;
    }
    for (int i = 0; i < n; i++) free(leaf[i].materials);
    free(leaf);
    free(to);
    free(m.u);
    free(m.cells);
    free(m.parent);
    free(m.alive);
    free(m.best);
    free(m.bestd);
    return ok;
}

bool splat_analyze(const splat_scene *s, splat_analysis *a, sg_diags *d)
{
    return splat_analyze_merged(s, 0, a, d);
}

bool splat_analyze_merged(const splat_scene *s, int max_combos, splat_analysis *a,
                          sg_diags *d)
{
    double t0 = splat_now();
    memset(a, 0, sizeof *a);
    const sg_scene *sc = s->desc;
    const splat_terrain *t = &s->terrain;
    int n = s->nmaterials;
    int T = sc->cell_texels > 0 ? sc->cell_texels : 32;
    a->cell_texels = T;
    a->cells_x = (t->width + T - 1) / T;
    a->cells_z = (t->height + T - 1) / T;
    a->naive_subsets = n > 0 ? ldexp(1.0, n - 1) : 0;

    combo_set cs = { .a = a, .words = n > 64 ? (n + 63) / 64 : 1 };
    ir_ref *masks = xcalloc((size_t)(n ? n : 1), sizeof *masks);
    int *painted_src = NULL, *vector_src = NULL;
    ir mir;
    ir_init(&mir);
    bool ok = mask_ir(s, &mir, masks, &painted_src, &vector_src, d);
    ir_iv *painted = xcalloc((size_t)(mir.npainted ? mir.npainted : 1), sizeof *painted);
    alloc_levels(a);
    /* member bitsets of the current level's nodes */
    size_t ncells = (size_t)a->cells_x * (size_t)a->cells_z;
    uint64_t *bits = xcalloc(ncells * (size_t)cs.words, sizeof *bits);
    block_ctx bc = { .s = s, .mir = &mir, .masks = masks, .painted_src = painted_src,
                     .vector_src = vector_src, .painted = painted, .texel_x = t->size[0] / t->width,
                     .texel_z = t->size[1] / t->height };
    ok = ok && analyze_cells(&bc, &cs, bits, d);
    a->nleaf = a->ncombos;
    a->max_combos = max_combos > 0 ? max_combos : 0;
    for (int i = 0; i < a->ncombos; i++)
        if (a->combos[i].nmaterials > a->leaf_largest)
            a->leaf_largest = a->combos[i].nmaterials;
    if (ok && max_combos > 0 && a->ncombos > max_combos) {
        /* a layer's cost where it is absent: its guard and its mask */
        int64_t *weight = xcalloc((size_t)(n ? n : 1), sizeof *weight);
        for (int m = 0; m < n; m++)
            weight[m] = 1 + (m > 0 ? ir_cost(&mir, &masks[m], 1) : 0);
        ok = merge(&cs, max_combos, weight, s, d);
        free(weight);
    }
    for (int L = 1; ok && L < a->nlevels; L++)
        analyze_level(&cs, L, &bits);
    for (int i = 0; i < a->ncombos; i++)
        if (a->combos[i].nmaterials > a->largest)
            a->largest = a->combos[i].nmaterials;
    if (ok && a->ncombos == 0) {
        sg_error(d, loc_hole(sc), SG_E_EMPTY_TERRAIN, "the whole terrain is a hole "
                 "(holes mask and nodata cover every texel)");
        ok = false;
    }

    free(bits);
    free(painted);
    free(painted_src);
    free(vector_src);
    free(masks);
    ir_free(&mir);
    free(cs.keys);
    free(cs.slots);
    a->seconds = splat_now() - t0;
    if (!ok) splat_analysis_free(a);
    return ok;
}

void splat_analysis_free(splat_analysis *a)
{
    for (int i = 0; i < a->ncombos; i++)
        free(a->combos[i].materials);
    free(a->combos);
    for (int L = 0; L < a->nlevels; L++)
        free(a->levels[L].ids);
    free(a->levels);
    memset(a, 0, sizeof *a);
}

void splat_analysis_report(const splat_scene *s, const splat_analysis *a, FILE *out)
{
    const sg_scene *sc = s->desc;
    fprintf(out, "scene '%s': %d materials, heightfield %d x %d texels, "
            "%g x %g m\n", sc->name, s->nmaterials, s->terrain.width,
            s->terrain.height, s->terrain.size[0], s->terrain.size[1]);
    fprintf(out, "cells: %d x %d = %d of %d x %d texels, %d quadtree levels\n",
            a->cells_x, a->cells_z, a->cells_x * a->cells_z, a->cell_texels,
            a->cell_texels, a->nlevels);
    fprintf(out, "combinations: %d in leaf cells, %d compiled", a->nleaf, a->ncombos);
    if (a->max_combos > 0)
        fprintf(out, " (merged to at most %d)", a->max_combos);
    fprintf(out, " (naive all subsets: %.0f)\n", a->naive_subsets);
    fprintf(out, "largest combination: %d materials (largest leaf-cell overlap: %d)\n",
            a->largest, a->leaf_largest);
    int coarse = 0;
    for (int L = 1; L < a->nlevels; L++)
        coarse += a->levels[L].width * a->levels[L].height;
    fprintf(out, "coarse quadtree nodes: %d, %d drawn by a compiled superset of their "
            "union, %d by the uber-shader (no combination covers them)\n", coarse,
            a->cover_nodes, a->uber_nodes);
    if (s->terrain.holes)
        fprintf(out, "holes: %d cells entirely hole (no combination)\n", a->hole_cells);
    fprintf(out, "  id  cells  nodes  materials (top first)\n");
    for (int i = 0; i < a->ncombos; i++) {
        const splat_combo *c = &a->combos[i];
        fprintf(out, "%4d %6d %6d  ", i, c->ncells, c->nnodes);
        for (int k = 0; k < c->nmaterials; k++)
            fprintf(out, "%s%s", k ? ", " : "", sc->materials[c->materials[k]]);
        fputc('\n', out);
    }
    fprintf(out, "analysis time: %.3f ms\n", a->seconds * 1e3);
}
