/* sparse.c — painted masks as sparse quad-tree textures (see sparse.h for
 * the layout): the build.  Reading the atlas is sparse_query.c, the file
 * sparse_file.c, rasters and slots sparse_raster.c.
 *
 * The build, per mask:
 *   1. reduced rasters D_L for L = 1..max_level (rounded block means);
 *   2. cells whose level-0 slot is all 0 or all 255 are constants;
 *   3. quad-tree levels, coarse to fine: an aligned block of 2^L x 2^L
 *      cells outside the `near` rect, with at least two non-constant cells,
 *      goes to level L if the exact max error of sampling D_L instead of
 *      the raster over its non-constant cells is within max_error (the
 *      error is exact because the difference of two bilinear interpolants
 *      is bilinear between the union of both grids' texel centres, which
 *      all lie on the half-texel lattice we evaluate);
 *   4. every non-constant cell's padded slot is hashed (XXH3) and stored
 *      once across all masks, in order of first use (deterministic);
 * then the atlas is laid out and encoded (R8 or BC4), and each cell's
 * bounds are taken from what the GPU and the CPU reference can read.
 *
 * Example: a 64 x 32 raster, all 0 but a soft disc in x 40..60:
 *   cells (0,0) -> index 0 (constant 0); cell (1,0) -> slot 0 (index 1);
 *   atlas 1 x 1 slots = 36 x 36 texels.
 */
#include "sparse_internal.h"
#include "ir.h"
#include "util.h"

#include <assert.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <xxhash.h>

#include <stb_image.h>
/* ---- the slot store: unique slots, deduplicated by XXH3 + bytes --------- */

typedef struct slot_store {
    uint8_t  *data;      /* n * SLOT_TEXELS bytes                         */
    uint64_t *hashes;
    int       n, cap;
    int32_t  *table;     /* open addressing, -1 = empty; tcap power of 2  */
    size_t    tcap;
} slot_store;

static void store_rehash(slot_store *st, size_t tcap)
{
    free(st->table);
    st->table = xcalloc(tcap, sizeof *st->table);
    memset(st->table, 0xff, tcap * sizeof *st->table);
    st->tcap = tcap;
    for (int k = 0; k < st->n; k++) {
        size_t i = st->hashes[k] & (tcap - 1);
        while (st->table[i] >= 0)
            i = (i + 1) & (tcap - 1);
        st->table[i] = k;
    }
}

/* The index of `slot` in the store, adding it if new (*added = true). */
static int store_intern(slot_store *st, const uint8_t *slot, bool *added)
{
    if ((size_t)(st->n + 1) * 2 > st->tcap)
        store_rehash(st, st->tcap ? st->tcap * 2 : 256);
    uint64_t h = XXH3_64bits(slot, SLOT_TEXELS);
    size_t i = h & (st->tcap - 1);
    for (; st->table[i] >= 0; i = (i + 1) & (st->tcap - 1)) {
        int k = st->table[i];
        if (st->hashes[k] == h &&
            memcmp(st->data + (size_t)k * SLOT_TEXELS, slot, SLOT_TEXELS) == 0) {
            *added = false;
            return k;
        }
    }
    if (st->n == st->cap) {
        st->cap = st->cap ? st->cap * 2 : 64;
        st->data = realloc(st->data, (size_t)st->cap * SLOT_TEXELS);
        st->hashes = realloc(st->hashes, (size_t)st->cap * sizeof *st->hashes);
        if (!st->data || !st->hashes)
            abort();
    }
    memcpy(st->data + (size_t)st->n * SLOT_TEXELS, slot, SLOT_TEXELS);
    st->hashes[st->n] = h;
    st->table[i] = st->n;
    *added = true;
    return st->n++;
}

static void store_free(slot_store *st)
{
    free(st->data);
    free(st->hashes);
    free(st->table);
}

/* ---- quad-tree levels --------------------------------------------------- */

/* Exact max |D_L - original| over the bilinear samples of cell (cx, cz). */
static double cell_reduce_error(const raster *orig, const raster *red,
                                int level, int cx, int cz)
{
    double s = ldexp(1.0, level), err = 0.0;
    int x1 = SPARSE_TILE * (cx + 1) < orig->w ? SPARSE_TILE * (cx + 1) : orig->w;
    int z1 = SPARSE_TILE * (cz + 1) < orig->h ? SPARSE_TILE * (cz + 1) : orig->h;
    for (int j = 2 * SPARSE_TILE * cz; j <= 2 * z1; j++)
        for (int i = 2 * SPARSE_TILE * cx; i <= 2 * x1; i++) {
            double x = 0.5 * i, z = 0.5 * j;
            double e = fabs(sparse_bilinear(red, x / s, z / s) - sparse_bilinear(orig, x, z));
            if (e > err)
                err = e;
        }
    return err;
}

static bool rects_overlap(int ax0, int az0, int ax1, int az1, const int b[4])
{
    return ax0 < b[2] && b[0] < ax1 && az0 < b[3] && b[1] < az1;
}

/* Fill lvl[] (cells_z x cells_x, -1 = constant at level 0) for one mask. */
static void choose_levels(const sparse_mask_desc *md, const raster *red,
                          int cells_x, int cells_z, int8_t *lvl,
                          sparse_mask_info *info)
{
    for (int L = md->max_level; L >= 1; L--) {
        int n = 1 << L, span = SPARSE_TILE << L;
        for (int bz = 0; bz * n < cells_z; bz++)
            for (int bx = 0; bx * n < cells_x; bx++) {
                if (md->near[2] > md->near[0] && md->near[3] > md->near[1] &&
                    rects_overlap(bx * span, bz * span, (bx + 1) * span,
                                  (bz + 1) * span, md->near))
                    continue;
                int cz1 = (bz + 1) * n < cells_z ? (bz + 1) * n : cells_z;
                int cx1 = (bx + 1) * n < cells_x ? (bx + 1) * n : cells_x;
                int live = 0;
                bool taken = false;
                for (int cz = bz * n; cz < cz1; cz++)
                    for (int cx = bx * n; cx < cx1; cx++) {
                        int8_t l = lvl[cz * cells_x + cx];
                        live += l >= 0;
                        taken |= l > 0;
                    }
                if (taken || live < 2)
                    continue;
                double err = 0.0;
                for (int cz = bz * n; cz < cz1 && err <= md->max_error; cz++)
                    for (int cx = bx * n; cx < cx1 && err <= md->max_error; cx++)
                        if (lvl[cz * cells_x + cx] >= 0) {
                            double e = cell_reduce_error(&red[0], &red[L], L, cx, cz);
                            err = e > err ? e : err;
                        }
                if (err > md->max_error)
                    continue;
                for (int cz = bz * n; cz < cz1; cz++)
                    for (int cx = bx * n; cx < cx1; cx++)
                        if (lvl[cz * cells_x + cx] >= 0)
                            lvl[cz * cells_x + cx] = (int8_t)L;
                if (err > info->reduce_error)
                    info->reduce_error = err;
            }
    }
}


/* ---- the build ---------------------------------------------------------- */

static void layout_atlas(sparse_masks *s, const slot_store *st)
{
    int cols = 1;
    while (cols * cols < st->n)
        cols++;
    s->nslots = st->n;
    s->atlas_cols = cols;
    s->atlas_rows = st->n > cols ? (st->n + cols - 1) / cols : 1;
    s->atlas_width = cols * SPARSE_SLOT;
    s->atlas_height = s->atlas_rows * SPARSE_SLOT;
    size_t w = (size_t)s->atlas_width, h = (size_t)s->atlas_height;
    uint8_t *r8 = xcalloc(w * h, 1);
    for (int k = 0; k < st->n; k++) {
        int ox, oz;
        sparse_slot_origin(s, k, &ox, &oz);
        for (int j = 0; j < SPARSE_SLOT; j++)
            memcpy(r8 + (size_t)(oz + j) * w + ox,
                   st->data + (size_t)k * SLOT_TEXELS + j * SPARSE_SLOT, SPARSE_SLOT);
    }
    if (s->format == SPARSE_R8) {
        s->atlas = r8;
        s->atlas_bytes = w * h;
        return;
    }
    s->atlas_bytes = w * h / 2;
    s->atlas = xcalloc(s->atlas_bytes, 1);
    for (size_t bz = 0; bz < h / 4; bz++)
        for (size_t bx = 0; bx < w / 4; bx++) {
            uint8_t in[16];
            for (int j = 0; j < 4; j++)
                memcpy(in + 4 * j, r8 + (bz * 4 + j) * w + bx * 4, 4);
            sparse_bc4_encode(s->atlas + (bz * (w / 4) + bx) * 8, in);
        }
    free(r8);
}

/* A desc's rect of all zeros means "the whole terrain". */
static bool rect_given(const double r[4])
{
    return r[0] != 0 || r[1] != 0 || r[2] != 0 || r[3] != 0;
}


static bool check_desc(const sparse_desc *d, sparse_error *err)
{
    if (d->width <= 0 || d->height <= 0 || d->nmasks < 0 ||
        (d->nmasks > 0 && !d->masks))
        return sparse_fail(err, SPARSE_E_BAD_OPTION, "(all)", "empty raster or no mask data");
    if (d->format != SPARSE_BC4 && d->format != SPARSE_R8)
        return sparse_fail(err, SPARSE_E_BAD_OPTION, "(all)", "unknown atlas format");
    for (int m = 0; m < d->nmasks; m++) {
        const sparse_mask_desc *md = &d->masks[m];
        const char *name = md->name ? md->name : "(unnamed)";
        if (!md->texels)
            return sparse_fail(err, SPARSE_E_BAD_OPTION, name, "no raster");
        if (md->max_level < 0 || md->max_level > SPARSE_MAX_LEVEL)
            return sparse_fail(err, SPARSE_E_BAD_OPTION, name,
                        "max_level must be 0..7 (the quad-tree's coarsest level)");
        if (!(md->max_error >= 0.0 && md->max_error <= 1.0))
            return sparse_fail(err, SPARSE_E_BAD_OPTION, name, "max_error must be in 0..1");
        if (md->width < 0 || md->height < 0 || (md->width > 0) != (md->height > 0) ||
            md->width > SPARSE_MAX_TEXELS || md->height > SPARSE_MAX_TEXELS)
            return sparse_fail(err, SPARSE_E_BAD_OPTION, name,
                        "a placed raster must be 1..65536 texels on each side");
        const double *r = md->rect;
        bool in_range = true;
        for (int i = 0; i < 4; i++)
            in_range &= isfinite(r[i]) && fabs(r[i]) < 1e6;
        if (rect_given(r) && !(in_range && r[2] - r[0] > 1e-9 && r[3] - r[1] > 1e-9))
            return sparse_fail(err, SPARSE_E_BAD_OPTION, name,
                        "its rectangle is empty or out of range (terrain uv within 1e6)");
    }
    return true;
}

/* Each mask's raster, rectangle and cells; the index grid the largest. */
static void set_places(sparse_masks *s, const sparse_desc *d)
{
    s->place = xcalloc((size_t)(d->nmasks ? d->nmasks : 1), sizeof *s->place);
    s->cells_x = d->nmasks ? 1 : (d->width + SPARSE_TILE - 1) / SPARSE_TILE;
    s->cells_z = d->nmasks ? 1 : (d->height + SPARSE_TILE - 1) / SPARSE_TILE;
    for (int m = 0; m < d->nmasks; m++) {
        const sparse_mask_desc *md = &d->masks[m];
        sparse_place *p = &s->place[m];
        p->width = md->width ? md->width : d->width;
        p->height = md->height ? md->height : d->height;
        static const double unit[4] = { 0, 0, 1, 1 };
        memcpy(p->rect, rect_given(md->rect) ? md->rect : unit, sizeof p->rect);
        sparse_place_cells(p, &s->cells_x, &s->cells_z);
    }
}

bool sparse_build(sparse_masks *s, const sparse_desc *d, sparse_error *err)
{
    memset(s, 0, sizeof *s);
    if (err)
        err->id = SPARSE_E_OK, err->msg[0] = 0;
    if (!check_desc(d, err))
        return false;
    s->width = d->width;
    s->height = d->height;
    s->nmasks = d->nmasks;
    s->format = d->format;
    set_places(s, d);
    s->layers = (d->nmasks + 3) / 4 > 0 ? (d->nmasks + 3) / 4 : 1;
    size_t ncell = (size_t)s->cells_x * s->cells_z;
    s->index = xcalloc(ncell * 4 * s->layers, sizeof *s->index);
    s->level = xcalloc(ncell * 4 * s->layers, 1);
    s->info = xcalloc((size_t)(d->nmasks ? d->nmasks : 1), sizeof *s->info);

    slot_store st = { 0 };
    uint8_t slot[SLOT_TEXELS];
    int8_t *lvl = xcalloc(ncell, 1);
    for (int m = 0; m < d->nmasks; m++) {
        const sparse_mask_desc *md = &d->masks[m];
        const sparse_place *pl = &s->place[m];
        int ncx = pl->cells_x, ncz = pl->cells_z;
        sparse_mask_info *info = &s->info[m];
        info->name = strdup(md->name ? md->name : "");
        info->max_level = md->max_level;
        raster red[SPARSE_MAX_LEVEL + 1];
        uint8_t *owned[SPARSE_MAX_LEVEL + 1] = { 0 };
        red[0] = (raster){ pl->width, pl->height, md->texels };
        for (int L = 1; L <= md->max_level; L++)
            owned[L] = sparse_reduce(&red[0], L, &red[L]);

        for (int cz = 0; cz < ncz; cz++)
            for (int cx = 0; cx < ncx; cx++) {
                sparse_make_slot(&red[0], cx, cz, slot);
                lvl[(size_t)cz * ncx + cx] = sparse_slot_constant(slot) >= 0 ? -1 : 0;
            }
        choose_levels(md, red, ncx, ncz, lvl, info);

        for (int cz = 0; cz < ncz; cz++)
            for (int cx = 0; cx < ncx; cx++) {
                int L = lvl[(size_t)cz * ncx + cx];
                L = L < 0 ? 0 : L;
                sparse_make_slot(&red[L], cx >> L, cz >> L, slot);
                size_t at = sparse_cell_at(s, m, cx, cz);
                int c = sparse_slot_constant(slot);
                s->level[at] = (uint8_t)L;
                if (c >= 0) {
                    s->index[at] = c ? SPARSE_CONST1 : SPARSE_CONST0;
                    s->level[at] = 0;
                    if (c) info->const1++; else info->const0++;
                    continue;
                }
                bool added;
                int k = store_intern(&st, slot, &added);
                if (k >= SPARSE_MAX_SLOTS) {
                    for (int L2 = 1; L2 <= md->max_level; L2++)
                        free(owned[L2]);
                    free(lvl);
                    store_free(&st);
                    sparse_free(s);
                    return sparse_fail(err, SPARSE_E_TOO_MANY_TILES, k + 1, (int)SPARSE_MAX_SLOTS);
                }
                s->index[at] = (uint16_t)(k + 1);
                info->stored++;
                info->reduced += L > 0;
                info->new_slots += added;
            }
        for (int L = 1; L <= md->max_level; L++)
            free(owned[L]);
    }
    free(lvl);
    layout_atlas(s, &st);
    store_free(&st);
    sparse_compute_bounds(s, d);
    return true;
}

void sparse_free(sparse_masks *s)
{
    if (s->info)
        for (int m = 0; m < s->nmasks; m++)
            free(s->info[m].name);
    free(s->info);
    free(s->index);
    free(s->level);
    free(s->atlas);
    free(s->lo);
    free(s->hi);
    free(s->place);
    memset(s, 0, sizeof *s);
}

/* ---- memory report ------------------------------------------------------ */

void sparse_get_stats(const sparse_masks *s, sparse_stats *st)
{
    memset(st, 0, sizeof *st);
    size_t ncell = (size_t)s->cells_x * s->cells_z;
    size_t aw = (size_t)s->atlas_width, ah = (size_t)s->atlas_height;
    st->nmasks = s->nmasks;
    st->cells = (int)ncell;
    st->nslots = s->nslots;
    for (int m = 0; m < s->nmasks; m++)
        st->dense_bytes += (size_t)s->place[m].width * s->place[m].height;
    st->index_bytes = ncell * 4 * s->layers * sizeof *s->index;
    st->level_bytes = ncell * 4 * s->layers;
    st->atlas_bytes = s->atlas_bytes;
    st->atlas_r8 = aw * ah;
    st->atlas_bc4 = aw * ah / 2;
    st->total_bytes = st->index_bytes + st->level_bytes + st->atlas_bytes;
    for (int m = 0; m < s->nmasks && s->info; m++) {
        st->const_cells += s->info[m].const0 + s->info[m].const1;
        st->stored_cells += s->info[m].stored;
        st->reduced_cells += s->info[m].reduced;
    }
    st->fraction = st->dense_bytes ? (double)st->total_bytes / st->dense_bytes : 0.0;
}

void sparse_print_stats(const sparse_masks *s, FILE *out)
{
    sparse_stats st;
    sparse_get_stats(s, &st);
    const char *fmt = s->format == SPARSE_BC4 ? "BC4" : "R8";
    fprintf(out, "painted masks: %d on %dx%d texels, %dx%d cells of %d, "
            "%s atlas %dx%d slots (%dx%d texels)\n",
            s->nmasks, s->width, s->height, s->cells_x, s->cells_z, SPARSE_TILE,
            fmt, s->atlas_cols, s->atlas_rows, s->atlas_width, s->atlas_height);
    fprintf(out, "  %-16s %5s %7s %7s %7s %7s %9s %10s\n", "mask", "level",
            "const0", "const1", "stored", "reduced", "new slots", "reduce err");
    for (int m = 0; m < s->nmasks && s->info; m++) {
        const sparse_mask_info *i = &s->info[m];
        fprintf(out, "  %-16s %5d %7d %7d %7d %7d %9d %10.5f\n", i->name,
                i->max_level, i->const0, i->const1, i->stored, i->reduced,
                i->new_slots, i->reduce_error);
        const sparse_place *p = &s->place[m];
        if (sparse_placed(s, m))
            fprintf(out, "  %-16s placed: %dx%d texels over terrain uv %.6g %.6g .. "
                    "%.6g %.6g\n", "", p->width, p->height, p->rect[0], p->rect[1],
                    p->rect[2], p->rect[3]);
    }
    fprintf(out, "  dense 8-bit        %12zu B\n", st.dense_bytes);
    fprintf(out, "  index (RGBA16UI)   %12zu B\n", st.index_bytes);
    fprintf(out, "  level (RGBA8UI)    %12zu B\n", st.level_bytes);
    fprintf(out, "  atlas (%-3s)        %12zu B   (R8 %zu B, BC4 %zu B)\n", fmt,
            st.atlas_bytes, st.atlas_r8, st.atlas_bc4);
    fprintf(out, "  sparse total       %12zu B = %.2f %% of dense (%d unique slots, "
            "%d of %d cells constant)\n", st.total_bytes, 100.0 * st.fraction,
            st.nslots, st.const_cells, st.cells * st.nmasks);
}
