/* sparse_file.c — the sparse masks' pack file (painted.sparse: header,
 * places, cell tables, the slot atlas; sparse.h has the format), written
 * and read back with every field checked, and a mask's raster read from
 * an image file. */
#include "sparse_internal.h"
#include "ir.h"
#include "util.h"

#include <assert.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <xxhash.h>

#include <stb_image.h>

/* ---- rasters from files --------------------------------------------------- */

bool sparse_load_raster(const char *path, int width, int height,
                        uint8_t **texels, sparse_error *err)
{
    *texels = NULL;
    int w, h, comp;
    char why[256];
    FILE *f = splat_input_fopen(path, SPLAT_MAX_IMAGE_BYTES, why, sizeof why);
    if (!f)
        return sparse_fail(err, SPARSE_E_IO, path, why);
    if (!stbi_info_from_file(f, &w, &h, &comp)) {
        fclose(f);
        return sparse_fail(err, SPARSE_E_IO, path, stbi_failure_reason());
    }
    bool is16 = stbi_is_16_bit_from_file(f);
    if (comp != 1) {
        fclose(f);
        return sparse_fail(err, SPARSE_E_BAD_CHANNELS, path, comp);
    }
    if (is16) {
        fclose(f);
        return sparse_fail(err, SPARSE_E_BAD_DEPTH, path);
    }
    if (w != width || h != height) {
        fclose(f);
        return sparse_fail(err, SPARSE_E_BAD_SIZE, path, w, h, width, height);
    }
    uint8_t *t = stbi_load_from_file(f, &w, &h, &comp, 1);
    fclose(f);
    if (!t) {
        /* the header read, the data did not */
        char why[160];
        snprintf(why, sizeof why, "truncated or corrupt PNG (stb_image: %s)",
                 stbi_failure_reason());
        return sparse_fail(err, SPARSE_E_IO, path, why);
    }
    /* copy into a malloc'd buffer the caller frees with free() */
    *texels = xcalloc((size_t)w * h, 1);
    memcpy(*texels, t, (size_t)w * h);
    stbi_image_free(t);
    return true;
}

/* ---- pack file ------------------------------------------------------------ */

static const char file_magic[8] = { 'S', 'P', 'L', 'A', 'T', 'S', 'P', 'M' };
enum { FILE_VERSION = 2, FILE_HEADER_WORDS = 11, PLACE_BYTES = 8 + 4 * 8 };

static void put_u32(uint8_t *p, uint32_t v)
{
    for (int i = 0; i < 4; i++)
        p[i] = (uint8_t)(v >> (8 * i));
}

static uint32_t get_u32(const uint8_t *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

static bool write_floats(const float *v, size_t n, FILE *f)
{
    uint8_t b[4];
    for (size_t i = 0; i < n; i++) {
        uint32_t u;
        memcpy(&u, &v[i], 4);
        put_u32(b, u);
        if (fwrite(b, 1, 4, f) != 4)
            return false;
    }
    return true;
}

bool sparse_write(const sparse_masks *s, FILE *f)
{
    uint8_t hdr[8 + 4 * FILE_HEADER_WORDS];
    uint32_t words[FILE_HEADER_WORDS] = {
        FILE_VERSION, (uint32_t)s->width, (uint32_t)s->height, (uint32_t)s->nmasks,
        (uint32_t)s->format, (uint32_t)s->cells_x, (uint32_t)s->cells_z,
        (uint32_t)s->layers, (uint32_t)s->nslots, (uint32_t)s->atlas_cols,
        (uint32_t)s->atlas_rows,
    };
    memcpy(hdr, file_magic, 8);
    for (int i = 0; i < FILE_HEADER_WORDS; i++)
        put_u32(hdr + 8 + 4 * i, words[i]);
    if (fwrite(hdr, 1, sizeof hdr, f) != sizeof hdr)
        return false;
    for (int m = 0; m < s->nmasks; m++) {
        uint8_t b[PLACE_BYTES];
        put_u32(b, (uint32_t)s->place[m].width);
        put_u32(b + 4, (uint32_t)s->place[m].height);
        for (int i = 0; i < 4; i++) {
            uint64_t u;
            memcpy(&u, &s->place[m].rect[i], 8);
            put_u32(b + 8 + 8 * i, (uint32_t)u);
            put_u32(b + 12 + 8 * i, (uint32_t)(u >> 32));
        }
        if (fwrite(b, 1, sizeof b, f) != sizeof b)
            return false;
    }
    size_t n = (size_t)s->cells_x * s->cells_z * 4 * s->layers;
    for (size_t i = 0; i < n; i++) {
        uint8_t b[2] = { (uint8_t)s->index[i], (uint8_t)(s->index[i] >> 8) };
        if (fwrite(b, 1, 2, f) != 2)
            return false;
    }
    size_t ncell = (size_t)s->cells_x * s->cells_z * s->nmasks;
    return fwrite(s->level, 1, n, f) == n &&
           fwrite(s->atlas, 1, s->atlas_bytes, f) == s->atlas_bytes &&
           write_floats(s->lo, ncell, f) && write_floats(s->hi, ncell, f);
}

/* The masks' places after the header: each raster 1..SPARSE_MAX_TEXELS
 * texels a side, its rectangle non-empty and finite, the index grid the
 * largest mask's cells (the heightfield's with no mask).  s->place is set
 * (and owned by s) when true. */
static bool read_places(sparse_masks *s, const uint8_t *at)
{
    int cx = s->nmasks ? 1 : (s->width + 31) / 32, cz = s->nmasks ? 1 : (s->height + 31) / 32;
    sparse_place *pl = calloc((size_t)(s->nmasks ? s->nmasks : 1), sizeof *pl);
    if (!pl)
        return false;
    for (int m = 0; m < s->nmasks; m++, at += PLACE_BYTES) {
        sparse_place *p = &pl[m];
        uint32_t w = get_u32(at), h = get_u32(at + 4);
        bool ok = w >= 1 && w <= SPARSE_MAX_TEXELS && h >= 1 && h <= SPARSE_MAX_TEXELS;
        for (int i = 0; i < 4; i++) {
            uint64_t u = (uint64_t)get_u32(at + 8 + 8 * i) |
                         (uint64_t)get_u32(at + 12 + 8 * i) << 32;
            memcpy(&p->rect[i], &u, 8);
            ok = ok && isfinite(p->rect[i]) && fabs(p->rect[i]) < 1e6;
        }
        if (!ok || !(p->rect[2] - p->rect[0] > 1e-9 && p->rect[3] - p->rect[1] > 1e-9)) {
            free(pl);
            return false;
        }
        p->width = (int)w;
        p->height = (int)h;
        sparse_place_cells(p, &cx, &cz);
    }
    if (cx != s->cells_x || cz != s->cells_z) {
        free(pl);
        return false;
    }
    s->place = pl;
    return true;
}

/* The header's words, checked, then the file's size against what they
 * describe, before anything is allocated: a forged header can neither
 * make the reader allocate more than the file holds nor read past it. */
bool sparse_read(sparse_masks *s, const uint8_t *data, size_t size, const char *name,
                 sparse_error *err)
{
    memset(s, 0, sizeof *s);
    enum { HDR = 8 + 4 * FILE_HEADER_WORDS };
    if (size < HDR || memcmp(data, file_magic, 8) != 0)
        return sparse_fail(err, SPARSE_E_BAD_FILE, name, "bad header");
    uint32_t w[FILE_HEADER_WORDS];
    for (int i = 0; i < FILE_HEADER_WORDS; i++)
        w[i] = get_u32(data + 8 + 4 * i);
    if (w[0] != FILE_VERSION)
        return sparse_fail(err, SPARSE_E_BAD_FILE, name, "unsupported version");
    /* every word bounded before any arithmetic on it */
    for (int i = 1; i < FILE_HEADER_WORDS; i++)
        if (w[i] > 65536)
            return sparse_fail(err, SPARSE_E_BAD_FILE, name, "inconsistent header (a field over 65536)");
    s->width = (int)w[1];
    s->height = (int)w[2];
    s->nmasks = (int)w[3];
    s->format = (sparse_format)w[4];
    s->cells_x = (int)w[5];
    s->cells_z = (int)w[6];
    s->layers = (int)w[7];
    s->nslots = (int)w[8];
    s->atlas_cols = (int)w[9];
    s->atlas_rows = (int)w[10];
    /* the header must describe a consistent, reasonably sized object */
    if (s->width <= 0 || s->height <= 0 || s->nmasks > 4096 ||
        size < HDR + (size_t)s->nmasks * PLACE_BYTES || !read_places(s, data + HDR) ||
        (s->format != SPARSE_R8 && s->format != SPARSE_BC4) ||
        s->layers != ((s->nmasks + 3) / 4 > 0 ? (s->nmasks + 3) / 4 : 1) ||
        s->nslots > SPARSE_MAX_SLOTS || s->atlas_cols <= 0 ||
        s->atlas_cols > 256 || s->atlas_rows <= 0 || s->atlas_rows > 256 ||
        s->atlas_cols * s->atlas_rows < s->nslots) {
        free(s->place);
        memset(s, 0, sizeof *s);
        return sparse_fail(err, SPARSE_E_BAD_FILE, name, "inconsistent header");
    }
    s->atlas_width = s->atlas_cols * SPARSE_SLOT;
    s->atlas_height = s->atlas_rows * SPARSE_SLOT;
    s->atlas_bytes = (size_t)s->atlas_width * s->atlas_height /
                     (s->format == SPARSE_BC4 ? 2 : 1);
    size_t n = (size_t)s->cells_x * s->cells_z * 4 * s->layers;
    size_t ncell = (size_t)s->cells_x * s->cells_z * s->nmasks;
    /* all sizes < 2^48 here (each factor <= 65536 or a small constant) */
    size_t want = HDR + (size_t)s->nmasks * PLACE_BYTES + n * 2 + n + s->atlas_bytes +
                  ncell * 8;
    if (size != want) {
        char what[160];
        snprintf(what, sizeof what, "%s: the header describes %zu bytes, the file has %zu",
                 size < want ? "truncated" : "trailing bytes", want, size);
        free(s->place);
        memset(s, 0, sizeof *s);
        return sparse_fail(err, SPARSE_E_BAD_FILE, name, what);
    }
    s->index = calloc(n ? n : 1, sizeof *s->index);
    s->level = calloc(n ? n : 1, 1);
    s->atlas = calloc(s->atlas_bytes ? s->atlas_bytes : 1, 1);
    s->lo = calloc(ncell ? ncell : 1, sizeof *s->lo);
    s->hi = calloc(ncell ? ncell : 1, sizeof *s->hi);
    if (!s->index || !s->level || !s->atlas || !s->lo || !s->hi) {
        sparse_free(s);
        return sparse_fail(err, SPARSE_E_BAD_FILE, name, "does not fit in memory");
    }
    const uint8_t *at = data + HDR + (size_t)s->nmasks * PLACE_BYTES;
    bool ok = true;
    for (size_t i = 0; i < n; i++, at += 2) {
        s->index[i] = (uint16_t)(at[0] | at[1] << 8);
        ok = ok && (s->index[i] == SPARSE_CONST1 || s->index[i] <= (unsigned)s->nslots);
    }
    memcpy(s->level, at, n);
    at += n;
    for (size_t i = 0; i < n; i++)
        ok = ok && s->level[i] <= SPARSE_MAX_LEVEL;
    memcpy(s->atlas, at, s->atlas_bytes);
    at += s->atlas_bytes;
    for (size_t i = 0; i < 2 * ncell; i++, at += 4) {
        uint32_t u = get_u32(at);
        memcpy(i < ncell ? &s->lo[i] : &s->hi[i - ncell], &u, 4);
    }
    if (!ok) {
        sparse_free(s);
        return sparse_fail(err, SPARSE_E_BAD_FILE, name, "index or level out of range");
    }
    return true;
}
