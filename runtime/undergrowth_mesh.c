/* undergrowth_mesh.c — the undergrowth's block table (what every pass
 * reads of a block: density, scale, colour, wind, flags, bounds) and the
 * single-triangle far meshes the runtime derives from a pack's tapered
 * quads; CPU only (undergrowth.c uploads both). */
#include "undergrowth_impl.h"

#include <math.h>
#include <string.h>

/* The radius of a mesh's footprint on the ground (m at scale 1): the
 * farthest vertex from its axis, for the contact shadow's quad. */
static double footprint(const rt_pack_ug *pu, int mesh)
{
    const rt_pack_ug_mesh *m = &pu->meshes[mesh];
    double r = 0;
    for (uint32_t v = 0; v < m->nv; v++) {
        const float *x = pu->vertices + 8 * (size_t)(m->first_vertex + v);
        double h = hypot(x[0], x[2]);
        r = h > r ? h : r;
    }
    return r;
}

/* The cull passes' bounding radius of a block at scale 1 (m): its mesh's
 * and its far mesh's farthest vertex from the root, or its contact
 * shadow's quad (1.3 footprints) if wider. */
static double bound(const rt_pack_ug *pu, int mesh)
{
    double r = 1.3 * footprint(pu, mesh);
    for (int k = 0; k < 2; k++) {
        int id = k == 0 ? mesh : pu->meshes[mesh].far;
        if (id < 0)
            continue;
        const rt_pack_ug_mesh *m = &pu->meshes[id];
        for (uint32_t v = 0; v < m->nv; v++) {
            const float *x = pu->vertices + 8 * (size_t)(m->first_vertex + v);
            double h = sqrt((double)x[0] * x[0] + (double)x[1] * x[1] + (double)x[2] * x[2]);
            r = h > r ? h : r;
        }
    }
    return r;
}

/* The single-triangle version of a far mesh made of tapered quads (each
 * pair of triangles has 4 distinct vertices, 2 at the root, v = 0, and 2
 * at the tip, v = 1): per quad one triangle from the root edge, widened
 * about its middle by (root + tip width) / root width so that it keeps
 * the quad's area, to the middle of the tip edge.  Writes 3 vertices (8
 * floats) and 3 indices (from 0) per quad; returns the triangles, 0 when
 * the mesh is not made of such quads (stone.far, an OBJ). */
uint32_t rt_ug_tri_mesh(const rt_pack_ug *pu, const rt_pack_ug_mesh *m, float *vout,
                        uint32_t *iout)
{
    if (m->nidx == 0 || m->nidx % 6 != 0)
        return 0;
    for (uint32_t q = 0; q < m->nidx / 6; q++) {
        const uint32_t *ix = pu->indices + m->first_index + 6 * q;
        const float *v[4];
        int n = 0;
        for (int k = 0; k < 6; k++) {
            const float *x = pu->vertices + 8 * (size_t)(m->first_vertex + ix[k]);
            bool seen = false;
            for (int j = 0; j < n; j++)
                seen |= v[j] == x;
            if (!seen && n == 4)
                return 0;
            if (!seen)
                v[n++] = x;
        }
        const float *root[2], *tip[2];
        int nr = 0, nt = 0;
        for (int j = 0; j < n; j++) {
            if (v[j][7] == 0.0f && nr < 2)
                root[nr++] = v[j];
            else if (v[j][7] == 1.0f && nt < 2)
                tip[nt++] = v[j];
        }
        if (n != 4 || nr != 2 || nt != 2)
            return 0;
        double wr = 0, wt = 0;
        for (int c = 0; c < 3; c++) {
            wr += ((double)root[1][c] - root[0][c]) * ((double)root[1][c] - root[0][c]);
            wt += ((double)tip[1][c] - tip[0][c]) * ((double)tip[1][c] - tip[0][c]);
        }
        double grow = wr > 0 ? (sqrt(wr) + sqrt(wt)) / sqrt(wr) : 1.0;
        float *o = vout + 24 * (size_t)q;
        for (int c = 0; c < 8; c++) {
            double mid = 0.5 * ((double)root[0][c] + root[1][c]);
            o[c] = (float)(c < 3 ? mid + (root[0][c] - mid) * grow : root[0][c]);
            o[8 + c] = (float)(c < 3 ? mid + (root[1][c] - mid) * grow : root[1][c]);
            o[16 + c] = (float)(0.5 * ((double)tip[0][c] + tip[1][c]));
        }
        o[6] = 0.0f;   /* u across the blade: 0, 1 at the root, 0.5 at the tip */
        o[14] = 1.0f;
        o[22] = 0.5f;
        for (int k = 0; k < 3; k++)
            iout[3 * q + (uint32_t)k] = 3 * q + (uint32_t)k;
    }
    return m->nidx / 6;
}

static uint32_t gcd(uint32_t a, uint32_t b)
{
    while (b) {
        uint32_t t = a % b;
        a = b;
        b = t;
    }
    return a;
}

/* The block table (set 0 binding 3 of the scatter pass, set 2 binding 0
 * of the draw and the probe): per block UG_BLOCK_VEC4 vec4s, (density,
 * scale lo, scale hi, blend), (colour, slot), (candidates per side, first
 * instance in the cell, flags, the stride of the candidates' lattice
 * order), (wind direction x, z, sway, gust), (root blend, shadow, the
 * mesh's footprint radius, the cull passes' bounding radius).
 * Flags: 1 cut out (frond), 2 lit with the terrain normal, 4 aligned to
 * the terrain normal, 8 cut out by the texture's alpha; bits 8 and up the
 * texture + 1 (0: none). */
void rt_ug_fill_blocks(rt_ug *u, float *b)
{
    const rt_pack_ug *pu = &u->p->ug;
    uint32_t at = 0;
    for (int i = 0; i < u->nblocks; i++) {
        const rt_pack_ug_block *k = &pu->blocks[i];
        /* enough candidates that keep = density * 256 / n^2 <= 1 */
        uint32_t nn = splat_ug_candidates(k->density), n = (uint32_t)lround(sqrt(nn));
        u->block_grid[i] = n;
        u->block_base[i] = at;
        at += nn;
        unsigned flags = (k->cutout == 1 ? 1u : 0u) | (k->light_terrain ? 2u : 0u) |
                         (k->align_normal ? 4u : 0u) | (k->cutout == 2 ? 8u : 0u) |
                         (unsigned)(k->texture + 1) << 8;
        uint32_t stride = (uint32_t)(0.618034 * n * n);
        while (stride > 1 && gcd(stride, n * n) != 1)
            stride++;
        float v[4 * UG_BLOCK_VEC4] = {
            (float)k->density, (float)k->scale[0], (float)k->scale[1], (float)k->blend,
            (float)k->color[0], (float)k->color[1], (float)k->color[2], (float)k->slot,
            (float)n, (float)u->block_base[i], (float)flags, (float)(stride ? stride : 1),
            (float)k->wind[0], (float)k->wind[1], (float)k->wind[2], (float)k->wind[3],
            (float)k->root_blend, (float)k->shadow, (float)footprint(pu, k->mesh),
            (float)bound(pu, k->mesh) };
        for (uint32_t t = 0; u->vbuf.map && t < u->tri[i][0]; t++) {   /* tri_mesh's */
            const float *x = (const float *)u->vbuf.map + 8 * (size_t)(u->tri[i][2] + t);
            float h = sqrtf(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
            v[4 * UG_BLOCK_VEC4 - 1] = h > v[4 * UG_BLOCK_VEC4 - 1] ? h : v[4 * UG_BLOCK_VEC4 - 1];
        }
        memcpy(b + 4 * UG_BLOCK_VEC4 * i, v, sizeof v);
    }
    u->cap = at;
}

/* Block b's mesh at level lv (0 near, 1 far, 2 the single triangle): its
 * index count, first index and vertex offset, as the draws and the
 * compute rasteriser's triangle table name it. */
void rt_ug_level_mesh(const rt_ug *u, int b, int lv, uint32_t out[3])
{
    const rt_pack_ug *pu = &u->p->ug;
    int far = pu->meshes[pu->blocks[b].mesh].far;
    if (lv == 2) {
        memcpy(out, u->tri[b], 3 * sizeof *out);
        return;
    }
    const rt_pack_ug_mesh *m = &pu->meshes[lv ? far : pu->blocks[b].mesh];
    out[0] = m->nidx;
    out[1] = m->first_index;
    out[2] = m->first_vertex;
}
