/* quadtree.c — terrain LOD as Andersson 2007 §5.4.1 describes it: a restricted
 * quadtree of 33x33-vertex patches over the heightfield, selected per frame
 * by distance (a screen-space error bound), with edge neighbours at most
 * one level apart and the 9 index-buffer permutations that stitch a patch
 * to coarser neighbours without T-junctions.
 *
 * Per frame, with no allocation:
 *   1. split top-down: a node splits while the camera is closer than
 *      lod_distance * node size (3D distance to the node's box), or, with
 *      split_uncovered, while the pack has no combination for it
 *      (SPLAT_COMBO_UBER: the compiler composes leaf cells' combinations
 *      only) and it is nearer than uncovered_far, so that every patch
 *      drawn has a composite; leaves always have one;
 *   2. restrict bottom-up: if a node at level K is split, the edge
 *      neighbours of its parent (level K+1) are split too.  Then a drawn
 *      patch at level L never touches one at level <= L-2: such a patch Q
 *      has a split ancestor at L-1 whose parent (level L) is a neighbour
 *      of the patch, and would have been split;
 *   3. emit the unsplit nodes under split parents, culling whole subtrees
 *      whose box (node min/max heights) is outside the frustum, and give
 *      each patch the permutation of its coarser edges: a same-level
 *      neighbour whose parent is not split is drawn coarser.
 *
 * Stitching, before and after for a coarser N edge (x = vertex kept):
 *     x x x x x        x . x . x      odd vertices of the edge are folded
 *     |/|/|/|/|  -->   |\ /|\ /|      onto their even neighbours; the
 *     x-x-x-x-x        x-x-x-x-x      triangles that collapse are dropped
 */
#include "rt_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static const unsigned perm_edges[RT_PERMS] = {
    0, RT_EDGE_N, RT_EDGE_E, RT_EDGE_S, RT_EDGE_W,
    RT_EDGE_N | RT_EDGE_E, RT_EDGE_E | RT_EDGE_S,
    RT_EDGE_S | RT_EDGE_W, RT_EDGE_W | RT_EDGE_N,
};

int rt_perm_of_edges(unsigned edges)
{
    for (int i = 0; i < RT_PERMS; i++)
        if (perm_edges[i] == edges)
            return i;
    return -1;
}

unsigned rt_edges_of_perm(int perm) { return perm_edges[perm]; }

void rt_grid_vertices(float *xy)
{
    const int n = SPLAT_GRID;
    for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++) {
            xy[2 * (j * n + i)] = (float)i / (float)(n - 1);
            xy[2 * (j * n + i) + 1] = (float)j / (float)(n - 1);
        }
}

/* Fold an odd vertex of a coarser edge onto the even vertex before it. */
static int snap(int i, int j, unsigned edges)
{
    const int last = SPLAT_GRID - 1;
    if ((edges & RT_EDGE_N) && j == 0 && (i & 1))
        i--;
    else if ((edges & RT_EDGE_S) && j == last && (i & 1))
        i--;
    else if ((edges & RT_EDGE_W) && i == 0 && (j & 1))
        j--;
    else if ((edges & RT_EDGE_E) && i == last && (j & 1))
        j--;
    return j * SPLAT_GRID + i;
}

uint32_t rt_grid_indices(int perm, uint16_t *out)
{
    const int last = SPLAT_GRID - 1;
    unsigned edges = perm_edges[perm];
    uint32_t n = 0;
    for (int j = 0; j < last; j++) {
        for (int i = 0; i < last; i++) {
            int a = snap(i, j, edges), b = snap(i + 1, j, edges);
            int c = snap(i + 1, j + 1, edges), d = snap(i, j + 1, edges);
            int tri[2][3] = { { a, b, c }, { a, c, d } };
            for (int t = 0; t < 2; t++) {
                int *v = tri[t];
                if (v[0] == v[1] || v[1] == v[2] || v[0] == v[2])
                    continue;   /* collapsed by the fold */
                for (int k = 0; k < 3; k++) {
                    if (out)
                        out[n] = (uint16_t)v[k];
                    n++;
                }
            }
        }
    }
    return n;
}

bool rt_quadtree_init(rt_quadtree *q, const rt_bounds *b, int cell_texels,
                      int hf_width, int hf_height, const double size[2])
{
    memset(q, 0, sizeof *q);
    q->bounds = b;
    q->nlevels = b->nlevels;
    q->width = b->width;
    q->height = b->height;
    q->cell_texels = cell_texels;
    q->hf_width = hf_width;
    q->hf_height = hf_height;
    q->size[0] = size[0];
    q->size[1] = size[1];
    q->split = calloc((size_t)q->nlevels, sizeof *q->split);
    if (!q->split)
        return false;
    for (int L = 0; L < q->nlevels; L++) {
        q->split[L] = calloc((size_t)q->width[L] * (size_t)q->height[L], 1);
        if (!q->split[L]) {
            rt_quadtree_free(q);
            return false;
        }
    }
    q->cap = q->width[0] * q->height[0];
    q->patches = malloc((size_t)q->cap * sizeof *q->patches);
    if (!q->patches) {
        rt_quadtree_free(q);
        return false;
    }
    return true;
}

void rt_quadtree_free(rt_quadtree *q)
{
    for (int L = 0; L < q->nlevels && q->split; L++)
        free(q->split[L]);
    free(q->split);
    free(q->patches);
    memset(q, 0, sizeof *q);
}

void rt_node_rect(const rt_quadtree *q, int level, int x, int z,
                  double *x0, double *z0, double *sx, double *sz)
{
    double texels = (double)q->cell_texels * (double)(1 << level);
    double mx = q->size[0] / q->hf_width, mz = q->size[1] / q->hf_height;
    *x0 = x * texels * mx;
    *z0 = z * texels * mz;
    *sx = texels * mx;
    *sz = texels * mz;
}

typedef struct frame {
    rt_quadtree          *q;
    const rt_select_desc *s;
    double                planes[6][4];
} frame;

/* Box of a node, clipped to the terrain, in terrain-local metres. */
static void node_box(const rt_quadtree *q, int L, int x, int z, double lo[3], double hi[3])
{
    double x0, z0, sx, sz;
    rt_node_rect(q, L, x, z, &x0, &z0, &sx, &sz);
    size_t i = (size_t)z * (size_t)q->width[L] + (size_t)x;
    lo[0] = x0;
    lo[1] = q->bounds->hmin[L][i];
    lo[2] = z0;
    hi[0] = fmin(x0 + sx, q->size[0]);
    hi[1] = q->bounds->hmax[L][i];
    hi[2] = fmin(z0 + sz, q->size[1]);
}

static double box_distance(const double c[3], const double lo[3], const double hi[3])
{
    double d2 = 0;
    for (int k = 0; k < 3; k++) {
        double d = c[k] < lo[k] ? lo[k] - c[k] : c[k] > hi[k] ? c[k] - hi[k] : 0.0;
        d2 += d * d;
    }
    return sqrt(d2);
}

void rt_node_distance(const rt_quadtree *q, int level, int x, int z, const double camera[3],
                      double *dmin, double *dmax)
{
    double x0, z0, sx, sz;
    rt_node_rect(q, level, x, z, &x0, &z0, &sx, &sz);
    size_t i = (size_t)z * (size_t)q->width[level] + (size_t)x;
    double lo[3] = { x0, q->bounds->hmin[level][i], z0 };
    double hi[3] = { x0 + sx, q->bounds->hmax[level][i], z0 + sz };
    *dmin = box_distance(camera, lo, hi);
    double far2 = 0;
    for (int k = 0; k < 3; k++) {
        double d = fmax(fabs(camera[k] - lo[k]), fabs(camera[k] - hi[k]));
        far2 += d * d;
    }
    *dmax = sqrt(far2);
}

static bool box_visible(const frame *f, const double lo[3], const double hi[3])
{
    const double *c = f->s->camera;
    for (int p = 0; p < 6; p++) {
        const double *pl = f->planes[p];
        double v = pl[3];
        for (int k = 0; k < 3; k++)
            v += pl[k] * ((pl[k] >= 0 ? hi[k] : lo[k]) - c[k]);
        if (v < 0)
            return false;
    }
    return true;
}

static void split_down(frame *f, int L, int x, int z)
{
    rt_quadtree *q = f->q;
    if (L == 0)
        return;
    double lo[3], hi[3];
    node_box(q, L, x, z, lo, hi);
    double size = fmax(hi[0] - lo[0], hi[2] - lo[2]);
    double dist = box_distance(f->s->camera, lo, hi);
    size_t i = (size_t)z * (size_t)q->width[L] + (size_t)x;
    if (dist >= f->s->lod_distance * size) {
        bool uncovered = f->s->split_uncovered && q->combo_ids &&
                         q->combo_ids[L][i] == SPLAT_COMBO_UBER &&
                         !(f->s->uncovered_far > 0 && dist >= f->s->uncovered_far);
        if (!uncovered)
            return;
        q->nsplit_uncovered++;
    }
    q->split[L][i] = 1;
    for (int c = 0; c < 4; c++) {
        int cx = 2 * x + (c & 1), cz = 2 * z + (c >> 1);
        if (cx < q->width[L - 1] && cz < q->height[L - 1])
            split_down(f, L - 1, cx, cz);
    }
}

static void mark(rt_quadtree *q, int L, int x, int z)
{
    if (x >= 0 && z >= 0 && x < q->width[L] && z < q->height[L])
        q->split[L][(size_t)z * (size_t)q->width[L] + (size_t)x] = 1;
}

static void restrict_levels(rt_quadtree *q)
{
    int top = q->nlevels - 1;
    for (int K = 1; K < top; K++) {
        for (int z = 0; z < q->height[K]; z++) {
            for (int x = 0; x < q->width[K]; x++) {
                if (!q->split[K][(size_t)z * (size_t)q->width[K] + (size_t)x])
                    continue;
                int px = x / 2, pz = z / 2;
                mark(q, K + 1, px, pz);
                mark(q, K + 1, px - 1, pz);
                mark(q, K + 1, px + 1, pz);
                mark(q, K + 1, px, pz - 1);
                mark(q, K + 1, px, pz + 1);
            }
        }
    }
}

/* Is the same-level neighbour (x, z) of a patch at level L drawn coarser? */
static bool coarser(const rt_quadtree *q, int L, int x, int z)
{
    if (L == q->nlevels - 1 || x < 0 || z < 0 || x >= q->width[L] || z >= q->height[L])
        return false;
    return !q->split[L + 1][(size_t)(z / 2) * (size_t)q->width[L + 1] + (size_t)(x / 2)];
}

static void emit(frame *f, int L, int x, int z)
{
    rt_quadtree *q = f->q;
    double lo[3], hi[3];
    node_box(q, L, x, z, lo, hi);
    if (f->s->cull && !box_visible(f, lo, hi)) {
        q->nculled++;
        return;
    }
    size_t i = (size_t)z * (size_t)q->width[L] + (size_t)x;
    if (q->split[L][i]) {
        /* nearest child first: patches come out roughly front to back
         * (the counting sort by combination keeps that order within a
         * group), so early depth testing skips hidden fragments */
        int fx = f->s->camera[0] >= 0.5 * (lo[0] + hi[0]) ? 1 : 0;
        int fz = f->s->camera[2] >= 0.5 * (lo[2] + hi[2]) ? 1 : 0;
        for (int c = 0; c < 4; c++) {
            int cx = 2 * x + ((c & 1) ^ fx), cz = 2 * z + ((c >> 1) ^ fz);
            if (cx < q->width[L - 1] && cz < q->height[L - 1])
                emit(f, L - 1, cx, cz);
        }
        return;
    }
    /* all hole (PACK.md): nothing of it is drawn */
    if (q->combo_ids && q->combo_ids[L][i] == SPLAT_COMBO_HOLE) {
        q->nholes++;
        return;
    }
    unsigned edges = 0;
    if (coarser(q, L, x, z - 1)) edges |= RT_EDGE_N;
    if (coarser(q, L, x + 1, z)) edges |= RT_EDGE_E;
    if (coarser(q, L, x, z + 1)) edges |= RT_EDGE_S;
    if (coarser(q, L, x - 1, z)) edges |= RT_EDGE_W;
    int perm = rt_perm_of_edges(edges);
    if (perm < 0)
        perm = 0;   /* cannot happen in a restricted tree (checked by tests) */
    rt_patch *p = &q->patches[q->npatches++];
    p->level = (uint8_t)L;
    p->perm = (uint8_t)perm;
    p->x = x;
    p->z = z;
    p->combo = q->combo_ids ? q->combo_ids[L][i] : 0;
}

void rt_quadtree_select(rt_quadtree *q, const rt_select_desc *s)
{
    frame f = { q, s, { { 0 } } };
    /* Frustum planes from the rows of the camera-relative view_proj
     * (column-major; Vulkan clip space: -w <= x, y <= w, 0 <= z <= w). */
    const float *m = s->view_proj;
    double r[4][4];
    for (int row = 0; row < 4; row++)
        for (int col = 0; col < 4; col++)
            r[row][col] = m[col * 4 + row];
    for (int k = 0; k < 4; k++) {
        f.planes[0][k] = r[3][k] + r[0][k];
        f.planes[1][k] = r[3][k] - r[0][k];
        f.planes[2][k] = r[3][k] + r[1][k];
        f.planes[3][k] = r[3][k] - r[1][k];
        f.planes[4][k] = r[2][k];
        f.planes[5][k] = r[3][k] - r[2][k];
    }
    memcpy(q->planes, f.planes, sizeof q->planes);
    memcpy(q->camera, s->camera, sizeof q->camera);
    q->culled = s->cull;
    for (int L = 0; L < q->nlevels; L++)
        memset(q->split[L], 0, (size_t)q->width[L] * (size_t)q->height[L]);
    int top = q->nlevels - 1;
    q->npatches = 0;
    q->nculled = 0;
    q->nholes = 0;
    q->nsplit_uncovered = 0;
    split_down(&f, top, 0, 0);
    restrict_levels(q);
    emit(&f, top, 0, 0);
}

bool rt_quadtree_node_visible(const rt_quadtree *q, int level, int x, int z, double margin)
{
    if (!q->culled)
        return true;
    rt_select_desc sd = { .cull = true };
    memcpy(sd.camera, q->camera, sizeof sd.camera);
    frame f = { (rt_quadtree *)q, &sd, { { 0 } } };
    memcpy(f.planes, q->planes, sizeof f.planes);
    double lo[3], hi[3];
    node_box(q, level, x, z, lo, hi);
    for (int k = 0; k < 3; k++) {
        lo[k] -= margin;
        hi[k] += margin;
    }
    return box_visible(&f, lo, hi);
}
