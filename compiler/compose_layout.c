/* compose_layout.c — the pack's layout (splat_layout, compose.h): one
 * slot per distinct texture, grouped into texture arrays by size and mips,
 * the params, painted masks and vector layers, from the scene; what the
 * composites and the GLSL index by. */
#include "compose_internal.h"

#include <assert.h>
#include <float.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "abi.h"
#include "sg_internal.h"
#include "util.h"

/* ---- layout --------------------------------------------------------------- */

int splat_layout_texture(const splat_layout *L, const ir_texture *t)
{
    for (int i = 0; i < L->ntextures; i++)
        if (ir_texture_same(&L->src->textures[L->textures[i]], t))
            return i;
    return -1;
}

bool splat_layout_init(splat_layout *L, const ir *src, sg_program *prog,
                       const char *compositor,
                       const char *const *materials, int nmaterials,
                       const char *const *painted, int npainted, sg_diags *d)
{
    memset(L, 0, sizeof *L);
    L->src = src;
    L->prog = prog;
    L->compositor = compositor;
    L->materials = xcalloc((size_t)nmaterials, sizeof *L->materials);
    memcpy(L->materials, materials, (size_t)nmaterials * sizeof *materials);
    L->nmaterials = nmaterials;
    L->painted = xcalloc((size_t)npainted, sizeof *L->painted);
    if (npainted)
        memcpy(L->painted, painted, (size_t)npainted * sizeof *painted);
    L->npainted = npainted;
    L->nparams = src->nparams;
    L->texture_of = xcalloc((size_t)src->ntextures, sizeof *L->texture_of);
    L->textures = xcalloc((size_t)src->ntextures, sizeof *L->textures);
    for (int i = 0; i < src->ntextures; i++) {
        int t = splat_layout_texture(L, &src->textures[i]);
        if (t < 0) {
            t = L->ntextures++;
            L->textures[t] = i;
        }
        L->texture_of[i] = t;
    }
    L->tex_array = xcalloc((size_t)L->ntextures + 1, sizeof *L->tex_array);
    L->tex_layer = xcalloc((size_t)L->ntextures + 1, sizeof *L->tex_layer);
    for (int t = 0; t < L->ntextures; t++)
        L->tex_array[t] = t;
    L->narrays = L->ntextures;
    for (int i = 0; i < nmaterials; i++) {
        char name[512];
        snprintf(name, sizeof name, "%s.mask", materials[i]);
        if (!ir_ref_ok(ir_find_root(src, name))) {
            sg_error(d, (sg_loc){0}, SG_E_INTERNAL, "material not lowered");
            splat_layout_free(L);
            return false;
        }
    }
    if (!splat_sites_find(L)) {
        sg_error(d, (sg_loc){0}, SG_E_OUT_OF_MEMORY, "out of memory");
        splat_layout_free(L);
        return false;
    }
    return true;
}

/* The shape a painted leaf named "vector.NAME[.across]" reads, or -1. */
int compose_layout_vector(const splat_layout *L, const char *name, bool *across)
{
    if (strncmp(name, "vector.", 7) != 0) return -1;
    const char *nm = name + 7, *dot = strchr(nm, '.');
    size_t n = dot ? (size_t)(dot - nm) : strlen(nm);
    *across = dot != NULL;
    for (int i = 0; i < L->nvectors; i++)
        if (strlen(L->vectors[i]) == n && !strncmp(L->vectors[i], nm, n))
            return i;
    return -1;
}

/* A painted leaf's local: in_painted<layer>, or in_vector<shape>[_across]. */
void compose_painted_local(const splat_layout *L, const char *name, char *buf, size_t n,
                          char *expr, size_t nexpr)
{
    bool across;
    int v = compose_layout_vector(L, name, &across);
    if (v >= 0) {
        snprintf(buf, n, "in_vector%d%s", v, across ? "_across" : "");
        if (expr)
            snprintf(expr, nexpr, "splat_vector_%s(%d)", across ? "across" : "mask", v);
        return;
    }
    int layer = 0;
    for (int p = 0; p < L->npainted; p++)
        if (strcmp(L->painted[p], name) == 0)
            layer = p;
    snprintf(buf, n, "in_painted%d", layer);
    if (expr)
        snprintf(expr, nexpr, "splat_painted(%d)", layer);
}

bool splat_layout_from_scene(splat_layout *L, const splat_scene *s, sg_diags *d)
{
    const sg_scene *sc = s->desc;
    const char **painted = xcalloc((size_t)sc->npainted, sizeof *painted);
    for (int i = 0; i < sc->npainted; i++)
        painted[i] = sc->painted[i].name;
    bool ok = splat_layout_init(L, &s->ir, s->prog, sc->compositor,
                                (const char *const *)sc->materials, sc->nmaterials,
                                painted, sc->npainted, d);
    free(painted);
    if (ok && sc->nvectors > 0) {
        L->vectors = xcalloc((size_t)sc->nvectors, sizeof *L->vectors);
        for (int i = 0; i < sc->nvectors; i++)
            L->vectors[i] = sc->vectors[i].name;
        L->nvectors = sc->nvectors;
    }
    return ok;
}

void splat_layout_group_textures(splat_layout *L, const int *w, const int *h, const int *mips)
{
    int *first = xcalloc((size_t)L->ntextures + 1, sizeof *first);   /* array -> a texture */
    int *layers = xcalloc((size_t)L->ntextures + 1, sizeof *layers);
    L->narrays = 0;
    for (int t = 0; t < L->ntextures; t++) {
        const ir_texture *x = &L->src->textures[L->textures[t]];
        int a = 0;
        for (; a < L->narrays; a++) {
            int u = first[a];
            const ir_texture *y = &L->src->textures[L->textures[u]];
            if (w[u] == w[t] && h[u] == h[t] && mips[u] == mips[t] && x->filter == y->filter &&
                x->mip == y->mip && x->wrap == y->wrap && x->srgb == y->srgb &&
                layers[a] < SPLAT_MAX_ARRAY_LAYERS)
                break;
        }
        if (a == L->narrays)
            first[L->narrays++] = t;
        L->tex_array[t] = a;
        L->tex_layer[t] = layers[a]++;
    }
    free(first);
    free(layers);
}

void splat_layout_free(splat_layout *L)
{
    free(L->materials);
    free(L->painted);
    free(L->vectors);
    free(L->texture_of);
    free(L->textures);
    free(L->tex_array);
    free(L->tex_layer);
    memset(L, 0, sizeof *L);
}
