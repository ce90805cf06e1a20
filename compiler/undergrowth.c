/* undergrowth.c — the scene's undergrowth blocks, slots and meshes. */
#include "undergrowth.h"

#include <stdlib.h>
#include <string.h>

#include <stb_image.h>

#include "util.h"

/* Append mesh `m` named `name` (owned), keyed `key`; its index. */
static int mesh_add(splat_ug *u, splat_mesh m, char *name, const char *key)
{
    int i = u->nmeshes++;
    u->meshes = xrealloc(u->meshes, sizeof *u->meshes * (size_t)u->nmeshes);
    u->mesh_names = xrealloc(u->mesh_names, sizeof *u->mesh_names * (size_t)u->nmeshes);
    u->mesh_keys = xrealloc(u->mesh_keys, sizeof *u->mesh_keys * (size_t)u->nmeshes);
    u->far = xrealloc(u->far, sizeof *u->far * (size_t)u->nmeshes);
    u->meshes[i] = m;
    u->mesh_names[i] = name;
    u->mesh_keys[i] = key;
    u->far[i] = -1;
    return i;
}

static int mesh_index(splat_ug *u, const sg_undergrowth *g, sg_diags *d)
{
    const char *key = g->obj ? g->obj : g->mesh;
    for (int i = 0; i < u->nmeshes; i++)
        if (u->mesh_keys[i] && strcmp(u->mesh_keys[i], key) == 0)
            return i;
    splat_mesh m = {0};
    if (g->obj) {
        char *err = NULL;
        if (!splat_mesh_obj(g->obj, &m, &err)) {
            sg_errorf(d, g->loc, SG_E_SETTING, "cannot use mesh '%s': %s", g->obj,
                      err ? err : "unreadable");
            free(err);
            return -1;
        }
    } else if (!splat_mesh_builtin(g->mesh, &m)) {
        sg_errorf(d, g->loc, SG_E_SETTING, "unknown built-in mesh '%s'", g->mesh);
        return -1;
    }
    const char *base = strrchr(key, '/');
    int i = mesh_add(u, m, xstrdup(base ? base + 1 : key), key);
    splat_mesh far;
    if (!g->obj && splat_mesh_builtin_far(g->mesh, &far)) {
        char name[64];
        snprintf(name, sizeof name, "%s.far", g->mesh);
        int f = mesh_add(u, far, xstrdup(name), NULL);   /* never looked up */
        u->far[i] = f;   /* after the call: it moves u->far */
    }
    return i;
}

/* Block g's texture index (loaded once per path), -1 without one. */
static int texture_index(splat_ug *u, const sg_undergrowth *g, sg_diags *d)
{
    if (!g->texture)
        return -1;
    for (int i = 0; i < u->ntextures; i++)
        if (strcmp(u->textures[i].path, g->texture) == 0)
            return i;
    if (u->ntextures == SPLAT_MAX_UG_TEXTURES) {
        sg_errorf(d, g->loc, SG_E_OVER_LIMIT, "the scene's undergrowth uses more than %d "
                  "textures", SPLAT_MAX_UG_TEXTURES);
        return -2;
    }
    char why[160];
    FILE *f = splat_input_fopen(g->texture, SPLAT_MAX_IMAGE_BYTES, why, sizeof why);
    int w = 0, h = 0, comp;
    uint8_t *px = f ? stbi_load_from_file(f, &w, &h, &comp, 4) : NULL;
    if (f)
        fclose(f);
    if (!px || w < 1 || h < 1 || w > SPLAT_MAX_UG_TEXTURE || h > SPLAT_MAX_UG_TEXTURE) {
        sg_errorf(d, g->loc, SG_E_IO, "cannot use texture '%s': %s", g->texture,
                  !f ? why : !px ? "not an image stb_image reads" : "too large");
        stbi_image_free(px);
        return -2;
    }
    u->textures = xrealloc(u->textures, sizeof *u->textures * (size_t)(u->ntextures + 1));
    u->textures[u->ntextures] = (splat_ug_texture){ g->texture, w, h, px };
    return u->ntextures++;
}

/* The runtime's instance buffer at the default radius within what every
 * device holds (abi.h SPLAT_UG_PACK_INSTANCE_BYTES): the blocks' densities
 * add up, so the error is at the block that goes over, with the total. */
static bool check_instances(const splat_ug *u, sg_diags *d)
{
    uint64_t per_cell = 0, pool = splat_ug_pool(SPLAT_UG_RADIUS);
    double total = 0;
    for (int b = 0; b < u->nblocks; b++) {
        const sg_undergrowth *g = u->blocks[b].u;
        per_cell += splat_ug_candidates(g->density);
        total += g->density;
        uint64_t bytes = pool * per_cell * SPLAT_UG_INSTANCE_BYTES;
        if (bytes > SPLAT_UG_PACK_INSTANCE_BYTES) {
            sg_errorf(d, g->loc, SG_E_OVER_LIMIT, "the scene's undergrowth densities add up "
                      "to %g instances per m^2 here; the runtime's instance buffer would be "
                      "%llu MiB, over the %llu MiB every device holds (about %.0f per m^2 "
                      "in all)", total, (unsigned long long)(bytes >> 20),
                      (unsigned long long)(SPLAT_UG_PACK_INSTANCE_BYTES >> 20),
                      (double)SPLAT_UG_PACK_INSTANCE_BYTES /
                          ((double)pool * SPLAT_UG_INSTANCE_BYTES * SPLAT_UG_CELL * SPLAT_UG_CELL));
            return false;
        }
    }
    return true;
}

bool splat_ug_init(splat_ug *u, const splat_scene *s, sg_diags *d)
{
    memset(u, 0, sizeof *u);
    u->slot_of = xcalloc((size_t)s->nmaterials, sizeof *u->slot_of);
    for (int i = 0; i < s->nmaterials; i++) {
        u->slot_of[i] = -1;
        int pm = sg_material_find(s->prog, s->desc->materials[i]);
        int n = pm >= 0 ? sg_undergrowth_count(s->prog, pm) : 0;
        if (n == 0)
            continue;
        if (u->nslots == SPLAT_UG_SLOTS) {
            sg_errorf(d, s->desc->material_locs[i], SG_E_OVER_LIMIT,
                      "more than %d materials of the scene carry undergrowth",
                      SPLAT_UG_SLOTS);
            return false;
        }
        u->slot_of[i] = u->nslots++;
        for (int k = 0; k < n; k++) {
            const sg_undergrowth *g = sg_undergrowth_get(s->prog, pm, k);
            int mesh = mesh_index(u, g, d);
            if (mesh < 0)
                return false;
            int tex = texture_index(u, g, d);
            if (tex < -1)
                return false;
            u->blocks = xrealloc(u->blocks, sizeof *u->blocks * (size_t)(u->nblocks + 1));
            u->blocks[u->nblocks++] = (splat_ug_block){
                .material = i, .slot = u->slot_of[i], .mesh = mesh, .u = g, .texture = tex};
        }
    }
    return check_instances(u, d);
}

void splat_ug_free(splat_ug *u)
{
    for (int i = 0; i < u->nmeshes; i++) {
        splat_mesh_free(&u->meshes[i]);
        free(u->mesh_names[i]);
    }
    free(u->meshes);
    free(u->mesh_names);
    free(u->mesh_keys);
    free(u->far);
    for (int i = 0; i < u->ntextures; i++)
        stbi_image_free(u->textures[i].rgba);
    free(u->textures);
    free(u->blocks);
    free(u->slot_of);
    memset(u, 0, sizeof *u);
}

bool splat_ug_in(const splat_ug *u, const int *materials, int n)
{
    for (int i = 0; i < n; i++)
        if (u->slot_of && u->slot_of[materials[i]] >= 0)
            return true;
    return false;
}

static bool put_u32(FILE *f, uint32_t v)
{
    uint8_t b[4] = {v & 255, (v >> 8) & 255, (v >> 16) & 255, v >> 24};
    return fwrite(b, 1, 4, f) == 4;
}

static bool put_f32(FILE *f, float x)
{
    uint32_t v;
    memcpy(&v, &x, 4);
    return put_u32(f, v);
}

/* "SPLATMSH", version 1, count; per mesh its vertex and index counts;
 * then per mesh its vertices (8 floats: position, normal, uv) and its
 * indices (uint32), all little-endian. */
bool splat_ug_write_meshes(const splat_ug *u, FILE *f)
{
    bool ok = fwrite("SPLATMSH", 1, 8, f) == 8 && put_u32(f, 1) &&
              put_u32(f, (uint32_t)u->nmeshes);
    for (int i = 0; ok && i < u->nmeshes; i++)
        ok = put_u32(f, u->meshes[i].nv) && put_u32(f, u->meshes[i].nidx);
    for (int i = 0; ok && i < u->nmeshes; i++) {
        const splat_mesh *m = &u->meshes[i];
        for (uint32_t v = 0; ok && v < m->nv; v++) {
            const splat_mesh_vertex *x = &m->v[v];
            for (int k = 0; ok && k < 3; k++)
                ok = put_f32(f, x->pos[k]);
            for (int k = 0; ok && k < 3; k++)
                ok = put_f32(f, x->nrm[k]);
            for (int k = 0; ok && k < 2; k++)
                ok = put_f32(f, x->uv[k]);
        }
        for (uint32_t k = 0; ok && k < m->nidx; k++)
            ok = put_u32(f, m->idx[k]);
    }
    return ok;
}

/* "SPLATUGT", version 1, count; per texture its width and height; then
 * per texture its texels, rows top first, 4 bytes each (sRGB rgb, linear
 * alpha), all little-endian. */
bool splat_ug_write_textures(const splat_ug *u, FILE *f)
{
    bool ok = fwrite("SPLATUGT", 1, 8, f) == 8 && put_u32(f, 1) &&
              put_u32(f, (uint32_t)u->ntextures);
    for (int i = 0; ok && i < u->ntextures; i++)
        ok = put_u32(f, (uint32_t)u->textures[i].width) &&
             put_u32(f, (uint32_t)u->textures[i].height);
    for (int i = 0; ok && i < u->ntextures; i++) {
        size_t n = (size_t)u->textures[i].width * (size_t)u->textures[i].height * 4;
        ok = fwrite(u->textures[i].rgba, 1, n, f) == n;
    }
    return ok;
}
