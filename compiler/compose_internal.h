/* compose_internal.h — the compositor's internals, shared by its files
 * (the interface is compose.h):
 *
 *   compose_layout.c    the pack layout: texture slots and arrays, params,
 *                       painted masks and vector layers
 *   compose.c           building a combination's composite IR
 *   compose_schedule.c  the region tree, placement, lazy branches
 *   compose_glsl.c      the composite's GLSL, walking the schedule
 */
#ifndef SPLAT_COMPOSE_INTERNAL_H
#define SPLAT_COMPOSE_INTERNAL_H

#include "compose.h"

/* ---- the layout (compose_layout.c) ----------------------------------------- */

int compose_layout_vector(const splat_layout *L, const char *name, bool *across);
void compose_painted_local(const splat_layout *L, const char *name, char *buf, size_t n, char *expr, size_t nexpr);

/* ---- building (compose.c) ------------------------------------------------- */

/* The layers' values, found by their root names ("layer<j>.T" ...). */
void compose_layers_from_roots(const ir *ir, splat_layer *layers, int n);

/* ---- scheduling (compose_schedule.c) --------------------------------------- */

typedef struct region {
    int parent, depth;
    uint32_t owner;        /* lazy side: the mix/select/mul it feeds, else 0 */
    int      side;         /* lazy side: the owner's operand index          */
    bool     kept;         /* lazy side: worth its branch (else merged up)  */
} region;

typedef struct sched {
    const ir *ir;
    region   *regions;
    int       nregions, capregions;
    int      *place;       /* per node: region, or -1 if not needed */
    int      *guard;       /* per layer: G_j                        */
    int      *surface;     /* per layer: W_j                        */
    int     (*lazy)[4];    /* per node: its lazy side region per operand, or -1 */
    int       nlazy;       /* lazy branches kept                    */
} sched;

enum { PLAT_0 = 1, PLAT_1 = 2 };   /* plateau_of (compose_glsl.c) */

/* Whether some component of `iv` (w of them) can be exactly `x`. */
bool compose_can_be(const ir_iv *iv, int w, double x);
void compose_schedule(sched *s, const ir *ir, const splat_layer *layers, int n, bool flat, const uint8_t *lazy);
void compose_sched_free(sched *s);

#endif
