/* test_quadtree.c — CPU geometry of the terrain LOD (runtime/quadtree.c):
 * the 9 index-buffer permutations, the restricted quadtree, and, for random
 * cameras, that every edge between patches of different levels uses only
 * vertices of the coarser side (no T-junctions), checked on the index data
 * the GPU draws. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "rt_internal.h"

enum { N = SPLAT_GRID, LAST = SPLAT_GRID - 1, MAXIDX = 6 * LAST * LAST };

static uint16_t perm_idx[RT_PERMS][MAXIDX];
static uint32_t perm_n[RT_PERMS];

static void build_perms(void)
{
    for (int p = 0; p < RT_PERMS; p++)
        perm_n[p] = rt_grid_indices(p, perm_idx[p]);
}

static void test_perm_table(void **state)
{
    (void)state;
    int seen[RT_PERMS] = { 0 };
    for (unsigned e = 0; e < 16; e++) {
        int p = rt_perm_of_edges(e);
        bool opposite = ((e & RT_EDGE_N) && (e & RT_EDGE_S)) || ((e & RT_EDGE_E) && (e & RT_EDGE_W));
        if (opposite || __builtin_popcount(e) > 2) {
            assert_int_equal(p, -1);
            continue;
        }
        assert_true(p >= 0 && p < RT_PERMS);
        assert_int_equal(rt_edges_of_perm(p), e);
        seen[p]++;
    }
    for (int p = 0; p < RT_PERMS; p++)
        assert_int_equal(seen[p], 1);
}

/* Signed doubled area of a triangle of grid vertices. */
static long area2(int a, int b, int c)
{
    long ax = a % N, az = a / N, bx = b % N, bz = b / N, cx = c % N, cz = c / N;
    return (bx - ax) * (cz - az) - (bz - az) * (cx - ax);
}

static bool on_side(int v, unsigned side)
{
    int i = v % N, j = v / N;
    return (side == RT_EDGE_N && j == 0) || (side == RT_EDGE_S && j == LAST) ||
           (side == RT_EDGE_W && i == 0) || (side == RT_EDGE_E && i == LAST);
}

/* Position (0..32) of a boundary vertex along its side. */
static int along(int v, unsigned side)
{
    return (side == RT_EDGE_N || side == RT_EDGE_S) ? v % N : v / N;
}

/* Vertices of a permutation's triangle edges that lie on `side`, as a mask
 * over positions 0..32; also checks the edges cover the side exactly. */
static uint64_t side_vertices(int perm, unsigned side)
{
    uint64_t used = 0;
    int covered[LAST] = { 0 };
    const uint16_t *ix = perm_idx[perm];
    for (uint32_t t = 0; t < perm_n[perm]; t += 3) {
        for (int k = 0; k < 3; k++) {
            int a = ix[t + k], b = ix[t + (k + 1) % 3];
            if (!on_side(a, side) || !on_side(b, side))
                continue;
            int pa = along(a, side), pb = along(b, side);
            int lo = pa < pb ? pa : pb, hi = pa < pb ? pb : pa;
            used |= 1ull << pa | 1ull << pb;
            for (int s = lo; s < hi; s++)
                covered[s]++;
        }
    }
    for (int s = 0; s < LAST; s++)
        assert_int_equal(covered[s], 1);   /* the side is one chain of edges */
    return used;
}

static void test_permutations(void **state)
{
    (void)state;
    const unsigned sides[4] = { RT_EDGE_N, RT_EDGE_E, RT_EDGE_S, RT_EDGE_W };
    for (int p = 0; p < RT_PERMS; p++) {
        uint32_t n = perm_n[p];
        assert_true(n > 0 && n % 3 == 0 && n <= MAXIDX);
        long total = 0;
        int sign = 0;
        for (uint32_t t = 0; t < n; t += 3) {
            long a = area2(perm_idx[p][t], perm_idx[p][t + 1], perm_idx[p][t + 2]);
            assert_true(a != 0);                       /* no degenerate triangle */
            int s = a > 0 ? 1 : -1;
            if (!sign)
                sign = s;
            assert_int_equal(s, sign);                 /* one winding */
            total += labs(a);
        }
        assert_int_equal(total, 2L * LAST * LAST);     /* covers the patch once */
        for (int k = 0; k < 4; k++) {
            uint64_t used = side_vertices(p, sides[k]);
            bool coarse = rt_edges_of_perm(p) & sides[k];
            for (int pos = 0; pos <= LAST; pos++) {
                bool u = (used >> pos) & 1;
                if (coarse)
                    assert_int_equal(u, pos % 2 == 0);  /* only every other vertex */
                else
                    assert_true(u);                     /* every vertex */
            }
        }
    }
}

/* ---- random terrains and cameras ------------------------------------------- */

typedef struct world {
    int       w, h, cell;
    double    size[2];
    uint16_t *texels;
    rt_bounds bounds;
    rt_quadtree q;
} world;

static void world_make(world *wd, int w, int h, int cell, double sx, double sz, unsigned seed)
{
    srand(seed);
    wd->w = w;
    wd->h = h;
    wd->cell = cell;
    wd->size[0] = sx;
    wd->size[1] = sz;
    wd->texels = malloc((size_t)w * h * sizeof *wd->texels);
    for (int i = 0; i < w * h; i++) {
        double x = i % w, z = i / w;
        double v = 0.5 + 0.3 * sin(x * 0.05) * cos(z * 0.04) + 0.1 * ((double)rand() / RAND_MAX);
        wd->texels[i] = (uint16_t)(v * 65535.0);
    }
    assert_true(rt_bounds_build(&wd->bounds, wd->texels, w, h, cell, 500.0, 10.0));
    assert_true(rt_quadtree_init(&wd->q, &wd->bounds, cell, w, h, wd->size));
}

static void world_free(world *wd)
{
    rt_quadtree_free(&wd->q);
    rt_bounds_free(&wd->bounds);
    free(wd->texels);
}

static double frand(double lo, double hi) { return lo + (hi - lo) * rand() / (double)RAND_MAX; }

/* Which patch owns each leaf cell; every cell exactly once. */
static int *owners(const world *wd)
{
    int cx = wd->bounds.width[0], cz = wd->bounds.height[0];
    int *own = malloc(sizeof *own * (size_t)(cx * cz));
    for (int i = 0; i < cx * cz; i++)
        own[i] = -1;
    for (int k = 0; k < wd->q.npatches; k++) {
        const rt_patch *p = &wd->q.patches[k];
        int s = 1 << p->level;
        for (int z = p->z * s; z < (p->z + 1) * s && z < cz; z++)
            for (int x = p->x * s; x < (p->x + 1) * s && x < cx; x++) {
                assert_int_equal(own[z * cx + x], -1);
                own[z * cx + x] = k;
            }
    }
    for (int i = 0; i < cx * cz; i++)
        assert_true(own[i] >= 0);
    return own;
}

/* Patch P and its neighbour Q across P's `side`, along the cell edge at
 * leaf cell `cell_along` (texel coordinates along the side): the vertices
 * P's triangles use on that side, in texels, lie on Q's grid. */
static void check_edge(const world *wd, const rt_patch *p, const rt_patch *q, unsigned side)
{
    int dl = (int)p->level - (int)q->level;
    assert_true(dl >= -1 && dl <= 1);                 /* restricted quadtree */
    bool coarse = rt_edges_of_perm(p->perm) & side;
    assert_int_equal(coarse, dl < 0);                 /* stitched exactly when coarser */
    long pstep = (long)wd->cell << p->level;          /* texels per patch side */
    long qgrid = ((long)wd->cell << q->level) / LAST; /* texels between Q's vertices */
    long origin = (side == RT_EDGE_N || side == RT_EDGE_S) ? p->x * pstep : p->z * pstep;
    uint64_t used = side_vertices(p->perm, side);
    for (int pos = 0; pos <= LAST; pos++) {
        if (!((used >> pos) & 1))
            continue;
        long t = origin + pos * (pstep / LAST);
        if (dl < 0)
            assert_int_equal(t % qgrid, 0);           /* a vertex of the coarser side */
    }
}

static void check_selection(const world *wd)
{
    int cx = wd->bounds.width[0], cz = wd->bounds.height[0];
    int *own = owners(wd);
    int edges_checked = 0;
    for (int z = 0; z < cz; z++)
        for (int x = 0; x < cx; x++) {
            int a = own[z * cx + x];
            if (x + 1 < cx && own[z * cx + x + 1] != a) {
                const rt_patch *p = &wd->q.patches[a], *q = &wd->q.patches[own[z * cx + x + 1]];
                check_edge(wd, p, q, RT_EDGE_E);
                check_edge(wd, q, p, RT_EDGE_W);
                edges_checked++;
            }
            if (z + 1 < cz && own[(z + 1) * cx + x] != a) {
                const rt_patch *p = &wd->q.patches[a], *q = &wd->q.patches[own[(z + 1) * cx + x]];
                check_edge(wd, p, q, RT_EDGE_S);
                check_edge(wd, q, p, RT_EDGE_N);
                edges_checked++;
            }
        }
    /* terrain-boundary sides are never stitched (no neighbour there) */
    for (int k = 0; k < wd->q.npatches; k++) {
        const rt_patch *p = &wd->q.patches[k];
        unsigned e = rt_edges_of_perm(p->perm);
        if (p->x == 0)
            assert_false(e & RT_EDGE_W);
        if (p->z == 0)
            assert_false(e & RT_EDGE_N);
    }
    free(own);
}

static void test_random_cameras(void **state)
{
    (void)state;
    world wd;
    world_make(&wd, 1000, 700, 16, 4000.0, 2100.0, 7);   /* non-square texels */
    int levels_seen = 0, mixed = 0;
    for (int it = 0; it < 300; it++) {
        rt_select_desc s = { .cull = false };
        s.camera[0] = frand(-500, 4500);
        s.camera[1] = frand(0, 1500);
        s.camera[2] = frand(-500, 2600);
        s.lod_distance = frand(0.3, 12.0);
        rt_quadtree_select(&wd.q, &s);
        assert_true(wd.q.npatches > 0);
        check_selection(&wd);
        int lo = 99, hi = -1;
        for (int k = 0; k < wd.q.npatches; k++) {
            lo = wd.q.patches[k].level < lo ? wd.q.patches[k].level : lo;
            hi = wd.q.patches[k].level > hi ? wd.q.patches[k].level : hi;
        }
        levels_seen = hi - lo + 1 > levels_seen ? hi - lo + 1 : levels_seen;
        mixed += hi > lo;
    }
    /* the cameras did exercise transitions over several levels */
    assert_true(levels_seen >= 4);
    assert_true(mixed > 200);
    world_free(&wd);
}

static void test_culling(void **state)
{
    (void)state;
    world wd;
    world_make(&wd, 512, 512, 32, 2048.0, 2048.0, 3);
    /* a camera above the centre looking straight down with a narrow view:
     * culling keeps a subset, and only patches under the camera */
    rt_select_desc s = { .cull = true, .lod_distance = 2.0 };
    s.camera[0] = 1024;
    s.camera[1] = 2000;
    s.camera[2] = 1024;
    /* clip = (4x, 4z, near, -y): looking down -y, |x|, |z| <= depth / 4 */
    float m[16] = { 0 };
    m[0] = 4.0f;         /* x_clip = 4 x                      */
    m[2 * 4 + 1] = 4.0f; /* y_clip = 4 z                      */
    m[1 * 4 + 3] = -1.0f;/* w = -y (depth below the camera)   */
    m[3 * 4 + 2] = 0.25f;/* z_clip = near (reversed Z)        */
    memcpy(s.view_proj, m, sizeof m);
    rt_quadtree_select(&wd.q, &s);
    int culled = wd.q.npatches;
    assert_true(culled > 0);
    assert_true(wd.q.nculled > 0);
    for (int k = 0; k < wd.q.npatches; k++) {
        double x0, z0, sx, sz;
        const rt_patch *p = &wd.q.patches[k];
        rt_node_rect(&wd.q, p->level, p->x, p->z, &x0, &z0, &sx, &sz);
        /* depth is at most 2000 - 10 m: the visible square is within 500 m */
        assert_true(x0 <= 1024 + 500 && x0 + sx >= 1024 - 500);
        assert_true(z0 <= 1024 + 500 && z0 + sz >= 1024 - 500);
    }
    s.cull = false;
    rt_quadtree_select(&wd.q, &s);
    assert_true(wd.q.npatches > culled);
    /* looking away (up): everything is culled */
    m[1 * 4 + 3] = 1.0f;
    memcpy(s.view_proj, m, sizeof m);
    s.cull = true;
    rt_quadtree_select(&wd.q, &s);
    assert_int_equal(wd.q.npatches, 0);
    world_free(&wd);
}

/* Not a timed test: prints the selection cost on a 4096^2 heightfield. */
static void test_select_cost(void **state)
{
    (void)state;
    world wd;
    world_make(&wd, 4096, 4096, 32, 16384.0, 16384.0, 11);
    rt_select_desc s = { .cull = false, .lod_distance = 5.4 };
    s.camera[0] = 5000;
    s.camera[1] = 400;
    s.camera[2] = 7000;
    struct timespec a, b;
    clock_gettime(CLOCK_MONOTONIC, &a);
    for (int i = 0; i < 100; i++)
        rt_quadtree_select(&wd.q, &s);
    clock_gettime(CLOCK_MONOTONIC, &b);
    double ms = ((double)(b.tv_sec - a.tv_sec) * 1e3 + (double)(b.tv_nsec - a.tv_nsec) * 1e-6) / 100;
    printf("quadtree selection, 4096^2 heightfield: %d patches, %.4f ms per frame\n",
           wd.q.npatches, ms);
    check_selection(&wd);
    world_free(&wd);
}

int main(void)
{
    build_perms();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_perm_table),
        cmocka_unit_test(test_permutations),
        cmocka_unit_test(test_random_cameras),
        cmocka_unit_test(test_culling),
        cmocka_unit_test(test_select_cost),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
