/* test_classify_view.c — the screen path's classification view
 * (runtime/screen.c rt_class_view, issue 29): the cover search tries only
 * the candidates of the materials in view, over renumbered sets.
 *
 * - random worlds (up to 200 materials, base combinations and distance
 *   classes with random costs and intervals) and random views: for random
 *   material sets in view and distance ranges, the first candidate that
 *   covers (the GPU's pick over the view's records) is the combination the
 *   search over every combination, in cost order, over the full sets,
 *   picks; with and without distance classes;
 * - the records: a combination is flagged outside exactly where it holds
 *   a material not in view, and its renumbered set is its materials in
 *   view;
 * - a studio world (32 biomes of 8 materials, 256 in all) seen inside one
 *   biome: one word per set and no more candidates than that biome's own
 *   combinations. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "rt_internal.h"

#define MAXM 256
#define MAXW (MAXM / 32)

static uint64_t rng = 0x9e3779b97f4a7c15ull;
static uint32_t rnd(void)
{
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return (uint32_t)(rng >> 11);
}

typedef struct world {
    rt_pack       p;
    rt_pack_combo combos[1200];
    int           mats[1200][MAXM];
    uint32_t      order[1200];
    float         dist[2400];
    uint32_t      full[1200][MAXW];   /* full material sets */
} world;

static const world *sorting;
static int by_cost(const void *a, const void *b)
{
    const rt_pack_combo *x = &sorting->combos[*(const uint32_t *)a];
    const rt_pack_combo *y = &sorting->combos[*(const uint32_t *)b];
    if (x->cost != y->cost)
        return x->cost < y->cost ? -1 : 1;
    if (x->nmaterials != y->nmaterials)
        return x->nmaterials - y->nmaterials;
    return (*(const uint32_t *)a > *(const uint32_t *)b) - (*(const uint32_t *)a < *(const uint32_t *)b);
}

static void add_combo(world *w, const int *mats, int n, double cost, double lo, double hi, int base)
{
    int i = w->p.ncombos++;
    rt_pack_combo *c = &w->combos[i];
    memset(c, 0, sizeof *c);
    memcpy(w->mats[i], mats, (size_t)n * sizeof *mats);
    c->materials = w->mats[i];
    c->nmaterials = n;
    c->cost = cost;
    c->dlo = lo;
    c->dhi = hi;
    c->base = base < 0 ? i : base;
    memset(w->full[i], 0, sizeof w->full[i]);
    for (int k = 0; k < n; k++)
        w->full[i][mats[k] / 32] |= 1u << (mats[k] % 32);
    w->dist[2 * i] = (float)lo;
    w->dist[2 * i + 1] = (float)hi;
}

static void finish(world *w)
{
    w->p.combos = w->combos;
    for (int i = 0; i < w->p.ncombos; i++)
        w->order[i] = (uint32_t)i;
    sorting = w;
    qsort(w->order, (size_t)w->p.ncombos, sizeof *w->order, by_cost);
}

/* A random world: nbase base combinations of 1-12 materials, then up to
 * two distance classes each with a subset of its materials. */
static void random_world(world *w, int nmat, int nbase)
{
    memset(&w->p, 0, sizeof w->p);
    w->p.nmaterials = nmat;
    int m[MAXM];
    for (int i = 0; i < nbase; i++) {
        int n = 1 + (int)(rnd() % 12), k = 0;
        int at = (int)(rnd() % (uint32_t)nmat);   /* clustered, as biomes are */
        for (int j = 0; j < n; j++) {
            int x = (at + (int)(rnd() % 24)) % nmat;
            bool dup = false;
            for (int q = 0; q < k; q++)
                dup |= m[q] == x;
            if (!dup)
                m[k++] = x;
        }
        add_combo(w, m, k, 1.0 + (rnd() % 1000) / 10.0, 0.0, INFINITY, -1);
    }
    w->p.nbase = nbase;
    for (int i = 0; i < nbase; i++)
        for (int c = (int)(rnd() % 3); c > 0; c--) {
            const rt_pack_combo *b = &w->combos[i];
            int k = 0;
            for (int j = 0; j < b->nmaterials; j++)
                if (rnd() % 3 || k == 0)
                    m[k++] = b->materials[j];
            double lo = (double)(rnd() % 500), hi = lo + 1.0 + (double)(rnd() % 800);
            add_combo(w, m, k, 0.5 + (rnd() % 1000) / 10.0, lo, rnd() % 4 ? hi : INFINITY, i);
        }
    finish(w);
}

static bool subset(const uint32_t *a, const uint32_t *b, int words)
{
    for (int k = 0; k < words; k++)
        if (a[k] & ~b[k])
            return false;
    return true;
}

static bool fits(const world *w, int c, float dmin, float dmax, bool no_classes)
{
    if (c < w->p.nbase)
        return true;
    return !no_classes && dmin >= w->dist[2 * c] && dmax <= w->dist[2 * c + 1];
}

/* The search over every combination, full sets (the classification before
 * the view). */
static int pick_all(const world *w, const uint32_t *need, float dmin, float dmax, bool nc)
{
    for (int k = 0; k < w->p.ncombos; k++) {
        int c = (int)w->order[k];
        if (subset(need, w->full[c], MAXW) && fits(w, c, dmin, dmax, nc))
            return c;
    }
    return w->p.ncombos;
}

/* The GPU's pick over the view: `need` renumbered from the records of the
 * cells' combinations, the first candidate whose record covers it. */
static int pick_view(const world *w, const rt_class_view *v, const uint32_t *need, float dmin,
                     float dmax, bool nc)
{
    uint32_t m[MAXW] = { 0 };
    for (int x = 0; x < w->p.nmaterials; x++)
        if ((need[x / 32] >> (x % 32)) & 1u) {
            assert_true(v->remap[x] >= 0);   /* callers ask for sets in view */
            m[v->remap[x] / 32] |= 1u << (v->remap[x] % 32);
        }
    int R = 1 + v->words;
    for (int i = 0; i < v->ncand; i++) {
        int c = (int)v->cand[i];
        if (subset(m, v->rec + (size_t)c * (size_t)R + 1, v->words) && fits(w, c, dmin, dmax, nc))
            return c;
    }
    return w->p.ncombos;
}

static void check_records(const world *w, const rt_class_view *v, const uint32_t *view)
{
    int R = 1 + v->words, nview = 0, last = -1;
    for (int x = 0; x < w->p.nmaterials; x++) {
        bool in = (view[x / 32] >> (x % 32)) & 1u;
        assert_int_equal(v->remap[x] >= 0, in);
        if (in) {
            assert_int_equal(v->remap[x], last + 1);   /* in scene order, dense */
            last = v->remap[x];
            nview++;
        }
    }
    assert_int_equal(v->nview, nview);
    assert_int_equal(v->words, nview <= 32 ? 1 : (w->p.nmaterials + 31) / 32);
    for (int c = 0; c < w->p.ncombos; c++) {
        const uint32_t *r = v->rec + (size_t)c * (size_t)R;
        bool out = !subset(w->full[c], view, MAXW);
        assert_int_equal((r[0] & RT_CLASS_OUTSIDE) != 0, out);
        int bits = 0, inview = 0;
        for (int k = 0; k < v->words; k++)
            bits += __builtin_popcount(r[1 + k]);
        for (int k = 0; k < w->combos[c].nmaterials; k++) {
            int x = w->combos[c].materials[k];
            if (v->remap[x] >= 0) {
                inview++;
                assert_true((r[1 + v->remap[x] / 32] >> (v->remap[x] % 32)) & 1u);
            }
        }
        assert_int_equal(bits, inview);
    }
}

static void test_random_views_pick_as_full_search(void **state)
{
    (void)state;
    static world w;
    long tried = 0, covered = 0;
    for (int round = 0; round < 60; round++) {
        int nmat = 8 + (int)(rnd() % (MAXM - 8));
        random_world(&w, nmat, 10 + (int)(rnd() % 150));
        int fw = (nmat + 31) / 32;
        /* the view: the union of some combinations' sets, plus a few */
        uint32_t view[MAXW] = { 0 };
        int nin = 1 + (int)(rnd() % 12);
        for (int j = 0; j < nin; j++) {
            int c = (int)(rnd() % (uint32_t)w.p.nbase);
            for (int k = 0; k < MAXW; k++)
                view[k] |= w.full[c][k];
        }
        for (int j = (int)(rnd() % 4); j > 0; j--) {
            int x = (int)(rnd() % (uint32_t)nmat);
            view[x / 32] |= 1u << (x % 32);
        }
        for (int nc = 0; nc < 2; nc++) {
            rt_class_view v = { 0 };
            assert_true(rt_class_view_build(&w.p, w.order, w.dist, view, fw, nc, &v));
            check_records(&w, &v, view);
            assert_true(v.ncand <= w.p.ncombos);
            for (int t = 0; t < 400; t++) {
                /* a tile: the union of 1-4 cells whose combination lies in
                 * view, or a random subset of the view */
                uint32_t need[MAXW] = { 0 };
                if (t % 2) {
                    for (int j = 1 + (int)(rnd() % 4); j > 0; j--) {
                        int c = (int)(rnd() % (uint32_t)w.p.ncombos);
                        if (subset(w.full[c], view, MAXW))
                            for (int k = 0; k < MAXW; k++)
                                need[k] |= w.full[c][k];
                    }
                } else {
                    for (int k = 0; k < MAXW; k++)
                        need[k] = view[k] & rnd() & rnd() & rnd();
                }
                bool empty = true;   /* a tile needs a material: every
                                        combination here has one */
                for (int k = 0; k < MAXW; k++)
                    empty &= need[k] == 0;
                if (empty)
                    continue;
                float dmin = (float)(rnd() % 1500), dmax = dmin + (float)(rnd() % 300);
                int a = pick_all(&w, need, dmin, dmax, nc);
                int b = pick_view(&w, &v, need, dmin, dmax, nc);
                assert_int_equal(a, b);
                tried++;
                covered += a < w.p.ncombos;
            }
            rt_class_view_free(&v);
        }
    }
    /* the random sets must exercise both outcomes */
    assert_true(covered > tried / 10);
    assert_true(covered < tried);
}

/* 32 biomes x 8 materials; per biome the combinations of its leaf cells
 * (runs of 1-4 of its materials) and the seams with the next biome. */
static void test_studio_world_view_of_one_biome(void **state)
{
    (void)state;
    static world w;
    memset(&w.p, 0, sizeof w.p);
    w.p.nmaterials = 256;
    int per_biome = 0, m[16];
    for (int b = 0; b < 32; b++) {
        int before = w.p.ncombos;
        for (int s = 0; s < 8; s++)
            for (int n = 1; n <= 4; n++) {
                for (int k = 0; k < n; k++)
                    m[k] = 8 * b + (s + k) % 8;
                add_combo(&w, m, n, 10.0 * n + s + b / 100.0, 0.0, INFINITY, -1);
            }
        if (b == 14)
            per_biome = w.p.ncombos - before;
        for (int k = 0; k < 4; k++) {   /* the seam with biome b + 1 */
            m[k] = 8 * b + k;
            m[4 + k] = (8 * (b + 1) + k) % 256;
        }
        add_combo(&w, m, 8, 90.0 + b / 100.0, 0.0, INFINITY, -1);
    }
    w.p.nbase = w.p.ncombos;
    finish(&w);
    uint32_t view[MAXW] = { 0 };
    view[(8 * 14) / 32] |= 0xffu << ((8 * 14) % 32);   /* biome 14 */
    rt_class_view v = { 0 };
    assert_true(rt_class_view_build(&w.p, w.order, w.dist, view, 8, false, &v));
    check_records(&w, &v, view);
    assert_int_equal(v.nview, 8);
    assert_int_equal(v.words, 1);
    assert_true(w.p.ncombos > 4 * per_biome);
    assert_true(v.ncand <= per_biome);
    /* every candidate holds a material of biome 14 */
    for (int i = 0; i < v.ncand; i++) {
        const uint32_t *r = v.rec + (size_t)v.cand[i] * 2;
        assert_true(r[1] != 0);
    }
    rt_class_view_free(&v);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_random_views_pick_as_full_search),
        cmocka_unit_test(test_studio_world_view_of_one_biome),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
