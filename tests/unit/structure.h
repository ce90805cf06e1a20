/* structure.h — the structure the scene analysis promises (compiler/
 * analysis.c; issue 29 "composites only where pixels need them"), checked
 * with cmocka's asserts (structure.c; linked into every unit test and the
 * generated-world test, tests/bench/test_world.c).
 *
 * structure_check(ref, a, max): `ref` is the scene analysed without
 * merging, `a` the analysis under test (`ref` itself, or merged to at most
 * `max` combinations; 0: not merged):
 *   - a's leaf combinations are ref's (nleaf, leaf_largest), and each of a's
 *     combinations shades leaf cells: none is a coarse node's union;
 *   - unmerged: every combination is some leaf cell's exact set, and the
 *     largest is at most the largest leaf-cell overlap;
 *   - merged: at most `max` combinations, each cell's a superset of its own;
 *   - every coarse node: SPLAT_COMBO_HOLE where all its cells are holes, else
 *     the smallest of a's combinations covering the union of its leaf cells'
 *     sets (ref's), or SPLAT_COMBO_UBER where none covers it.
 * Scenes of up to 512 materials. */
#ifndef SPLAT_TEST_STRUCTURE_H
#define SPLAT_TEST_STRUCTURE_H

#include "analysis.h"

typedef struct structure_counts {
    int uber;        /* coarse nodes left to the über-shader               */
    int unions;      /* coarse nodes whose union is no leaf's combination:
                        each a composite of its own before issue 29       */
    int distinct;    /* distinct such unions                               */
    int largest;     /* most materials in one of them                      */
} structure_counts;

structure_counts structure_check(const splat_analysis *ref, const splat_analysis *a, int max);

#endif
