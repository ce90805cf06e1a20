/* pack_sections.c — the manifest's sections other than shaders and
 * textures (compiler/PACK.md): scene, light, materials, params, world
 * sites, undergrowth (meshes.bin, ugtex.bin), the far atlas, vectors.bin;
 * each value checked against its range before use (pack_internal.h). */
#include "pack_internal.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* meshes.bin (PACK.md): its header against the manifest's meshes, then
 * every vertex finite and every index inside its mesh. */
static bool read_meshes(rt_pk_reader *r, const char *rel, rt_pack_ug *u)
{
    size_t n = 0;
    uint8_t *data = rt_pk_pack_file(r, "undergrowth.file", rel, 0, MAX_BINARY, &n);
    if (!data)
        return false;
    size_t head = 16 + 8 * (size_t)u->nmeshes;
    size_t want = head + 32 * (size_t)u->nvertices + 4 * (size_t)u->nindices;
    const char *bad = NULL;
    if (n != want || memcmp(data, "SPLATMSH", 8) || rt_pk_le32(data + 8) != 1 ||
        rt_pk_le32(data + 12) != (uint32_t)u->nmeshes)
        bad = "does not match the manifest's meshes (size, magic, version or count)";
    for (int i = 0; !bad && i < u->nmeshes; i++)
        if (rt_pk_le32(data + 16 + 8 * i) != u->meshes[i].nv ||
            rt_pk_le32(data + 20 + 8 * i) != u->meshes[i].nidx)
            bad = "has mesh sizes other than the manifest's";
    u->vertices = bad ? NULL : malloc(32 * (size_t)u->nvertices + 1);
    u->indices = bad ? NULL : malloc(4 * (size_t)u->nindices + 1);
    if (!bad && (!u->vertices || !u->indices))
        bad = "does not fit in memory";
    const uint8_t *at = data + head;
    for (int i = 0; !bad && i < u->nmeshes; i++) {
        const rt_pack_ug_mesh *m = &u->meshes[i];
        for (uint32_t k = 0; k < 8 * m->nv; k++, at += 4) {
            uint32_t w = rt_pk_le32(at);
            float f;
            memcpy(&f, &w, 4);
            if (!isfinite(f) || fabsf(f) > (float)SPLAT_MAX_MESH_VALUE)
                bad = "holds a vertex value that is not finite or over 1000";
            u->vertices[8 * (size_t)m->first_vertex + k] = f;
        }
        for (uint32_t k = 0; k < m->nidx; k++, at += 4) {
            uint32_t x = rt_pk_le32(at);
            if (x >= m->nv)
                bad = "holds an index past its mesh's vertices";
            u->indices[m->first_index + k] = x;
        }
    }
    free(data);
    if (bad)
        return rt_fail(r->e, RT_E_PACK_FILE, r->manifest, "undergrowth.file", rel, bad);
    return true;
}

/* undergrowth.textures (optional): each one's width and height. */
static bool read_ug_texture_sizes(rt_pk_reader *r, json_t *o, rt_pack_ug *u)
{
    json_t *ts = json_object_get(o, "textures");
    if (!ts)
        return true;
    if (!json_is_array(ts) || json_array_size(ts) < 1 ||
        json_array_size(ts) > SPLAT_MAX_UG_TEXTURES)
        return rt_pk_field_fail(r, "undergrowth.textures:", "must be an array of 1 to 8 entries");
    u->ntextures = (int)json_array_size(ts);
    u->textures = calloc((size_t)u->ntextures, sizeof *u->textures);
    if (!u->textures)
        return false;
    for (int i = 0; i < u->ntextures; i++) {
        char where[64];
        snprintf(where, sizeof where, "undergrowth.textures[%d]", i);
        json_t *t = json_array_get(ts, (size_t)i);
        if (!rt_pk_get_int(r, t, "width", where, 1, SPLAT_MAX_UG_TEXTURE, &u->textures[i].width) ||
            !rt_pk_get_int(r, t, "height", where, 1, SPLAT_MAX_UG_TEXTURE, &u->textures[i].height))
            return false;
    }
    return true;
}

/* ugtex.bin (PACK.md "Undergrowth"): its size from the manifest's sizes,
 * checked before it is read, and its header against them. */
static bool read_ug_textures(rt_pk_reader *r, json_t *o, rt_pack_ug *u)
{
    if (u->ntextures == 0)
        return true;
    const char *rel;
    if (!rt_pk_get_string(r, o, "texture_file", "undergrowth", &rel))
        return false;
    size_t head = 16 + 8 * (size_t)u->ntextures, want = head;
    for (int i = 0; i < u->ntextures; i++)
        want += 4 * (size_t)u->textures[i].width * (size_t)u->textures[i].height;
    uint8_t *data = rt_pk_pack_file(r, "undergrowth.texture_file", rel, want, 0, NULL);
    if (!data)
        return false;
    const char *bad = NULL;
    if (memcmp(data, "SPLATUGT", 8) || rt_pk_le32(data + 8) != 1 ||
        rt_pk_le32(data + 12) != (uint32_t)u->ntextures)
        bad = "does not match the manifest's textures (magic, version or count)";
    for (int i = 0; !bad && i < u->ntextures; i++)
        if (rt_pk_le32(data + 16 + 8 * i) != (uint32_t)u->textures[i].width ||
            rt_pk_le32(data + 20 + 8 * i) != (uint32_t)u->textures[i].height)
            bad = "has texture sizes other than the manifest's";
    const uint8_t *at = data + head;
    for (int i = 0; !bad && i < u->ntextures; i++) {
        size_t n = 4 * (size_t)u->textures[i].width * (size_t)u->textures[i].height;
        u->textures[i].rgba = malloc(n);
        if (!u->textures[i].rgba) {
            bad = "does not fit in memory";
            break;
        }
        memcpy(u->textures[i].rgba, at, n);
        at += n;
    }
    free(data);
    if (bad)
        return rt_fail(r->e, RT_E_PACK_FILE, r->manifest, "undergrowth.texture_file", rel, bad);
    return true;
}

/* "far_atlas" (optional): far.atlas, its size from the manifest's width,
 * height and levels checked against the file's before it is read, and its
 * header against the manifest (compiler/far_atlas.h). */
bool rt_pk_read_far(rt_pk_reader *r, json_t *root)
{
    json_t *o = rt_pk_get(r, root, "far_atlas", "manifest", false);
    if (!o || json_is_null(o))
        return true;
    rt_pack_far *f = &r->p->far;
    const char *file;
    if (!rt_pk_get_int(r, o, "width", "far_atlas", 1, FAR_ATLAS_MAX_SIDE, &f->width) ||
        !rt_pk_get_int(r, o, "height", "far_atlas", 1, FAR_ATLAS_MAX_SIDE, &f->height) ||
        !rt_pk_get_int(r, o, "levels", "far_atlas", 1,
                       far_atlas_levels_max((uint32_t)f->width, (uint32_t)f->height), &f->levels) ||
        !rt_pk_get_string(r, o, "file", "far_atlas", &file))
        return false;
    size_t want = (size_t)far_atlas_file_bytes((uint32_t)f->width, (uint32_t)f->height,
                                               f->levels);
    size_t n = 0;
    uint8_t *data = rt_pk_pack_file(r, "far_atlas.file", file, want, want, &n);
    if (!data)
        return false;
    double tx, tz;
    uint64_t bx, bz;
    memcpy(&bx, data + 24, 8);   /* little-endian hosts only, as le32 */
    memcpy(&bz, data + 32, 8);
    memcpy(&tx, &bx, 8);
    memcpy(&tz, &bz, 8);
    if (memcmp(data, FAR_ATLAS_MAGIC, 8) || rt_pk_le32(data + 8) != FAR_ATLAS_VERSION ||
        rt_pk_le32(data + 12) != (uint32_t)f->width ||
        rt_pk_le32(data + 16) != (uint32_t)f->height ||
        rt_pk_le32(data + 20) != (uint32_t)f->levels || !isfinite(tx) || !isfinite(tz) ||
        !(tx > 0) || !(tz > 0)) {
        free(data);
        return rt_fail(r->e, RT_E_PACK_FILE, r->manifest, "far_atlas.file", file,
                       "does not match the manifest's far_atlas (magic, version, size, levels "
                       "or texel size)");
    }
    f->data = data;
    f->n = n;
    f->texel[0] = tx;
    f->texel[1] = tz;
    return true;
}

/* Whether the words are a well-formed vector buffer of `nshapes` shapes
 * (abi.h): every count within its pack limit, the sections adding up to
 * the words exactly, every float finite and in range, every index in
 * bounds — the shader indexes with them unchecked.  64-bit sums. */
static bool vectors_valid(const uint32_t *w, size_t nw, uint32_t nshapes, const char **why)
{
#define VFAIL(msg) do { *why = msg; return false; } while (0)
    if (nw < SPLAT_VEC_HEADER) VFAIL("is shorter than its header");
    uint64_t ncx = w[0], ncz = w[1], ns = w[2], nseg = w[3], nent = w[4];
    if (ncx < 1 || ncz < 1 || ncx > SPLAT_MAX_VECTOR_GRID || ncz > SPLAT_MAX_VECTOR_GRID)
        VFAIL("has a grid outside 1..SPLAT_MAX_VECTOR_GRID cells a side");
    if (ns != nshapes || ns < 1 || ns > SPLAT_MAX_VECTORS)
        VFAIL("has a shape count that is not the manifest's (1..SPLAT_MAX_VECTORS)");
    if (nseg < 1 || nseg > SPLAT_MAX_VECTOR_SEGMENTS)
        VFAIL("has a segment count outside 1..SPLAT_MAX_VECTOR_SEGMENTS");
    uint64_t ncells = ncx * ncz;
    if (nent > ncells * SPLAT_MAX_VECTOR_CELL)
        VFAIL("has more entries than its cells may list");
    uint64_t cells = SPLAT_VEC_HEADER + (uint64_t)SPLAT_VEC_SHAPE * ns;
    uint64_t ent = cells + (uint64_t)SPLAT_VEC_CELL * ncells, segs = ent + nent;
    if (segs + (uint64_t)SPLAT_VEC_SEG * nseg != nw)
        VFAIL("has sections that do not add up to its size");
    float f[3];
    memcpy(f, &w[5], sizeof f);
    if (!(fabsf(f[0]) <= SPLAT_MAX_EXTENT * 2) || !(fabsf(f[1]) <= SPLAT_MAX_EXTENT * 2) ||
        !(f[2] > 0 && f[2] <= SPLAT_MAX_EXTENT * 2))
        VFAIL("has a non-finite grid origin or cell size");
    for (uint64_t s = 0; s < ns; s++) {
        const uint32_t *q = &w[SPLAT_VEC_HEADER + SPLAT_VEC_SHAPE * s];
        float hf[2];
        memcpy(hf, q, sizeof hf);
        if (!(hf[0] >= 0 && hf[0] <= SPLAT_MAX_VECTOR_WIDTH) ||
            !(hf[1] >= 0 && hf[1] <= SPLAT_MAX_VECTOR_WIDTH) || (q[2] & 255u) > 1 ||
            (q[2] >> 8) > 1)
            VFAIL("has a shape with a bad width, falloff, profile or kind");
    }
    for (uint64_t i = 0; i < ncells; i++) {
        const uint32_t *q = &w[cells + SPLAT_VEC_CELL * i];
        float r[2];
        memcpy(r, &q[4], sizeof r);
        if (q[1] > SPLAT_MAX_VECTOR_CELL || (uint64_t)q[0] + q[1] > nent ||
            (ns < 32 && (q[2] >> ns) != 0) || !isfinite(r[0]) || !isfinite(r[1]))
            VFAIL("has a cell whose entries, inside bits or reference point are out of range");
    }
    for (uint64_t i = 0; i < nent; i++)
        if (w[ent + i] >= nseg) VFAIL("has an entry past its segments");
    for (uint64_t k = 0; k < nseg; k++) {
        const uint32_t *q = &w[segs + SPLAT_VEC_SEG * k];
        float c[4];
        memcpy(c, q, sizeof c);
        for (int j = 0; j < 4; j++)
            if (!(fabsf(c[j]) <= SPLAT_MAX_EXTENT * 2)) VFAIL("has a non-finite segment");
        if (q[4] >= ns) VFAIL("has a segment of no shape");
    }
    return true;
#undef VFAIL
}

/* "vectors" (optional): the spline and polygon shapes, vectors.bin. */
bool rt_pk_read_vectors(rt_pk_reader *r, json_t *root)
{
    json_t *o = rt_pk_get(r, root, "vectors", "manifest", false);
    if (!o || json_is_null(o))
        return true;
    const char *file;
    int words;
    /* the buffer within Vulkan's minimum maxStorageBufferRange (2^27 B) */
    if (!rt_pk_get_int(r, o, "words", "vectors", SPLAT_VEC_HEADER, SPLAT_MAX_VECTOR_WORDS,
                       &words) ||
        !rt_pk_get_string(r, o, "file", "vectors", &file))
        return false;
    json_t *names = rt_pk_get_array(r, o, "shapes", "vectors", true);
    if (!names)
        return false;
    size_t ns = json_array_size(names);
    if (ns < 1 || ns > SPLAT_MAX_VECTORS)
        return rt_pk_field_fail(r, "vectors.shapes:", "must have 1 to 32 entries");
    for (size_t i = 0; i < ns; i++)
        if (!json_is_string(json_array_get(names, i)))
            return rt_pk_field_fail(r, "vectors.shapes:", "must be names (strings)");
    size_t want = 16 + 4 * (size_t)words, n = 0;
    uint8_t *data = rt_pk_pack_file(r, "vectors.file", file, want, want, &n);
    if (!data)
        return false;
    if (memcmp(data, "SPLATVEC", 8) || rt_pk_le32(data + 8) != 1 ||
        rt_pk_le32(data + 12) != (uint32_t)words) {
        free(data);
        return rt_fail(r->e, RT_E_PACK_FILE, r->manifest, "vectors.file", file,
                       "does not match the manifest's vectors (magic, version 1, words)");
    }
    uint32_t *w = malloc(4 * (size_t)words);
    if (!w) {
        free(data);
        return false;
    }
    for (int i = 0; i < words; i++)
        w[i] = rt_pk_le32(data + 16 + 4 * (size_t)i);
    free(data);
    const char *why = NULL;
    if (!vectors_valid(w, (size_t)words, (uint32_t)ns, &why)) {
        free(w);
        return rt_fail(r->e, RT_E_PACK_FILE, r->manifest, "vectors.file", file, why);
    }
    r->p->vectors = w;
    r->p->nvectors = (size_t)words;
    return true;
}

/* undergrowth.meshes: counts, names and far versions (their data:
 * read_meshes). */
static bool read_ug_meshes(rt_pk_reader *r, json_t *ms, rt_pack_ug *u)
{
    for (int i = 0; i < u->nmeshes; i++) {
        char where[64];
        snprintf(where, sizeof where, "undergrowth.meshes[%d]", i);
        json_t *m = json_array_get(ms, (size_t)i);
        int nv, ni;
        const char *name;
        if (!rt_pk_get_int(r, m, "vertices", where, 1, SPLAT_MAX_MESH_VERTICES, &nv) ||
            !rt_pk_get_int(r, m, "indices", where, 3, SPLAT_MAX_MESH_INDICES, &ni) ||
            !rt_pk_get_string(r, m, "name", where, &name))
            return false;
        if (ni % 3)
            return rt_pk_field_fail(r, where, "indices: must be a multiple of 3");
        int far = -1;
        if (json_object_get(m, "far") &&
            !rt_pk_get_int(r, m, "far", where, 0, (int)json_array_size(ms) - 1, &far))
            return false;
        u->meshes[i] = (rt_pack_ug_mesh){ (uint32_t)nv, (uint32_t)ni, u->nvertices, u->nindices,
                                          far };
        u->nvertices += (uint32_t)nv;
        u->nindices += (uint32_t)ni;
    }
    for (int i = 0; i < u->nmeshes; i++) {   /* a far version is a plain mesh */
        rt_pack_ug_mesh *m = &u->meshes[i];
        if (m->far >= 0 && (m->far == i || u->meshes[m->far].far >= 0))
            return rt_pk_field_fail(r, "undergrowth.meshes:",
                                    "far: must name another mesh that has no far version");
    }
    return true;
}

/* undergrowth.blocks[i] (`where`), each key within its range. */
static bool read_ug_block(rt_pk_reader *r, json_t *b, const char *where, rt_pack_ug_block *k)
{
    const rt_pack_ug *u = &r->p->ug;
    const char *align, *lighting, *cutout;
    if (!rt_pk_get_int(r, b, "material", where, 0, r->p->nmaterials - 1, &k->material) ||
        !rt_pk_get_int(r, b, "slot", where, 0, u->nslots - 1, &k->slot) ||
        !rt_pk_get_int(r, b, "mesh", where, 0, u->nmeshes - 1, &k->mesh) ||
        !rt_pk_get_number(r, b, "density", where, &k->density) ||
        !rt_pk_get_vec(r, b, "scale", where, 2, k->scale) ||
        !rt_pk_get_number(r, b, "blend", where, &k->blend) ||
        !rt_pk_get_vec(r, b, "color", where, 3, k->color) ||
        !rt_pk_get_string(r, b, "align", where, &align) ||
        !rt_pk_get_number(r, b, "root_blend", where, &k->root_blend) ||
        !rt_pk_get_string(r, b, "lighting", where, &lighting) ||
        !rt_pk_get_string(r, b, "cutout", where, &cutout) ||
        !rt_pk_get_vec(r, b, "wind", where, 4, k->wind) ||
        !rt_pk_get_number(r, b, "shadow", where, &k->shadow) ||
        !rt_pk_get_int(r, b, "texture", where, -1, u->ntextures - 1, &k->texture))
        return false;
    if (!(k->root_blend >= 0 && k->root_blend <= 1))
        return rt_pk_field_fail(r, where, "root_blend: must be in [0, 1]");
    if (!(k->shadow >= 0 && k->shadow <= 1))
        return rt_pk_field_fail(r, where, "shadow: must be in [0, 1]");
    if (!(fabs(hypot(k->wind[0], k->wind[1]) - 1) <= 1e-3))
        return rt_pk_field_fail(r, where, "wind: its direction (x, z) must be a unit vector");
    if (!(k->wind[2] >= 0 && k->wind[2] <= SPLAT_MAX_UG_WIND))
        return rt_pk_field_fail(r, where, "wind: the sway must be in [0, 2]");
    if (!(k->wind[3] >= 0 && k->wind[3] <= 1))
        return rt_pk_field_fail(r, where, "wind: the gust must be in [0, 1]");
    if (strcmp(lighting, "terrain") && strcmp(lighting, "mesh"))
        return rt_pk_field_fail(r, where, "lighting: must be \"terrain\" or \"mesh\"");
    if (strcmp(cutout, "frond") && strcmp(cutout, "none") && strcmp(cutout, "alpha"))
        return rt_pk_field_fail(r, where, "cutout: must be \"none\", \"frond\" or \"alpha\"");
    k->light_terrain = strcmp(lighting, "terrain") == 0;
    k->cutout = strcmp(cutout, "frond") == 0 ? 1 : strcmp(cutout, "alpha") == 0 ? 2 : 0;
    if (k->cutout == 2 && k->texture < 0)
        return rt_pk_field_fail(r, where, "cutout: \"alpha\" needs a texture");
    if (!(k->density > 0 && k->density <= SPLAT_MAX_UG_DENSITY))
        return rt_pk_field_fail(r, where, "density: must be in (0, 64]");
    if (!(k->scale[0] > 0 && k->scale[0] <= k->scale[1] && k->scale[1] <= 100))
        return rt_pk_field_fail(r, where, "scale: must be 0 < lo <= hi <= 100");
    if (!(k->blend >= 0 && k->blend <= 1))
        return rt_pk_field_fail(r, where, "blend: must be in [0, 1]");
    for (int c = 0; c < 3; c++)
        if (!(k->color[c] >= 0 && k->color[c] <= 1))
            return rt_pk_field_fail(r, where, "color: must be in [0, 1]");
    if (strcmp(align, "normal") && strcmp(align, "upright"))
        return rt_pk_field_fail(r, where, "align: must be \"normal\" or \"upright\"");
    k->align_normal = strcmp(align, "normal") == 0;
    return true;
}

/* "undergrowth" (optional): slots, meshes, blocks, meshes.bin. */
bool rt_pk_read_undergrowth(rt_pk_reader *r, json_t *root)
{
    json_t *o = rt_pk_get(r, root, "undergrowth", "manifest", false);
    if (!o || json_is_null(o))
        return true;
    rt_pack_ug *u = &r->p->ug;
    int texels;
    const char *file;
    if (!rt_pk_get_int(r, o, "slots", "undergrowth", 1, SPLAT_UG_SLOTS, &u->nslots) ||
        !rt_pk_get_int(r, o, "texels", "undergrowth", SPLAT_UG_TEXELS, SPLAT_UG_TEXELS, &texels) ||
        !rt_pk_get_string(r, o, "file", "undergrowth", &file))
        return false;
    json_t *ms = rt_pk_get_array(r, o, "meshes", "undergrowth", true);
    json_t *bs = ms ? rt_pk_get_array(r, o, "blocks", "undergrowth", true) : NULL;
    if (!bs)
        return false;
    if (json_array_size(ms) < 1 || json_array_size(ms) > 64)
        return rt_pk_field_fail(r, "undergrowth.meshes:", "must have 1 to 64 entries");
    if (json_array_size(bs) < 1 || json_array_size(bs) > SPLAT_MAX_UG_BLOCKS)
        return rt_pk_field_fail(r, "undergrowth.blocks:", "must have 1 to 64 entries");
    if (!read_ug_texture_sizes(r, o, u))
        return false;
    u->nmeshes = (int)json_array_size(ms);
    u->nblocks = (int)json_array_size(bs);
    u->meshes = calloc((size_t)u->nmeshes, sizeof *u->meshes);
    u->blocks = calloc((size_t)u->nblocks, sizeof *u->blocks);
    if (!u->meshes || !u->blocks)
        return false;
    if (!read_ug_meshes(r, ms, u))
        return false;
    for (int i = 0; i < u->nblocks; i++) {
        char where[64];
        snprintf(where, sizeof where, "undergrowth.blocks[%d]", i);
        if (!read_ug_block(r, json_array_get(bs, (size_t)i), where, &u->blocks[i]))
            return false;
    }
    return read_meshes(r, file, u) && read_ug_textures(r, o, u);
}

/* scene.light (optional, and each of its fields): over the defaults. */
static bool read_light(rt_pk_reader *r, json_t *scene)
{
    rt_light *l = &r->p->light;
    rt_light_default(l);
    json_t *o = rt_pk_get(r, scene, "light", "scene", false);
    if (!o)
        return true;
    if (!json_is_object(o))
        return rt_pk_field_fail(r, "scene.light:", "must be an object");
    for (int k = 0; k < SPLAT_LIGHT_COUNT; k++) {
        const splat_light_key *lk = &splat_light_keys[k];
        double *v = rt_light_values(l, k);
        if (json_object_get(o, lk->key) &&
            !(lk->n == 1 ? rt_pk_get_number(r, o, lk->key, "scene.light", v)
                         : rt_pk_get_vec(r, o, lk->key, "scene.light", lk->n, v)))
            return false;
    }
    const char *bad = rt_light_check(l);
    return bad ? rt_pk_field_fail(r, "scene.light:", bad) : true;
}

/* The heightfield's bytes (W*H little-endian uint16) and its holes. */
static bool read_heights(rt_pk_reader *r, json_t *hf, const char *file)
{
    rt_pack *p = r->p;
    size_t texels = (size_t)p->hf_width * (size_t)p->hf_height;
    uint8_t *raw = rt_pk_pack_file(r, "scene.heightfield.file", file, texels * 2, 0, NULL);
    if (!raw)
        return false;
    p->heights = malloc(texels * sizeof *p->heights);
    if (!p->heights) {
        free(raw);
        return rt_pk_field_fail(r, "heightfield:", "out of memory");
    }
    for (size_t i = 0; i < texels; i++)
        p->heights[i] = (uint16_t)(raw[2 * i] | raw[2 * i + 1] << 8);
    free(raw);
    /* the terrain's holes (PACK.md), optional: W*H bytes, 0 or 255 */
    if (rt_pk_get(r, hf, "holes", "scene.heightfield", false)) {
        const char *hfile;
        if (!rt_pk_get_string(r, hf, "holes", "scene.heightfield", &hfile))
            return false;
        p->holes = rt_pk_pack_file(r, "scene.heightfield.holes", hfile, texels, 0, NULL);
        if (!p->holes)
            return false;
    }
    return true;
}

/* scene.destruction: the destructible area (destruction.c), or null. */
static bool read_destruction(rt_pk_reader *r, json_t *scene)
{
    rt_pack *p = r->p;
    json_t *dd = rt_pk_get(r, scene, "destruction", "scene", false);
    if (dd && !json_is_null(dd)) {
        if (!rt_pk_get_vec(r, dd, "origin", "scene.destruction", 2, p->destr_origin) ||
            !rt_pk_get_vec(r, dd, "size", "scene.destruction", 2, p->destr_size) ||
            !rt_pk_get_number(r, dd, "cell_size", "scene.destruction", &p->destr_cell))
            return false;
        if (!(p->destr_cell > 0) || !(p->destr_size[0] > 0) || !(p->destr_size[1] > 0) ||
            !isfinite(p->destr_origin[0]) || !isfinite(p->destr_origin[1]) ||
            !isfinite(p->destr_size[0]) || !isfinite(p->destr_size[1]))
            return rt_pk_field_fail(r, "scene.destruction:",
                                    "needs a finite origin, a positive size "
                                    "and a positive cell_size");
        double side = p->destr_size[0] > p->destr_size[1] ? p->destr_size[0] : p->destr_size[1];
        if (!(side / p->destr_cell <= SPLAT_MAX_DESTRUCTION_CELLS)) {
            char what[200];
            snprintf(what, sizeof what, "size / cell_size is %.0f cells per side, over the "
                     "pack limit of %d", ceil(side / p->destr_cell), SPLAT_MAX_DESTRUCTION_CELLS);
            return rt_pk_field_fail(r, "scene.destruction:", what);
        }
        p->has_destruction = true;
    }
    return true;
}

/* scene.cameras (optional). */
static bool read_cameras(rt_pk_reader *r, json_t *scene)
{
    rt_pack *p = r->p;
    json_t *cams = rt_pk_get_array(r, scene, "cameras", "scene", false);
    if (cams) {
        p->ncameras = (int)json_array_size(cams);
        p->cameras = calloc((size_t)p->ncameras + 1, sizeof *p->cameras);
        if (!p->cameras)
            return false;
        for (int i = 0; i < p->ncameras; i++) {
            json_t *c = json_array_get(cams, (size_t)i);
            char where[64];
            snprintf(where, sizeof where, "scene.cameras[%d]", i);
            const char *cn;
            if (!rt_pk_get_string(r, c, "name", where, &cn) ||
                !rt_pk_get_vec(r, c, "position", where, 3, p->cameras[i].position) ||
                !rt_pk_get_vec(r, c, "look", where, 3, p->cameras[i].look))
                return false;
            p->cameras[i].name = rt_pk_strdup(cn);
        }
    }
    return true;
}

bool rt_pk_read_scene(rt_pk_reader *r, json_t *root)
{
    rt_pack *p = r->p;
    json_t *scene = rt_pk_get(r, root, "scene", "manifest", true);
    if (!scene)
        return false;
    const char *name = "";
    json_t *nm = rt_pk_get(r, scene, "name", "scene", false);
    if (json_is_string(nm))
        name = json_string_value(nm);
    p->name = rt_pk_strdup(name);
    json_t *sp = rt_pk_get(r, scene, "source", "scene", false);
    if (json_is_string(sp))
        p->scene_path = rt_pk_strdup(json_string_value(sp));

    json_t *hf = rt_pk_get(r, scene, "heightfield", "scene", true);
    const char *file;
    if (!hf || !rt_pk_get_string(r, hf, "file", "scene.heightfield", &file) ||
        !rt_pk_get_int(r, hf, "width", "scene.heightfield", 1, SPLAT_MAX_HEIGHTFIELD,
                       &p->hf_width) ||
        !rt_pk_get_int(r, hf, "height", "scene.heightfield", 1, SPLAT_MAX_HEIGHTFIELD,
                       &p->hf_height))
        return false;
    double size[2];
    if (!rt_pk_get_vec(r, scene, "size", "scene", 2, size) ||
        !rt_pk_get_number(r, scene, "max_height", "scene", &p->max_height))
        return false;
    if (!(size[0] > 0 && size[1] > 0))
        return rt_pk_field_fail(r, "scene.size:", "must be positive");
    p->size[0] = size[0];
    p->size[1] = size[1];
    p->height_offset = 0;
    if (rt_pk_get(r, scene, "height_offset", "scene", false) &&
        !rt_pk_get_number(r, scene, "height_offset", "scene", &p->height_offset))
        return false;
    if (!rt_pk_get_int(r, scene, "cell_texels", "scene", 1, 4096, &p->cell_texels))
        return false;
    if (p->cell_texels & (p->cell_texels - 1))
        return rt_pk_field_fail(r, "scene.cell_texels:", "must be a power of two");
    int side = p->hf_width > p->hf_height ? p->hf_width : p->hf_height;
    int cells = (side + p->cell_texels - 1) / p->cell_texels;
    if (cells > SPLAT_MAX_CELLS) {
        char what[160];
        snprintf(what, sizeof what, "gives %d leaf cells per side, over the pack limit of %d",
                 cells, SPLAT_MAX_CELLS);
        return rt_pk_field_fail(r, "scene.cell_texels:", what);
    }
    if (!(p->size[0] <= SPLAT_MAX_EXTENT) || !(p->size[1] <= SPLAT_MAX_EXTENT) ||
        !(p->max_height >= 0 && p->max_height <= SPLAT_MAX_EXTENT) ||
        !(fabs(p->height_offset) <= SPLAT_MAX_EXTENT))
        return rt_pk_field_fail(r, "scene:", "size, max_height and height_offset must be finite "
                                "and at most 1e8 m (max_height >= 0)");

    if (!read_heights(r, hf, file))
        return false;

    return read_destruction(r, scene) && read_light(r, scene) && read_cameras(r, scene);
}

bool rt_pk_read_materials(rt_pk_reader *r, json_t *root)
{
    rt_pack *p = r->p;
    json_t *mats = rt_pk_get_array(r, root, "materials", "manifest", true);
    if (!mats)
        return false;
    p->nmaterials = (int)json_array_size(mats);
    if (p->nmaterials == 0)
        return rt_pk_field_fail(r, "materials:", "is empty");
    p->materials = calloc((size_t)p->nmaterials, sizeof *p->materials);
    if (!p->materials)
        return false;
    for (int i = 0; i < p->nmaterials; i++) {
        json_t *m = json_array_get(mats, (size_t)i);
        char where[64];
        snprintf(where, sizeof where, "materials[%d]", i);
        const char *name;
        if (!rt_pk_get_string(r, m, "name", where, &name))
            return false;
        p->materials[i].name = rt_pk_strdup(name);
        json_t *src = rt_pk_get(r, m, "source", where, false);
        if (json_is_string(src))
            p->materials[i].source = rt_pk_strdup(json_string_value(src));
        json_t *ref = rt_pk_get(r, m, "reference", where, false);
        if (ref && !json_is_null(ref)) {
            char w2[96];
            snprintf(w2, sizeof w2, "%s.reference", where);
            if (!rt_pk_read_spirv(r, ref, w2, RT_ROLE_REFERENCE, &p->materials[i].reference))
                return false;
        }
    }
    return true;
}

bool rt_pk_read_params(rt_pk_reader *r, json_t *root)
{
    rt_pack *p = r->p;
    int size = 16;
    if (rt_pk_get(r, root, "params_size", "manifest", false) &&
        !rt_pk_get_int(r, root, "params_size", "manifest", 0, 1 << 16, &size))
        return false;
    p->params_size = size < 16 ? 16 : (uint32_t)size;
    json_t *ps = rt_pk_get_array(r, root, "params", "manifest", false);
    if (!ps)
        return !r->e->msg;
    p->nparams = (int)json_array_size(ps);
    p->params = calloc((size_t)p->nparams + 1, sizeof *p->params);
    if (!p->params)
        return false;
    for (int i = 0; i < p->nparams; i++) {
        json_t *q = json_array_get(ps, (size_t)i);
        char where[64];
        snprintf(where, sizeof where, "params[%d]", i);
        const char *name;
        double def[4];
        int off;
        if (!rt_pk_get_string(r, q, "name", where, &name) ||
            !rt_pk_get_vec(r, q, "default", where, 4, def) ||
            !rt_pk_get_int(r, q, "offset", where, 0, (int)p->params_size - 16, &off))
            return false;
        if (off % 16)
            return rt_pk_field_fail(r, where, "offset must be a multiple of 16");
        p->params[i].name = rt_pk_strdup(name);
        p->params[i].offset = (uint32_t)off;
        /* optional: the type's width and the declared range */
        json_t *ty = json_object_get(q, "type");
        const char *tn = json_is_string(ty) ? json_string_value(ty) : "";
        p->params[i].width = !strcmp(tn, "float") ? 1 : !strcmp(tn, "vec2") ? 2
                           : !strcmp(tn, "vec3") ? 3 : 4;
        json_t *mn = json_object_get(q, "min"), *mx = json_object_get(q, "max");
        if (json_is_number(mn) && json_is_number(mx) &&
            json_number_value(mn) < json_number_value(mx)) {
            p->params[i].has_range = true;
            p->params[i].min = json_number_value(mn);
            p->params[i].max = json_number_value(mx);
        }
        for (int k = 0; k < 4; k++)
            p->params[i].value[k] = (float)def[k];
    }
    return true;
}

/* The periodic sites of terrain.position (PACK.md), optional. */
bool rt_pk_read_sites(rt_pk_reader *r, json_t *root)
{
    rt_pack *p = r->p;
    json_t *ss = rt_pk_get(r, root, "world_sites", "manifest", false);
    if (!ss)
        return true;
    if (!json_is_array(ss) || json_array_size(ss) > SPLAT_WORLD_SITES)
        return rt_pk_field_fail(r, "world_sites:", "must be an array of at most 16 sites");
    p->nsites = (int)json_array_size(ss);
    for (int i = 0; i < p->nsites; i++) {
        json_t *o = json_array_get(ss, (size_t)i);
        rt_pack_site *st = &p->sites[i];
        char where[64];
        snprintf(where, sizeof where, "world_sites[%d]", i);
        const char *axes, *op;
        if (!rt_pk_get_string(r, o, "axes", where, &axes) ||
            !rt_pk_get_string(r, o, "op", where, &op))
            return false;
        if (strlen(axes) != 2 || !strchr("xyz", axes[0]) || !strchr("xyz", axes[1]) ||
            (strcmp(op, "div") && strcmp(op, "mul")))
            return rt_pk_field_fail(r, where, "axes must be two of x y z, op div or mul");
        st->axes[0] = (int)(strchr("xyz", axes[0]) - "xyz");
        st->axes[1] = (int)(strchr("xyz", axes[1]) - "xyz");
        st->mul = op[0] == 'm';
        st->param = -1;
        if (rt_pk_get(r, o, "param", where, false)) {
            if (!rt_pk_get_int(r, o, "param", where, 0, p->nparams - 1, &st->param))
                return false;
        } else if (!rt_pk_get_vec(r, o, "scale", where, 2, st->scale)) {
            return false;
        }
    }
    return true;
}
