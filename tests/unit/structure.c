/* structure.c — structure_check (structure.h). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdlib.h>
#include <string.h>

#include "abi.h"
#include "structure.h"

enum { WORDS = 8 };                   /* 512 materials */
typedef struct mset { uint64_t w[WORDS]; } mset;

static mset set_of(const splat_combo *c)
{
    mset m;
    memset(&m, 0, sizeof m);
    for (int i = 0; i < c->nmaterials; i++) {
        assert_true(c->materials[i] >= 0 && c->materials[i] < 64 * WORDS);
        m.w[c->materials[i] / 64] |= 1ull << (c->materials[i] % 64);
    }
    return m;
}

static bool subset(const mset *a, const mset *b)
{
    for (int k = 0; k < WORDS; k++)
        if (a->w[k] & ~b->w[k]) return false;
    return true;
}

static bool equal(const mset *a, const mset *b)
{
    return memcmp(a, b, sizeof *a) == 0;
}

static bool empty(const mset *a)
{
    for (int k = 0; k < WORDS; k++)
        if (a->w[k]) return false;
    return true;
}

static int count(const mset *a)
{
    int n = 0;
    for (int k = 0; k < WORDS; k++) n += __builtin_popcountll(a->w[k]);
    return n;
}

structure_counts structure_check(const splat_analysis *ref, const splat_analysis *a, int max)
{
    structure_counts out = { 0 };
    assert_int_equal(a->nlevels, ref->nlevels);
    assert_int_equal(a->nleaf, ref->ncombos);
    assert_int_equal(ref->nleaf, ref->ncombos);
    const splat_level *r0 = &ref->levels[0], *a0 = &a->levels[0];
    int ncells = r0->width * r0->height, overlap = 0;
    mset *leaf = calloc((size_t)ref->ncombos + 1, sizeof *leaf);
    mset *sets = calloc((size_t)a->ncombos + 1, sizeof *sets);
    int *cells = calloc((size_t)a->ncombos + 1, sizeof *cells);
    for (int k = 0; k < ref->ncombos; k++) leaf[k] = set_of(&ref->combos[k]);
    for (int k = 0; k < a->ncombos; k++) sets[k] = set_of(&a->combos[k]);
    for (int i = 0; i < ncells; i++) {
        if (r0->ids[i] == SPLAT_COMBO_HOLE) {
            assert_int_equal(a0->ids[i], SPLAT_COMBO_HOLE);
            continue;
        }
        assert_true(r0->ids[i] < ref->ncombos && a0->ids[i] < a->ncombos);
        int n = ref->combos[r0->ids[i]].nmaterials;
        overlap = n > overlap ? n : overlap;
        assert_true(subset(&leaf[r0->ids[i]], &sets[a0->ids[i]]));   /* covered */
        cells[a0->ids[i]]++;
    }
    assert_int_equal(a->leaf_largest, overlap);
    for (int k = 0; k < a->ncombos; k++) {
        assert_true(cells[k] > 0);                  /* not a node-only union */
        assert_int_equal(a->combos[k].ncells, cells[k]);
        assert_true(a->combos[k].nmaterials <= a->largest);
    }
    if (max == 0) {
        assert_int_equal(a->ncombos, ref->ncombos);
        assert_true(a->largest <= overlap);         /* issue 29's target */
        for (int k = 0; k < a->ncombos; k++) {      /* each a leaf's exact set */
            bool found = false;
            for (int j = 0; j < ref->ncombos && !found; j++) found = equal(&sets[k], &leaf[j]);
            assert_true(found);
        }
    } else {
        assert_true(a->ncombos <= max);
    }
    int cap = 16, n = 0;
    mset *seen = malloc((size_t)cap * sizeof *seen);
    for (int L = 1; L < a->nlevels; L++) {
        const splat_level *lv = &a->levels[L];
        for (int z = 0; z < lv->height; z++)
            for (int x = 0; x < lv->width; x++) {
                mset u;
                memset(&u, 0, sizeof u);
                for (int cz = z << L; cz < (z + 1) << L && cz < r0->height; cz++)
                    for (int cx = x << L; cx < (x + 1) << L && cx < r0->width; cx++) {
                        uint16_t id = r0->ids[cz * r0->width + cx];
                        if (id == SPLAT_COMBO_HOLE) continue;
                        for (int k = 0; k < WORDS; k++) u.w[k] |= leaf[id].w[k];
                    }
                uint16_t id = lv->ids[z * lv->width + x];
                if (empty(&u)) {
                    assert_int_equal(id, SPLAT_COMBO_HOLE);
                    continue;
                }
                bool is_leaf = false;
                for (int j = 0; j < ref->ncombos && !is_leaf; j++) is_leaf = equal(&u, &leaf[j]);
                if (!is_leaf) {
                    out.unions++;
                    bool dup = false;
                    for (int j = 0; j < n && !dup; j++) dup = equal(&seen[j], &u);
                    if (!dup) {
                        if (n == cap) seen = realloc(seen, (size_t)(cap *= 2) * sizeof *seen);
                        seen[n++] = u;
                        int c = count(&u);
                        out.largest = c > out.largest ? c : out.largest;
                    }
                }
                int smallest = -1;
                for (int k = 0; k < a->ncombos; k++)
                    if (subset(&u, &sets[k]) &&
                        (smallest < 0 || a->combos[k].nmaterials < smallest))
                        smallest = a->combos[k].nmaterials;
                if (id == SPLAT_COMBO_UBER) {
                    assert_int_equal(smallest, -1);
                    out.uber++;
                } else {
                    assert_true(id < a->ncombos);
                    assert_true(subset(&u, &sets[id]));
                    assert_int_equal(a->combos[id].nmaterials, smallest);
                }
            }
    }
    out.distinct = n;
    assert_int_equal(a->uber_nodes, out.uber);
    free(seen);
    free(cells);
    free(sets);
    free(leaf);
    return out;
}
