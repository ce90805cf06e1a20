/* pack_load.c — read a shader pack (compiler/PACK.md) and check it before the
 * GPU sees any of it: the manifest's fields and types, every file it names
 * (present, right size), every SPIR-V module (spirv-val), every
 * combination id in combos.bin (in range).  A bad pack is a message that
 * names the file and the field, never a crash or a validation error. */
#include "rt_internal.h"
#include "ir.h"
#include "far_atlas.h"
#include "zst.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <jansson.h>
#include <stb_image.h>

/* A module read but not validated yet: its words stay where the pack's
 * rt_spirv keeps them (that struct may move as arrays grow; they do not). */
struct unchecked {
    const uint32_t *words;
    size_t          nwords;
    char           *path;   /* pack-relative, owned */
};

typedef struct reader {
    const char *manifest;   /* path, for messages */
    rt_pack    *p;
    rt_error   *e;
    int         dirfd;      /* the pack folder: every file opened under it */
    struct unchecked *unchecked; /* modules read, validated at the end on
                               all cores (validate_all)                  */
    int         nunchecked, capunchecked;
} reader;

/* Files bigger than these are refused before they are read. */
#define MAX_MANIFEST ((size_t)64 << 20)
#define MAX_SPIRV    ((size_t)64 << 20)
#define MAX_IMAGE    ((size_t)1 << 30)
#define MAX_BINARY   ((size_t)1 << 31)

static char *xstrdup(const char *s)
{
    size_t n = strlen(s) + 1;
    char *d = malloc(n);
    if (d)
        memcpy(d, s, n);
    return d;
}

static char *join(const char *dir, const char *rel)
{
    size_t n = strlen(dir) + strlen(rel) + 2;
    char *s = malloc(n);
    if (s)
        snprintf(s, n, "%s/%s", dir, rel);
    return s;
}

/* ---- pack files: untrusted input ----------------------------------------
 * Every file of a pack is opened here, relative to the pack folder, one
 * path component at a time with O_NOFOLLOW: no absolute path, no "..", no
 * symbolic link anywhere on the way (a link out of the pack, or to
 * /dev/zero, is never followed), and only a regular file at the end (a
 * FIFO would block a reader forever, a device never ends).  The size comes
 * from fstat before a byte is read, and reads stop at that size. */

int rt_pack_open_file(int dirfd, const char *rel, char *why, size_t nwhy)
{
    if (!rel[0] || rel[0] == '/') {
        snprintf(why, nwhy, "is outside the pack (an absolute or empty path)");
        return -1;
    }
    size_t len = strlen(rel);
    char *path = malloc(len + 1);
    if (!path) {
        snprintf(why, nwhy, "cannot be opened (out of memory)");
        return -1;
    }
    memcpy(path, rel, len + 1);
    int cur = dirfd, fd = -1;
    char *save = NULL;
    for (char *c = strtok_r(path, "/", &save); c; c = strtok_r(NULL, "/", &save)) {
        bool last = save == NULL || *save == '\0';
        if (!strcmp(c, "..")) {
            snprintf(why, nwhy, "is outside the pack (\"..\")");
            break;
        }
        struct stat st;
        if (fstatat(cur, c, &st, AT_SYMLINK_NOFOLLOW) != 0) {
            snprintf(why, nwhy, "cannot be read (%s)", strerror(errno));
            break;
        }
        if (S_ISLNK(st.st_mode)) {
            snprintf(why, nwhy, "is%s a symbolic link (a pack holds only regular files)",
                     last ? "" : " inside");
            break;
        }
        if (!last && !S_ISDIR(st.st_mode)) {
            snprintf(why, nwhy, "cannot be read ('%s' is not a folder)", c);
            break;
        }
        if (last && !S_ISREG(st.st_mode)) {
            snprintf(why, nwhy, "is not a regular file (%s)",
                     S_ISFIFO(st.st_mode) ? "a FIFO" : S_ISDIR(st.st_mode) ? "a folder"
                     : S_ISCHR(st.st_mode) || S_ISBLK(st.st_mode) ? "a device" : "a socket");
            break;
        }
        int next = openat(cur, c, O_RDONLY | O_NOFOLLOW | O_CLOEXEC | O_NOCTTY |
                                      (last ? O_NONBLOCK : O_DIRECTORY));
        struct stat st2;
        if (next >= 0 && (fstat(next, &st2) != 0 || st2.st_dev != st.st_dev ||
                          st2.st_ino != st.st_ino)) {
            close(next);   /* replaced between the look and the open */
            next = -1;
            errno = ESTALE;
        }
        if (next < 0) {
            snprintf(why, nwhy, "cannot be read (%s)", strerror(errno));
            break;
        }
        if (cur != dirfd)
            close(cur);
        cur = next;
        if (last) {
            fd = cur;
            cur = dirfd;
        }
    }
    if (cur != dirfd)
        close(cur);
    free(path);
    if (fd >= 0)
        fcntl(fd, F_SETFL, 0);   /* a regular file: blocking reads again */
    return fd;
}

uint8_t *rt_pack_read_file(int dirfd, const char *rel, size_t max, size_t *n, char *why,
                           size_t nwhy)
{
    int fd = rt_pack_open_file(dirfd, rel, why, nwhy);
    if (fd < 0)
        return NULL;
    struct stat st;
    uint8_t *buf = NULL;
    if (fstat(fd, &st) != 0) {
        snprintf(why, nwhy, "cannot be read (%s)", strerror(errno));
    } else if ((uint64_t)st.st_size > max) {
        snprintf(why, nwhy, "has %llu bytes, more than the %zu it may have",
                 (unsigned long long)st.st_size, max);
    } else if (!(buf = malloc((size_t)st.st_size + 1))) {
        snprintf(why, nwhy, "does not fit in memory (%llu bytes)",
                 (unsigned long long)st.st_size);
    } else {
        size_t size = (size_t)st.st_size, got = 0;
        while (got < size) {
            ssize_t r = read(fd, buf + got, size - got);
            if (r < 0 && errno == EINTR)
                continue;
            if (r <= 0) {
                snprintf(why, nwhy, "cannot be read (%s)",
                         r < 0 ? strerror(errno) : "it shrank while being read");
                free(buf);
                buf = NULL;
                break;
            }
            got += (size_t)r;
        }
        if (buf) {
            buf[size] = 0;   /* text files end in a NUL */
            *n = size;
        }
    }
    close(fd);
    return buf;
}

uint8_t *rt_pack_read_content(int dirfd, const char *rel, size_t max, size_t *n, char *why,
                              size_t nwhy)
{
    if (!splat_zst_name(rel))
        return rt_pack_read_file(dirfd, rel, max, n, why, nwhy);
    /* the file within the largest frame of `max` bytes; the frame's stated
     * content size within `max` before its buffer is allocated (zst.h) */
    size_t zn = 0;
    uint8_t *z = rt_pack_read_file(dirfd, rel, splat_zst_bound(max), &zn, why, nwhy);
    if (!z)
        return NULL;
    uint8_t *d = splat_zst_decompress(z, zn, max, n, why, nwhy);
    free(z);
    return d;
}

/* ---- typed field access with messages naming the field ------------------ */

static bool field_fail(reader *r, const char *where, const char *what)
{
    char msg[512];
    snprintf(msg, sizeof msg, "%s %s", where, what);
    return rt_fail(r->e, RT_E_PACK_FIELD, r->manifest, msg);
}

static json_t *get(reader *r, json_t *obj, const char *key, const char *where,
                   bool required)
{
    json_t *v = json_is_object(obj) ? json_object_get(obj, key) : NULL;
    if (!v && required) {
        char w[256];
        snprintf(w, sizeof w, "%s: missing field", where);
        field_fail(r, w, key);
    }
    return v;
}

static bool get_number(reader *r, json_t *obj, const char *key, const char *where,
                       double *out)
{
    json_t *v = get(r, obj, key, where, true);
    if (!v)
        return false;
    if (!json_is_number(v)) {
        char w[256];
        snprintf(w, sizeof w, "%s.%s:", where, key);
        return field_fail(r, w, "must be a number");
    }
    *out = json_number_value(v);
    return true;
}

static bool get_int(reader *r, json_t *obj, const char *key, const char *where,
                    int lo, int hi, int *out)
{
    json_t *v = get(r, obj, key, where, true);
    if (!v)
        return false;
    if (!json_is_integer(v) || json_integer_value(v) < lo || json_integer_value(v) > hi) {
        char w[256], what[96];
        snprintf(w, sizeof w, "%s.%s:", where, key);
        snprintf(what, sizeof what, "must be an integer in [%d, %d]", lo, hi);
        return field_fail(r, w, what);
    }
    *out = (int)json_integer_value(v);
    return true;
}

static bool get_string(reader *r, json_t *obj, const char *key, const char *where,
                       const char **out)
{
    json_t *v = get(r, obj, key, where, true);
    if (!v)
        return false;
    if (!json_is_string(v)) {
        char w[256];
        snprintf(w, sizeof w, "%s.%s:", where, key);
        return field_fail(r, w, "must be a string");
    }
    *out = json_string_value(v);
    return true;
}

static json_t *get_array(reader *r, json_t *obj, const char *key, const char *where,
                         bool required)
{
    json_t *v = get(r, obj, key, where, required);
    if (v && !json_is_array(v)) {
        char w[256];
        snprintf(w, sizeof w, "%s.%s:", where, key);
        field_fail(r, w, "must be an array");
        return NULL;
    }
    return v;
}

static bool get_vec(reader *r, json_t *obj, const char *key, const char *where,
                    int n, double *out)
{
    json_t *a = get_array(r, obj, key, where, true);
    if (!a)
        return false;
    if ((int)json_array_size(a) != n) {
        char w[256], what[64];
        snprintf(w, sizeof w, "%s.%s:", where, key);
        snprintf(what, sizeof what, "must have %d numbers", n);
        return field_fail(r, w, what);
    }
    for (int i = 0; i < n; i++) {
        json_t *v = json_array_get(a, (size_t)i);
        if (!json_is_number(v)) {
            char w[256];
            snprintf(w, sizeof w, "%s.%s[%d]:", where, key, i);
            return field_fail(r, w, "must be a number");
        }
        out[i] = json_number_value(v);
    }
    return true;
}

/* A file of the pack (rt_pack_read_file): of exactly `want` bytes if want
 * > 0, else at most `max`. */
static uint8_t *pack_file(reader *r, const char *field, const char *rel,
                          size_t want, size_t max, size_t *got)
{
    char why[256];
    size_t n = 0;
    uint8_t *data = rt_pack_read_content(r->dirfd, rel, want ? want : max, &n, why, sizeof why);
    if (!data) {
        rt_fail(r->e, RT_E_PACK_FILE, r->manifest, field, rel, why);
        return NULL;
    }
    if (want && n != want) {
        snprintf(why, sizeof why, "has %zu bytes, expected %zu", n, want);
        rt_fail(r->e, RT_E_PACK_FILE, r->manifest, field, rel, why);
        free(data);
        return NULL;
    }
    if (got)
        *got = n;
    return data;
}

/* {"glsl": …, "spirv": …} → a validated SPIR-V module. */
static bool read_spirv(reader *r, json_t *obj, const char *where, rt_spirv *out)
{
    const char *rel;
    if (!get_string(r, obj, "spirv", where, &rel))
        return false;
    char field[256];
    snprintf(field, sizeof field, "%s.spirv", where);
    size_t n = 0;
    uint8_t *data = pack_file(r, field, rel, 0, MAX_SPIRV, &n);
    if (!data)
        return false;
    out->path = xstrdup(rel);
    if (n % 4) {
        free(data);
        char path[512];
        snprintf(path, sizeof path, "%s/%s", r->p->dir, rel);
        return rt_fail(r->e, RT_E_PACK_SPIRV, path, "size is not a multiple of 4 bytes");
    }
    out->words = (uint32_t *)data;
    out->nwords = n / 4;
    if (r->nunchecked == r->capunchecked) {
        int cap = r->capunchecked ? 2 * r->capunchecked : 64;
        struct unchecked *u = realloc(r->unchecked, (size_t)cap * sizeof *u);
        if (!u)
            return false;
        r->unchecked = u;
        r->capunchecked = cap;
    }
    r->unchecked[r->nunchecked++] = (struct unchecked){ out->words, out->nwords, xstrdup(rel) };
    return true;
}

/* One job of validate_all: spirv-val on module k, its failure in errs[k]. */
typedef struct validate_jobs {
    reader    *r;
    rt_error  *errs;
} validate_jobs;

static bool validate_one(void *ctx, int k, rt_error *e)
{
    validate_jobs *j = ctx;
    const struct unchecked *s = &j->r->unchecked[k];
    char path[512];
    snprintf(path, sizeof path, "%s/%s", j->r->p->dir, s->path);
    (void)e;   /* every module is validated: the first failure by index is reported */
    rt_spirv_validate(s->words, s->nwords, path, &j->errs[k]);
    return true;
}

/* Every module read, validated before any reaches the driver: spirv-val
 * on all cores (jobs.c), the failure reported that of the first module in
 * manifest order, so the message does not depend on the threads. */
static bool validate_all(reader *r)
{
    rt_error *errs = calloc((size_t)r->nunchecked + 1, sizeof *errs);
    if (!errs)
        return false;
    validate_jobs j = { r, errs };
    bool ok = rt_parallel(r->nunchecked, validate_one, &j, r->e);
    for (int k = 0; k < r->nunchecked; k++) {
        if (ok && errs[k].id != RT_OK) {
            *r->e = errs[k];
            ok = false;
        } else {
            rt_error_clear(&errs[k]);
        }
    }
    free(errs);
    return ok;
}

/* {"compute": {"glsl": …}} of a combination or the über-shader: the
 * compute variant's GLSL text (PACK.md), NUL-terminated; optional (a pack
 * without it cannot be drawn by the screen-space path). */
static bool read_glsl_at(reader *r, json_t *c, const char *w, char **out);

static bool read_glsl(reader *r, json_t *obj, const char *key, const char *where, char **out)
{
    json_t *c = get(r, obj, key, where, false);
    if (!c || json_is_null(c))
        return true;
    char w[96];
    snprintf(w, sizeof w, "%s.%s", where, key);
    return read_glsl_at(r, c, w, out);
}

/* read_glsl, and the variant's SPIR-V where the build made it
 * ({"glsl": …, "spirv": …}; `spv` words NULL without): validated with
 * every module of the pack, so the runtime compiles nothing for it. */
static bool read_compute(reader *r, json_t *obj, const char *key, const char *where,
                         char **out, rt_spirv *spv)
{
    if (!read_glsl(r, obj, key, where, out))
        return false;
    json_t *c = json_object_get(obj, key);
    if (!json_is_object(c) || !json_object_get(c, "spirv"))
        return true;
    char w[96];
    snprintf(w, sizeof w, "%s.%s", where, key);
    return read_spirv(r, c, w, spv);
}

/* c["glsl"], the fragment GLSL beside c["spirv"]: optional, and only its
 * path is kept (the forward path's counting variant reads it on first use:
 * rt_pack_read_glsl). */
static bool read_fragment_glsl(reader *r, json_t *c, const char *where, char **path)
{
    const char *rel;
    if (!get(r, c, "glsl", where, false))
        return true;
    if (!get_string(r, c, "glsl", where, &rel))
        return false;
    *path = xstrdup(rel);
    return true;
}

/* The file's bytes as GLSL text: NUL-terminated, no NUL inside; NULL with
 * `why` set if not.  Takes `data` (n bytes, one spare byte allocated). */
static char *glsl_text(uint8_t *data, size_t n, char *why, size_t nwhy)
{
    char *text = (char *)data;
    text[n] = '\0';
    if (strlen(text) != n) {
        snprintf(why, nwhy, "holds a NUL byte: not GLSL text");
        free(text);
        return NULL;
    }
    return text;
}

/* The text of c["glsl"] (`w` names c in errors). */
static bool read_glsl_at(reader *r, json_t *c, const char *w, char **out)
{
    const char *rel;
    if (!get_string(r, c, "glsl", w, &rel))
        return false;
    char field[128], why[96];
    snprintf(field, sizeof field, "%s.glsl", w);
    size_t n = 0;
    uint8_t *data = pack_file(r, field, rel, 0, MAX_SPIRV, &n);
    if (!data)
        return false;
    if (!(*out = glsl_text(data, n, why, sizeof why)))
        return field_fail(r, field, why);
    return true;
}

char *rt_pack_read_glsl(const rt_pack *p, const char *field, const char *rel, rt_error *e)
{
    char why[256];
    size_t n = 0;
    uint8_t *data = NULL;
    int dirfd = open(p->dir, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (dirfd < 0) {
        snprintf(why, sizeof why, "cannot open the pack folder (%s)", strerror(errno));
    } else {
        data = rt_pack_read_content(dirfd, rel, MAX_SPIRV, &n, why, sizeof why);
        close(dirfd);
    }
    char *text = data ? glsl_text(data, n, why, sizeof why) : NULL;
    if (!text) {
        char manifest[512];
        snprintf(manifest, sizeof manifest, "%s/manifest.json", p->dir);
        rt_fail(e, RT_E_PACK_FILE, manifest, field, rel, why);
    }
    return text;
}

/* ---- sections ------------------------------------------------------------ */

static uint32_t le32(const uint8_t *b)
{
    return (uint32_t)b[0] | (uint32_t)b[1] << 8 | (uint32_t)b[2] << 16 | (uint32_t)b[3] << 24;
}

/* meshes.bin (PACK.md): its header against the manifest's meshes, then
 * every vertex finite and every index inside its mesh. */
static bool read_meshes(reader *r, const char *rel, rt_pack_ug *u)
{
    size_t n = 0;
    uint8_t *data = pack_file(r, "undergrowth.file", rel, 0, MAX_BINARY, &n);
    if (!data)
        return false;
    size_t head = 16 + 8 * (size_t)u->nmeshes;
    size_t want = head + 32 * (size_t)u->nvertices + 4 * (size_t)u->nindices;
    const char *bad = NULL;
    if (n != want || memcmp(data, "SPLATMSH", 8) || le32(data + 8) != 1 ||
        le32(data + 12) != (uint32_t)u->nmeshes)
        bad = "does not match the manifest's meshes (size, magic, version or count)";
    for (int i = 0; !bad && i < u->nmeshes; i++)
        if (le32(data + 16 + 8 * i) != u->meshes[i].nv ||
            le32(data + 20 + 8 * i) != u->meshes[i].nidx)
            bad = "has mesh sizes other than the manifest's";
    u->vertices = bad ? NULL : malloc(32 * (size_t)u->nvertices + 1);
    u->indices = bad ? NULL : malloc(4 * (size_t)u->nindices + 1);
    if (!bad && (!u->vertices || !u->indices))
        bad = "does not fit in memory";
    const uint8_t *at = data + head;
    for (int i = 0; !bad && i < u->nmeshes; i++) {
        const rt_pack_ug_mesh *m = &u->meshes[i];
        for (uint32_t k = 0; k < 8 * m->nv; k++, at += 4) {
            uint32_t w = le32(at);
            float f;
            memcpy(&f, &w, 4);
            if (!isfinite(f) || fabsf(f) > (float)SPLAT_MAX_MESH_VALUE)
                bad = "holds a vertex value that is not finite or over 1000";
            u->vertices[8 * (size_t)m->first_vertex + k] = f;
        }
        for (uint32_t k = 0; k < m->nidx; k++, at += 4) {
            uint32_t x = le32(at);
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
static bool read_ug_texture_sizes(reader *r, json_t *o, rt_pack_ug *u)
{
    json_t *ts = json_object_get(o, "textures");
    if (!ts)
        return true;
    if (!json_is_array(ts) || json_array_size(ts) < 1 ||
        json_array_size(ts) > SPLAT_MAX_UG_TEXTURES)
        return field_fail(r, "undergrowth.textures:", "must be an array of 1 to 8 entries");
    u->ntextures = (int)json_array_size(ts);
    u->textures = calloc((size_t)u->ntextures, sizeof *u->textures);
    if (!u->textures)
        return false;
    for (int i = 0; i < u->ntextures; i++) {
        char where[64];
        snprintf(where, sizeof where, "undergrowth.textures[%d]", i);
        json_t *t = json_array_get(ts, (size_t)i);
        if (!get_int(r, t, "width", where, 1, SPLAT_MAX_UG_TEXTURE, &u->textures[i].width) ||
            !get_int(r, t, "height", where, 1, SPLAT_MAX_UG_TEXTURE, &u->textures[i].height))
            return false;
    }
    return true;
}

/* ugtex.bin (PACK.md "Undergrowth"): its size from the manifest's sizes,
 * checked before it is read, and its header against them. */
static bool read_ug_textures(reader *r, json_t *o, rt_pack_ug *u)
{
    if (u->ntextures == 0)
        return true;
    const char *rel;
    if (!get_string(r, o, "texture_file", "undergrowth", &rel))
        return false;
    size_t head = 16 + 8 * (size_t)u->ntextures, want = head;
    for (int i = 0; i < u->ntextures; i++)
        want += 4 * (size_t)u->textures[i].width * (size_t)u->textures[i].height;
    uint8_t *data = pack_file(r, "undergrowth.texture_file", rel, want, 0, NULL);
    if (!data)
        return false;
    const char *bad = NULL;
    if (memcmp(data, "SPLATUGT", 8) || le32(data + 8) != 1 ||
        le32(data + 12) != (uint32_t)u->ntextures)
        bad = "does not match the manifest's textures (magic, version or count)";
    for (int i = 0; !bad && i < u->ntextures; i++)
        if (le32(data + 16 + 8 * i) != (uint32_t)u->textures[i].width ||
            le32(data + 20 + 8 * i) != (uint32_t)u->textures[i].height)
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
static bool read_far(reader *r, json_t *root)
{
    json_t *o = get(r, root, "far_atlas", "manifest", false);
    if (!o || json_is_null(o))
        return true;
    rt_pack_far *f = &r->p->far;
    const char *file;
    if (!get_int(r, o, "width", "far_atlas", 1, FAR_ATLAS_MAX_SIDE, &f->width) ||
        !get_int(r, o, "height", "far_atlas", 1, FAR_ATLAS_MAX_SIDE, &f->height) ||
        !get_int(r, o, "levels", "far_atlas", 1,
                 far_atlas_levels_max((uint32_t)f->width, (uint32_t)f->height), &f->levels) ||
        !get_string(r, o, "file", "far_atlas", &file))
        return false;
    size_t want = (size_t)far_atlas_file_bytes((uint32_t)f->width, (uint32_t)f->height,
                                               f->levels);
    size_t n = 0;
    uint8_t *data = pack_file(r, "far_atlas.file", file, want, want, &n);
    if (!data)
        return false;
    double tx, tz;
    uint64_t bx, bz;
    memcpy(&bx, data + 24, 8);   /* little-endian hosts only, as le32 */
    memcpy(&bz, data + 32, 8);
    memcpy(&tx, &bx, 8);
    memcpy(&tz, &bz, 8);
    if (memcmp(data, FAR_ATLAS_MAGIC, 8) || le32(data + 8) != FAR_ATLAS_VERSION ||
        le32(data + 12) != (uint32_t)f->width || le32(data + 16) != (uint32_t)f->height ||
        le32(data + 20) != (uint32_t)f->levels || !isfinite(tx) || !isfinite(tz) ||
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
static bool read_vectors(reader *r, json_t *root)
{
    json_t *o = get(r, root, "vectors", "manifest", false);
    if (!o || json_is_null(o))
        return true;
    const char *file;
    int words;
    /* the buffer within Vulkan's minimum maxStorageBufferRange (2^27 B) */
    if (!get_int(r, o, "words", "vectors", SPLAT_VEC_HEADER, SPLAT_MAX_VECTOR_WORDS, &words) ||
        !get_string(r, o, "file", "vectors", &file))
        return false;
    json_t *names = get_array(r, o, "shapes", "vectors", true);
    if (!names)
        return false;
    size_t ns = json_array_size(names);
    if (ns < 1 || ns > SPLAT_MAX_VECTORS)
        return field_fail(r, "vectors.shapes:", "must have 1 to 32 entries");
    for (size_t i = 0; i < ns; i++)
        if (!json_is_string(json_array_get(names, i)))
            return field_fail(r, "vectors.shapes:", "must be names (strings)");
    size_t want = 16 + 4 * (size_t)words, n = 0;
    uint8_t *data = pack_file(r, "vectors.file", file, want, want, &n);
    if (!data)
        return false;
    if (memcmp(data, "SPLATVEC", 8) || le32(data + 8) != 1 || le32(data + 12) != (uint32_t)words) {
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
        w[i] = le32(data + 16 + 4 * (size_t)i);
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

/* "undergrowth" (optional): slots, meshes, blocks, meshes.bin. */
static bool read_undergrowth(reader *r, json_t *root)
{
    json_t *o = get(r, root, "undergrowth", "manifest", false);
    if (!o || json_is_null(o))
        return true;
    rt_pack_ug *u = &r->p->ug;
    int texels;
    const char *file;
    if (!get_int(r, o, "slots", "undergrowth", 1, SPLAT_UG_SLOTS, &u->nslots) ||
        !get_int(r, o, "texels", "undergrowth", SPLAT_UG_TEXELS, SPLAT_UG_TEXELS, &texels) ||
        !get_string(r, o, "file", "undergrowth", &file))
        return false;
    json_t *ms = get_array(r, o, "meshes", "undergrowth", true);
    json_t *bs = ms ? get_array(r, o, "blocks", "undergrowth", true) : NULL;
    if (!bs)
        return false;
    if (json_array_size(ms) < 1 || json_array_size(ms) > 64)
        return field_fail(r, "undergrowth.meshes:", "must have 1 to 64 entries");
    if (json_array_size(bs) < 1 || json_array_size(bs) > SPLAT_MAX_UG_BLOCKS)
        return field_fail(r, "undergrowth.blocks:", "must have 1 to 64 entries");
    if (!read_ug_texture_sizes(r, o, u))
        return false;
    u->nmeshes = (int)json_array_size(ms);
    u->nblocks = (int)json_array_size(bs);
    u->meshes = calloc((size_t)u->nmeshes, sizeof *u->meshes);
    u->blocks = calloc((size_t)u->nblocks, sizeof *u->blocks);
    if (!u->meshes || !u->blocks)
        return false;
    for (int i = 0; i < u->nmeshes; i++) {
        char where[64];
        snprintf(where, sizeof where, "undergrowth.meshes[%d]", i);
        json_t *m = json_array_get(ms, (size_t)i);
        int nv, ni;
        const char *name;
        if (!get_int(r, m, "vertices", where, 1, SPLAT_MAX_MESH_VERTICES, &nv) ||
            !get_int(r, m, "indices", where, 3, SPLAT_MAX_MESH_INDICES, &ni) ||
            !get_string(r, m, "name", where, &name))
            return false;
        if (ni % 3)
            return field_fail(r, where, "indices: must be a multiple of 3");
        int far = -1;
        if (json_object_get(m, "far") &&
            !get_int(r, m, "far", where, 0, (int)json_array_size(ms) - 1, &far))
            return false;
        u->meshes[i] = (rt_pack_ug_mesh){ (uint32_t)nv, (uint32_t)ni, u->nvertices, u->nindices,
                                          far };
        u->nvertices += (uint32_t)nv;
        u->nindices += (uint32_t)ni;
    }
    for (int i = 0; i < u->nmeshes; i++) {   /* a far version is a plain mesh */
        rt_pack_ug_mesh *m = &u->meshes[i];
        if (m->far >= 0 && (m->far == i || u->meshes[m->far].far >= 0))
            return field_fail(r, "undergrowth.meshes:",
                              "far: must name another mesh that has no far version");
    }
    for (int i = 0; i < u->nblocks; i++) {
        char where[64];
        snprintf(where, sizeof where, "undergrowth.blocks[%d]", i);
        json_t *b = json_array_get(bs, (size_t)i);
        rt_pack_ug_block *k = &u->blocks[i];
        const char *align, *lighting, *cutout;
        if (!get_int(r, b, "material", where, 0, r->p->nmaterials - 1, &k->material) ||
            !get_int(r, b, "slot", where, 0, u->nslots - 1, &k->slot) ||
            !get_int(r, b, "mesh", where, 0, u->nmeshes - 1, &k->mesh) ||
            !get_number(r, b, "density", where, &k->density) ||
            !get_vec(r, b, "scale", where, 2, k->scale) ||
            !get_number(r, b, "blend", where, &k->blend) ||
            !get_vec(r, b, "color", where, 3, k->color) ||
            !get_string(r, b, "align", where, &align) ||
            !get_number(r, b, "root_blend", where, &k->root_blend) ||
            !get_string(r, b, "lighting", where, &lighting) ||
            !get_string(r, b, "cutout", where, &cutout) ||
            !get_vec(r, b, "wind", where, 4, k->wind) ||
            !get_number(r, b, "shadow", where, &k->shadow) ||
            !get_int(r, b, "texture", where, -1, u->ntextures - 1, &k->texture))
            return false;
        if (!(k->root_blend >= 0 && k->root_blend <= 1))
            return field_fail(r, where, "root_blend: must be in [0, 1]");
        if (!(k->shadow >= 0 && k->shadow <= 1))
            return field_fail(r, where, "shadow: must be in [0, 1]");
        if (!(fabs(hypot(k->wind[0], k->wind[1]) - 1) <= 1e-3))
            return field_fail(r, where, "wind: its direction (x, z) must be a unit vector");
        if (!(k->wind[2] >= 0 && k->wind[2] <= SPLAT_MAX_UG_WIND))
            return field_fail(r, where, "wind: the sway must be in [0, 2]");
        if (!(k->wind[3] >= 0 && k->wind[3] <= 1))
            return field_fail(r, where, "wind: the gust must be in [0, 1]");
        if (strcmp(lighting, "terrain") && strcmp(lighting, "mesh"))
            return field_fail(r, where, "lighting: must be \"terrain\" or \"mesh\"");
        if (strcmp(cutout, "frond") && strcmp(cutout, "none") && strcmp(cutout, "alpha"))
            return field_fail(r, where, "cutout: must be \"none\", \"frond\" or \"alpha\"");
        k->light_terrain = strcmp(lighting, "terrain") == 0;
        k->cutout = strcmp(cutout, "frond") == 0 ? 1 : strcmp(cutout, "alpha") == 0 ? 2 : 0;
        if (k->cutout == 2 && k->texture < 0)
            return field_fail(r, where, "cutout: \"alpha\" needs a texture");
        if (!(k->density > 0 && k->density <= SPLAT_MAX_UG_DENSITY))
            return field_fail(r, where, "density: must be in (0, 64]");
        if (!(k->scale[0] > 0 && k->scale[0] <= k->scale[1] && k->scale[1] <= 100))
            return field_fail(r, where, "scale: must be 0 < lo <= hi <= 100");
        if (!(k->blend >= 0 && k->blend <= 1))
            return field_fail(r, where, "blend: must be in [0, 1]");
        for (int c = 0; c < 3; c++)
            if (!(k->color[c] >= 0 && k->color[c] <= 1))
                return field_fail(r, where, "color: must be in [0, 1]");
        if (strcmp(align, "normal") && strcmp(align, "upright"))
            return field_fail(r, where, "align: must be \"normal\" or \"upright\"");
        k->align_normal = strcmp(align, "normal") == 0;
    }
    return read_meshes(r, file, u) && read_ug_textures(r, o, u);
}

/* scene.light (optional, and each of its fields): over the defaults. */
static bool read_light(reader *r, json_t *scene)
{
    rt_light *l = &r->p->light;
    rt_light_default(l);
    json_t *o = get(r, scene, "light", "scene", false);
    if (!o)
        return true;
    if (!json_is_object(o))
        return field_fail(r, "scene.light:", "must be an object");
    for (int k = 0; k < SPLAT_LIGHT_COUNT; k++) {
        const splat_light_key *lk = &splat_light_keys[k];
        double *v = rt_light_values(l, k);
        if (json_object_get(o, lk->key) &&
            !(lk->n == 1 ? get_number(r, o, lk->key, "scene.light", v)
                         : get_vec(r, o, lk->key, "scene.light", lk->n, v)))
            return false;
    }
    const char *bad = rt_light_check(l);
    return bad ? field_fail(r, "scene.light:", bad) : true;
}

static bool read_scene(reader *r, json_t *root)
{
    rt_pack *p = r->p;
    json_t *scene = get(r, root, "scene", "manifest", true);
    if (!scene)
        return false;
    const char *name = "";
    json_t *nm = get(r, scene, "name", "scene", false);
    if (json_is_string(nm))
        name = json_string_value(nm);
    p->name = xstrdup(name);
    json_t *sp = get(r, scene, "source", "scene", false);
    if (json_is_string(sp))
        p->scene_path = xstrdup(json_string_value(sp));

    json_t *hf = get(r, scene, "heightfield", "scene", true);
    const char *file;
    if (!hf || !get_string(r, hf, "file", "scene.heightfield", &file) ||
        !get_int(r, hf, "width", "scene.heightfield", 1, SPLAT_MAX_HEIGHTFIELD, &p->hf_width) ||
        !get_int(r, hf, "height", "scene.heightfield", 1, SPLAT_MAX_HEIGHTFIELD, &p->hf_height))
        return false;
    double size[2];
    if (!get_vec(r, scene, "size", "scene", 2, size) ||
        !get_number(r, scene, "max_height", "scene", &p->max_height))
        return false;
    if (!(size[0] > 0 && size[1] > 0))
        return field_fail(r, "scene.size:", "must be positive");
    p->size[0] = size[0];
    p->size[1] = size[1];
    p->height_offset = 0;
    if (get(r, scene, "height_offset", "scene", false) &&
        !get_number(r, scene, "height_offset", "scene", &p->height_offset))
        return false;
    if (!get_int(r, scene, "cell_texels", "scene", 1, 4096, &p->cell_texels))
        return false;
    if (p->cell_texels & (p->cell_texels - 1))
        return field_fail(r, "scene.cell_texels:", "must be a power of two");
    int side = p->hf_width > p->hf_height ? p->hf_width : p->hf_height;
    int cells = (side + p->cell_texels - 1) / p->cell_texels;
    if (cells > SPLAT_MAX_CELLS) {
        char what[160];
        snprintf(what, sizeof what, "gives %d leaf cells per side, over the pack limit of %d",
                 cells, SPLAT_MAX_CELLS);
        return field_fail(r, "scene.cell_texels:", what);
    }
    if (!(p->size[0] <= SPLAT_MAX_EXTENT) || !(p->size[1] <= SPLAT_MAX_EXTENT) ||
        !(p->max_height >= 0 && p->max_height <= SPLAT_MAX_EXTENT) ||
        !(fabs(p->height_offset) <= SPLAT_MAX_EXTENT))
        return field_fail(r, "scene:", "size, max_height and height_offset must be finite "
                          "and at most 1e8 m (max_height >= 0)");

    size_t texels = (size_t)p->hf_width * (size_t)p->hf_height;
    uint8_t *raw = pack_file(r, "scene.heightfield.file", file, texels * 2, 0, NULL);
    if (!raw)
        return false;
    p->heights = malloc(texels * sizeof *p->heights);
    if (!p->heights) {
        free(raw);
        return field_fail(r, "heightfield:", "out of memory");
    }
    for (size_t i = 0; i < texels; i++)
        p->heights[i] = (uint16_t)(raw[2 * i] | raw[2 * i + 1] << 8);
    free(raw);
    /* the terrain's holes (PACK.md), optional: W*H bytes, 0 or 255 */
    if (get(r, hf, "holes", "scene.heightfield", false)) {
        const char *hfile;
        if (!get_string(r, hf, "holes", "scene.heightfield", &hfile))
            return false;
        p->holes = pack_file(r, "scene.heightfield.holes", hfile, texels, 0, NULL);
        if (!p->holes)
            return false;
    }

    /* the destructible area (destruction.c), or null */
    json_t *dd = get(r, scene, "destruction", "scene", false);
    if (dd && !json_is_null(dd)) {
        if (!get_vec(r, dd, "origin", "scene.destruction", 2, p->destr_origin) ||
            !get_vec(r, dd, "size", "scene.destruction", 2, p->destr_size) ||
            !get_number(r, dd, "cell_size", "scene.destruction", &p->destr_cell))
            return false;
        if (!(p->destr_cell > 0) || !(p->destr_size[0] > 0) || !(p->destr_size[1] > 0) ||
            !isfinite(p->destr_origin[0]) || !isfinite(p->destr_origin[1]) ||
            !isfinite(p->destr_size[0]) || !isfinite(p->destr_size[1]))
            return field_fail(r, "scene.destruction:", "needs a finite origin, a positive size "
                              "and a positive cell_size");
        double side = p->destr_size[0] > p->destr_size[1] ? p->destr_size[0] : p->destr_size[1];
        if (!(side / p->destr_cell <= SPLAT_MAX_DESTRUCTION_CELLS)) {
            char what[200];
            snprintf(what, sizeof what, "size / cell_size is %.0f cells per side, over the "
                     "pack limit of %d", ceil(side / p->destr_cell), SPLAT_MAX_DESTRUCTION_CELLS);
            return field_fail(r, "scene.destruction:", what);
        }
        p->has_destruction = true;
    }
    if (!read_light(r, scene))
        return false;
    json_t *cams = get_array(r, scene, "cameras", "scene", false);
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
            if (!get_string(r, c, "name", where, &cn) ||
                !get_vec(r, c, "position", where, 3, p->cameras[i].position) ||
                !get_vec(r, c, "look", where, 3, p->cameras[i].look))
                return false;
            p->cameras[i].name = xstrdup(cn);
        }
    }
    return true;
}

static bool read_materials(reader *r, json_t *root)
{
    rt_pack *p = r->p;
    json_t *mats = get_array(r, root, "materials", "manifest", true);
    if (!mats)
        return false;
    p->nmaterials = (int)json_array_size(mats);
    if (p->nmaterials == 0)
        return field_fail(r, "materials:", "is empty");
    p->materials = calloc((size_t)p->nmaterials, sizeof *p->materials);
    if (!p->materials)
        return false;
    for (int i = 0; i < p->nmaterials; i++) {
        json_t *m = json_array_get(mats, (size_t)i);
        char where[64];
        snprintf(where, sizeof where, "materials[%d]", i);
        const char *name;
        if (!get_string(r, m, "name", where, &name))
            return false;
        p->materials[i].name = xstrdup(name);
        json_t *src = get(r, m, "source", where, false);
        if (json_is_string(src))
            p->materials[i].source = xstrdup(json_string_value(src));
        json_t *ref = get(r, m, "reference", where, false);
        if (ref && !json_is_null(ref)) {
            char w2[96];
            snprintf(w2, sizeof w2, "%s.reference", where);
            if (!read_spirv(r, ref, w2, &p->materials[i].reference))
                return false;
        }
    }
    return true;
}

static bool read_params(reader *r, json_t *root)
{
    rt_pack *p = r->p;
    int size = 16;
    if (get(r, root, "params_size", "manifest", false) &&
        !get_int(r, root, "params_size", "manifest", 0, 1 << 16, &size))
        return false;
    p->params_size = size < 16 ? 16 : (uint32_t)size;
    json_t *ps = get_array(r, root, "params", "manifest", false);
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
        if (!get_string(r, q, "name", where, &name) ||
            !get_vec(r, q, "default", where, 4, def) ||
            !get_int(r, q, "offset", where, 0, (int)p->params_size - 16, &off))
            return false;
        if (off % 16)
            return field_fail(r, where, "offset must be a multiple of 16");
        p->params[i].name = xstrdup(name);
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

/* "X.mipK.ext" beside "X.ext" (texgen.h's contract, as the pack writer
 * names them). */
static char *mip_name(const char *file, int k)
{
    const char *slash = strrchr(file, '/'), *dot = strrchr(file, '.');
    size_t stem = dot && (!slash || dot > slash) ? (size_t)(dot - file) : strlen(file);
    const char *ext = file + stem;
    size_t n = strlen(file) + 16;
    char *s = malloc(n);
    if (s)
        snprintf(s, n, "%.*s.mip%d%s", (int)stem, file, k, ext);
    return s;
}

/* The stored mip levels of texture `tx` (manifest "mips": how many files);
 * each must have the size of its level. */
static bool read_mips(reader *r, json_t *t, const char *where, rt_pack_texture *tx)
{
    int n, side = tx->width > tx->height ? tx->width : tx->height, levels = 1;
    while (side >> levels)
        levels++;   /* floor(log2(side)) + 1 levels down to 1x1 */
    if (!get_int(r, t, "mips", where, 1, 31, &n))
        return false;
    if (n + 1 > levels) {
        char what[160];
        snprintf(what, sizeof what, "is %d: %d levels with the base, more than the %d "
                 "(log2(%d) + 1) a %dx%d texture has", n, n + 1, levels, side, tx->width,
                 tx->height);
        char w[96];
        snprintf(w, sizeof w, "%s.mips", where);
        return field_fail(r, w, what);
    }
    tx->mips = calloc((size_t)n, sizeof *tx->mips);
    if (!tx->mips)
        return rt_fail(r->e, RT_E_VULKAN, "textures", "out of memory");
    tx->nmips = n;
    for (int k = 1; k <= n; k++) {
        char *file = mip_name(tx->file, k), field[96];
        if (!file)
            return rt_fail(r->e, RT_E_VULKAN, "textures", "out of memory");
        snprintf(field, sizeof field, "%s.mips[%d]", where, k);
        size_t bytes;
        uint8_t *data = pack_file(r, field, file, 0, MAX_IMAGE, &bytes);
        int w = 0, h = 0, ch;
        if (data && stbi_info_from_memory(data, (int)bytes, &w, &h, &ch) &&
            w == (tx->width >> k > 0 ? tx->width >> k : 1) &&
            h == (tx->height >> k > 0 ? tx->height >> k : 1))
            tx->mips[k - 1] = stbi_load_from_memory(data, (int)bytes, &w, &h, &ch, 4);
        free(data);
        int ww = tx->width >> k > 0 ? tx->width >> k : 1;
        int wh = tx->height >> k > 0 ? tx->height >> k : 1;
        bool ok = data && tx->mips[k - 1];
        if (data && !ok && (w != ww || h != wh) && w > 0) {
            char msg[96];
            snprintf(msg, sizeof msg, "is %dx%d, its level needs %dx%d", w, h, ww, wh);
            rt_fail(r->e, RT_E_PACK_FILE, r->manifest, field, file, msg);
        } else if (data && !ok)
            rt_fail(r->e, RT_E_PACK_FILE, r->manifest, field, file,
                    "is not an image stb_image can read");
        else if (ok && (w != ww || h != wh)) {
            char msg[96];
            snprintf(msg, sizeof msg, "is %dx%d, its level needs %dx%d", w, h, ww, wh);
            rt_fail(r->e, RT_E_PACK_FILE, r->manifest, field, file, msg);
            ok = false;
        }
        free(file);
        if (!ok)
            return false;
    }
    return true;
}

/* The textures' arrays (binding 1 + a, layer l): the bindings dense from
 * 1, each array's layers dense from 0, one texture a layer, and its
 * textures alike in size, mip levels and sampler state. */
static bool texture_arrays(reader *r)
{
    rt_pack *p = r->p;
    for (int i = 0; i < p->ntextures; i++) {
        int a = (int)p->textures[i].binding - SPLAT_BIND_TEXTURE0;
        if (a + 1 > p->narrays)
            p->narrays = a + 1;
    }
    p->arrays = calloc((size_t)p->narrays + 1, sizeof *p->arrays);
    if (!p->arrays)
        return field_fail(r, "textures:", "out of memory");
    for (int a = 0; a < p->narrays; a++) {
        rt_pack_array *A = &p->arrays[a];
        for (int i = 0; i < p->ntextures; i++)
            if ((int)p->textures[i].binding == SPLAT_BIND_TEXTURE0 + a)
                A->nlayers++;
        char where[64];
        snprintf(where, sizeof where, "textures (binding %d)", SPLAT_BIND_TEXTURE0 + a);
        if (!A->nlayers)
            return field_fail(r, where, "no texture has this binding: the bindings must be dense");
        A->textures = calloc((size_t)A->nlayers, sizeof *A->textures);
        if (!A->textures)
            return field_fail(r, "textures:", "out of memory");
        for (int l = 0; l < A->nlayers; l++)
            A->textures[l] = -1;
        for (int i = 0; i < p->ntextures; i++) {
            const rt_pack_texture *t = &p->textures[i];
            if ((int)t->binding != SPLAT_BIND_TEXTURE0 + a)
                continue;
            if (t->layer >= A->nlayers || A->textures[t->layer] >= 0)
                return field_fail(r, where, "its layers must be 0, 1, … once each");
            A->textures[t->layer] = i;
            const rt_pack_texture *u = &p->textures[A->textures[0] >= 0 ? A->textures[0] : i];
            if (t->width != u->width || t->height != u->height || t->nmips != u->nmips ||
                t->linear != u->linear || t->mip_linear != u->mip_linear ||
                t->srgb != u->srgb || t->wrap != u->wrap)
                return field_fail(r, where, "its textures differ in size, mip levels or "
                                  "sampler state");
        }
    }
    return true;
}

static bool read_textures(reader *r, json_t *root)
{
    rt_pack *p = r->p;
    json_t *ts = get_array(r, root, "textures", "manifest", false);
    if (!ts)
        return !r->e->msg;
    p->ntextures = (int)json_array_size(ts);
    if (p->ntextures > SPLAT_MAX_TEXTURES) {
        char what[96];
        snprintf(what, sizeof what, "has %d entries, over the pack limit of %d", p->ntextures,
                 SPLAT_MAX_TEXTURES);
        p->ntextures = 0;
        return field_fail(r, "textures:", what);
    }
    p->textures = calloc((size_t)p->ntextures + 1, sizeof *p->textures);
    if (!p->textures)
        return false;
    for (int i = 0; i < p->ntextures; i++) {
        json_t *t = json_array_get(ts, (size_t)i);
        rt_pack_texture *tx = &p->textures[i];
        char where[64];
        snprintf(where, sizeof where, "textures[%d]", i);
        const char *file, *filter = "linear", *mip = "linear", *wrap = "repeat";
        int binding, layer = 0;
        if (!get_string(r, t, "file", where, &file) ||
            !get_int(r, t, "binding", where, SPLAT_BIND_TEXTURE0,
                     SPLAT_BIND_TEXTURE0 + SPLAT_MAX_TEXTURE_ARRAYS - 1, &binding))
            return false;
        if (get(r, t, "layer", where, false) &&
            !get_int(r, t, "layer", where, 0, SPLAT_MAX_ARRAY_LAYERS - 1, &layer))
            return false;
        tx->layer = layer;
        if (get(r, t, "filter", where, false) && !get_string(r, t, "filter", where, &filter))
            return false;
        if (get(r, t, "mip", where, false) && !get_string(r, t, "mip", where, &mip))
            return false;
        if (get(r, t, "wrap", where, false) && !get_string(r, t, "wrap", where, &wrap))
            return false;
        tx->file = xstrdup(file);
        tx->binding = (uint32_t)binding;
        int f = ir_filter_by_name(filter), mf = ir_filter_by_name(mip), wr = ir_wrap_by_name(wrap);
        if (f < 0 || mf < 0 || wr < 0)   /* ir.h's sampler names */
            return field_fail(r, where, "unknown filter, mip or wrap name");
        tx->linear = f == IR_FILTER_LINEAR;
        tx->mip_linear = mf == IR_FILTER_LINEAR;
        tx->wrap = rt_sampler_wrap((ir_wrap)wr);
        json_t *srgb = get(r, t, "srgb", where, false);
        tx->srgb = json_is_true(srgb);
        char field[96];
        snprintf(field, sizeof field, "%s.file", where);
        size_t n;
        uint8_t *data = pack_file(r, field, file, 0, MAX_IMAGE, &n);
        if (!data)
            return false;
        int ch, w, h;
        /* the size from the header before anything is decoded */
        if (stbi_info_from_memory(data, (int)n, &w, &h, &ch) &&
            (w > SPLAT_MAX_TEXTURE || h > SPLAT_MAX_TEXTURE)) {
            free(data);
            char msg[160];
            snprintf(msg, sizeof msg, "is %dx%d, over the pack limit of %d texels per side", w,
                     h, SPLAT_MAX_TEXTURE);
            return rt_fail(r->e, RT_E_PACK_FILE, r->manifest, field, file, msg);
        }
        tx->rgba = stbi_load_from_memory(data, (int)n, &tx->width, &tx->height, &ch, 4);
        free(data);
        if (!tx->rgba)
            return rt_fail(r->e, RT_E_PACK_FILE, r->manifest, field, file,
                           "is not an image stb_image can read");
        if (get(r, t, "mips", where, false) && !read_mips(r, t, where, tx))
            return false;
    }
    return texture_arrays(r);
}

static bool read_painted(reader *r, json_t *root)
{
    rt_pack *p = r->p;
    json_t *pa = get_array(r, root, "painted", "manifest", false);
    if (!pa && r->e->msg)
        return false;
    p->npainted = pa ? (int)json_array_size(pa) : 0;
    if (p->npainted > SPLAT_MAX_PAINTED) {
        char what[96];
        snprintf(what, sizeof what, "has %d masks, over the pack limit of %d", p->npainted,
                 SPLAT_MAX_PAINTED);
        return field_fail(r, "painted:", what);
    }
    /* sparse quad-tree (painted_upload.c) unless painted_format says dense;
     * absent: dense (PACK.md) */
    const char *fmt = "dense", *file = "painted.r8";
    if (get(r, root, "painted_format", "manifest", false) &&
        !get_string(r, root, "painted_format", "manifest", &fmt))
        return false;
    if (strcmp(fmt, "dense") && strcmp(fmt, "bc4") && strcmp(fmt, "r8"))
        return field_fail(r, "painted_format:", "must be \"dense\", \"bc4\" or \"r8\"");
    bool dense = !strcmp(fmt, "dense");
    if ((!dense || get(r, root, "painted_file", "manifest", false)) &&
        !get_string(r, root, "painted_file", "manifest", &file))
        return false;
    if (dense && p->npainted == 0)
        return true;   /* no masks: one zero layer (terrain_upload.c) */
    /* a sparse pack's shaders sample the atlas even without masks (the
     * file then holds none), so it is read and bound the same way */
    if (!dense) {
        size_t n = 0;
        uint8_t *data = pack_file(r, "painted_file", file, 0, MAX_BINARY, &n);
        bool ok = data && rt_painted_read(p, r->manifest, file, data, n, r->e);
        free(data);
        if (ok && (p->sparse->format == SPARSE_BC4) != !strcmp(fmt, "bc4")) {
            char what[160];
            snprintf(what, sizeof what, "holds %s masks, the manifest's painted_format is %s",
                     p->sparse->format == SPARSE_BC4 ? "bc4" : "r8", fmt);
            ok = rt_fail(r->e, RT_E_PACK_FILE, r->manifest, "painted_file", file, what);
        }
        return ok;
    }
    size_t bytes = (size_t)p->npainted * (size_t)p->hf_width * (size_t)p->hf_height;
    p->painted = pack_file(r, "painted_file", file, bytes, 0, NULL);
    return p->painted != NULL;
}

/* The periodic sites of terrain.position (PACK.md), optional. */
static bool read_sites(reader *r, json_t *root)
{
    rt_pack *p = r->p;
    json_t *ss = get(r, root, "world_sites", "manifest", false);
    if (!ss)
        return true;
    if (!json_is_array(ss) || json_array_size(ss) > SPLAT_WORLD_SITES)
        return field_fail(r, "world_sites:", "must be an array of at most 16 sites");
    p->nsites = (int)json_array_size(ss);
    for (int i = 0; i < p->nsites; i++) {
        json_t *o = json_array_get(ss, (size_t)i);
        rt_pack_site *st = &p->sites[i];
        char where[64];
        snprintf(where, sizeof where, "world_sites[%d]", i);
        const char *axes, *op;
        if (!get_string(r, o, "axes", where, &axes) || !get_string(r, o, "op", where, &op))
            return false;
        if (strlen(axes) != 2 || !strchr("xyz", axes[0]) || !strchr("xyz", axes[1]) ||
            (strcmp(op, "div") && strcmp(op, "mul")))
            return field_fail(r, where, "axes must be two of x y z, op div or mul");
        st->axes[0] = (int)(strchr("xyz", axes[0]) - "xyz");
        st->axes[1] = (int)(strchr("xyz", axes[1]) - "xyz");
        st->mul = op[0] == 'm';
        st->param = -1;
        if (get(r, o, "param", where, false)) {
            if (!get_int(r, o, "param", where, 0, p->nparams - 1, &st->param))
                return false;
        } else if (!get_vec(r, o, "scale", where, 2, st->scale)) {
            return false;
        }
    }
    return true;
}

/* The combinations' distance classes (PACK.md "Distance classes"),
 * appended to p->combos after the nbase combinations. */
static bool read_classes(reader *r, json_t *cs)
{
    rt_pack *p = r->p;
    int total = p->nbase;
    for (int i = 0; i < p->nbase; i++) {
        char where[64];
        snprintf(where, sizeof where, "combinations[%d]", i);
        json_t *c = json_array_get(cs, (size_t)i);
        json_t *cl = get_array(r, c, "classes", where, false);
        if (!cl && json_object_get(c, "classes"))
            return false;   /* not an array: get_array said so */
        if (cl && json_array_size(cl) > 16)
            return field_fail(r, where, "classes: has more than 16 entries");
        total += cl ? (int)json_array_size(cl) : 0;
    }
    if (total > 65534)
        return field_fail(r, "combinations:", "with their classes, more than 65534 shaders");
    if (total == p->nbase)
        return true;
    rt_pack_combo *all = realloc(p->combos, (size_t)total * sizeof *all);
    if (!all)
        return false;
    memset(all + p->nbase, 0, (size_t)(total - p->nbase) * sizeof *all);
    p->combos = all;
    int n = p->nbase;
    for (int i = 0; i < p->nbase; i++) {
        json_t *cl = json_object_get(json_array_get(cs, (size_t)i), "classes");
        p->combos[i].first_class = n;
        for (size_t k = 0; k < json_array_size(cl); k++) {
            json_t *c = json_array_get(cl, k);
            char where[96];
            snprintf(where, sizeof where, "combinations[%d].classes[%zu]", i, k);
            rt_pack_combo *co = &p->combos[n];
            p->ncombos = ++n;   /* freed with the pack from here on */
            co->base = i;
            co->nmaterials = p->combos[i].nmaterials;
            co->materials = calloc((size_t)co->nmaterials + 1, sizeof *co->materials);
            if (!co->materials)
                return false;
            memcpy(co->materials, p->combos[i].materials,
                   (size_t)co->nmaterials * sizeof *co->materials);
            json_t *dist = get_array(r, c, "distance", where, true);
            if (!dist)
                return false;
            json_t *lo = json_array_get(dist, 0), *hi = json_array_get(dist, 1);
            if (json_array_size(dist) != 2 || !json_is_number(lo) ||
                !(json_is_number(hi) || json_is_null(hi)))
                return field_fail(r, where, "distance: must be [lo, hi or null]");
            co->dlo = json_number_value(lo);
            co->dhi = json_is_null(hi) ? INFINITY : json_number_value(hi);
            if (!(co->dlo >= 0) || !(co->dhi >= co->dlo))
                return field_fail(r, where, "distance: must have 0 <= lo <= hi");
            if (get(r, c, "spirv", where, false)
                    ? !read_spirv(r, c, where, &co->spirv) ||
                          !read_fragment_glsl(r, c, where, &co->frag_path)
                    : !read_glsl_at(r, c, where, &co->glsl))
                return false;
            if (!read_compute(r, c, "compute", where, &co->compute, &co->compute_spirv) ||
                !get_number(r, c, "cost", where, &co->cost))
                return false;
            if (!(co->cost >= 0) || co->cost > 1e12)
                return field_fail(r, where, "cost: must be a number >= 0");
        }
        p->combos[i].nclasses = n - p->combos[i].first_class;
    }
    return true;
}

static bool read_combos(reader *r, json_t *root)
{
    rt_pack *p = r->p;
    json_t *cs = get_array(r, root, "combinations", "manifest", true);
    if (!cs)
        return false;
    p->ncombos = (int)json_array_size(cs);
    if (p->ncombos == 0)
        return field_fail(r, "combinations:", "is empty");
    if (p->ncombos > 65535)
        return field_fail(r, "combinations:", "has more than 65535 entries");
    p->combos = calloc((size_t)p->ncombos, sizeof *p->combos);
    if (!p->combos)
        return false;
    for (int i = 0; i < p->ncombos; i++) {
        json_t *c = json_array_get(cs, (size_t)i);
        char where[64];
        snprintf(where, sizeof where, "combinations[%d]", i);
        int id;
        if (!get_int(r, c, "id", where, 0, 65535, &id))
            return false;
        if (id != i)
            return field_fail(r, where, "id must equal its index");
        json_t *ms = get_array(r, c, "materials", where, true);
        if (!ms)
            return false;
        rt_pack_combo *co = &p->combos[i];
        co->nmaterials = (int)json_array_size(ms);
        co->materials = calloc((size_t)co->nmaterials + 1, sizeof *co->materials);
        if (!co->materials)
            return false;
        for (int k = 0; k < co->nmaterials; k++) {
            json_t *m = json_array_get(ms, (size_t)k);
            if (!json_is_integer(m) || json_integer_value(m) < 0 ||
                json_integer_value(m) >= p->nmaterials)
                return field_fail(r, where, "materials: index out of range");
            co->materials[k] = (int)json_integer_value(m);
        }
        if (!read_spirv(r, c, where, &co->spirv) ||
            !read_fragment_glsl(r, c, where, &co->frag_path) ||
            !read_compute(r, c, "compute", where, &co->compute, &co->compute_spirv) ||
            !read_compute(r, c, "undergrowth", where, &co->ug_compute, &co->ug_spirv))
            return false;
        json_t *cost = get(r, c, "cost", where, false);
        if (cost && (!json_is_number(cost) || !(json_number_value(cost) >= 0) ||
                     json_number_value(cost) > 1e12))
            return field_fail(r, where, "cost: must be a number >= 0");
        co->cost = cost ? json_number_value(cost) : 0;
        co->base = i;
        co->dhi = INFINITY;
    }
    p->nbase = p->ncombos;
    return read_classes(r, cs);
}

bool rt_combos_parse(const uint8_t *data, size_t n, int cells_x, int cells_z,
                     const int64_t *offsets, int ncombos, bool holes,
                     rt_pack_level *levels, const char *path, rt_error *e)
{
    int nlevels = rt_level_count(cells_x, cells_z), w = cells_x, h = cells_z;
    for (int L = 0; L < nlevels; L++) {
        size_t nodes = (size_t)w * (size_t)h, off = (size_t)offsets[L];
        if (offsets[L] < 0 || off > n || nodes * 2 > n - off) {
            char what[200];
            snprintf(what, sizeof what, "level %d (%dx%d nodes at offset %lld) runs past the "
                     "end of the file (%zu bytes)", L, w, h, (long long)offsets[L], n);
            return rt_fail(e, RT_E_PACK_FIELD, path, what);
        }
        rt_pack_level *pl = &levels[L];
        pl->width = w;
        pl->height = h;
        pl->ids = malloc(nodes * 2);
        if (!pl->ids)
            return rt_fail(e, RT_E_PACK_FIELD, path, "does not fit in memory");
        for (size_t i = 0; i < nodes; i++) {
            pl->ids[i] = (uint16_t)(data[off + 2 * i] | data[off + 2 * i + 1] << 8);
            /* a node all hole (PACK.md) only where the terrain has holes;
             * a coarse node without a combination (über-shaded) above the
             * leaves only */
            if (pl->ids[i] >= ncombos && !(pl->ids[i] == SPLAT_COMBO_HOLE && holes) &&
                !(pl->ids[i] == SPLAT_COMBO_UBER && L > 0)) {
                char at[160];
                snprintf(at, sizeof at, "level %d node (%zu, %zu)", L, i % (size_t)w,
                         i / (size_t)w);
                return rt_fail(e, RT_E_PACK_COMBO, path, pl->ids[i], ncombos, at);
            }
        }
        w = (w + 1) / 2;
        h = (h + 1) / 2;
    }
    return true;
}

static bool read_quadtree(reader *r, json_t *root)
{
    rt_pack *p = r->p;
    json_t *qt = get(r, root, "quadtree", "manifest", true);
    const char *file;
    if (!qt || !get_string(r, qt, "file", "quadtree", &file))
        return false;
    json_t *lv = get_array(r, qt, "levels", "quadtree", true);
    if (!lv)
        return false;
    int cx = (p->hf_width + p->cell_texels - 1) / p->cell_texels;
    int cz = (p->hf_height + p->cell_texels - 1) / p->cell_texels;
    int want = rt_level_count(cx, cz);
    if ((int)json_array_size(lv) != want) {
        char what[96];
        snprintf(what, sizeof what, "must have %d levels for %dx%d cells", want, cx, cz);
        return field_fail(r, "quadtree.levels", what);
    }
    int64_t *offsets = calloc((size_t)want, sizeof *offsets);
    p->levels = calloc((size_t)want, sizeof *p->levels);
    if (!offsets || !p->levels) {
        free(offsets);
        return false;
    }
    p->nlevels = want;
    int w = cx, h = cz;
    for (int L = 0; L < want; L++) {
        json_t *l = json_array_get(lv, (size_t)L);
        char where[64];
        snprintf(where, sizeof where, "quadtree.levels[%d]", L);
        int lw, lh, off;
        if (!get_int(r, l, "width", where, 1, 1 << 20, &lw) ||
            !get_int(r, l, "height", where, 1, 1 << 20, &lh) ||
            !get_int(r, l, "offset", where, 0, 0x7fffffff, &off)) {
            free(offsets);
            return false;
        }
        if (lw != w || lh != h) {
            char what[96];
            snprintf(what, sizeof what, "must be %dx%d nodes", w, h);
            free(offsets);
            return field_fail(r, where, what);
        }
        offsets[L] = off;
        w = (w + 1) / 2;
        h = (h + 1) / 2;
    }
    size_t n = 0;
    uint8_t *data = pack_file(r, "quadtree.file", file, 0, MAX_BINARY, &n);
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", p->dir, file);
    bool ok = data && rt_combos_parse(data, n, cx, cz, offsets, p->nbase, p->holes != NULL,
                                      p->levels, path,
                                      r->e);
    free(data);
    free(offsets);
    return ok;
}

/* Every shader against the interface of its role (spirv_check.c), so
 * that no module reaches the driver unchecked. */
static bool check_one(reader *r, const rt_spirv *s, const rt_interface *in)
{
    if (!s->words)
        return true;
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", r->p->dir, s->path);
    return rt_spirv_check(s->words, s->nwords, path, in, r->e);
}

static bool check_shaders(reader *r)
{
    rt_pack *p = r->p;
    rt_interface in[RT_ROLE_COUNT];
    bool ok = true;
    int made = 0;
    for (; made < RT_ROLE_COUNT && ok; made++)
        ok = rt_interface_for(p, (rt_shader_role)made, &in[made]);
    if (!ok) {
        made--;
        rt_fail(r->e, RT_E_PACK_FIELD, r->manifest, "out of memory");
    }
    ok = ok && check_one(r, &p->vertex, &in[RT_ROLE_VERTEX]) &&
         check_one(r, &p->uber, &in[RT_ROLE_COMPOSITE]);
    for (int i = 0; ok && i < p->ncombos; i++)
        ok = check_one(r, &p->combos[i].spirv, &in[RT_ROLE_COMPOSITE]) &&
             check_one(r, &p->combos[i].compute_spirv, &in[RT_ROLE_COMPUTE]) &&
             check_one(r, &p->combos[i].ug_spirv, &in[RT_ROLE_UNDERGROWTH]);
    ok = ok && check_one(r, &p->uber_compute_spirv, &in[RT_ROLE_COMPUTE]);
    for (int i = 0; ok && i < p->nmaterials; i++)
        ok = check_one(r, &p->materials[i].reference, &in[RT_ROLE_REFERENCE]);
    for (int i = 0; i < made; i++)
        rt_interface_free(&in[i]);
    return ok;
}

bool rt_pack_load(rt_pack *p, const char *dir, rt_error *e)
{
    rt_error local = { 0 };
    if (!e)
        e = &local;
    memset(p, 0, sizeof *p);
    p->dir = xstrdup(dir);
    char *manifest = join(dir, "manifest.json");
    reader r = { manifest, p, e, -1 };
    rt_error_clear(e);
    json_t *root = NULL;
    bool ok = false;
    if (!p->dir || !manifest)
        goto done;
    r.dirfd = open(dir, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (r.dirfd < 0) {
        rt_fail(e, RT_E_IO, "open the pack folder", dir, strerror(errno));
        goto done;
    }
    char why[256];
    size_t mn = 0;
    char *text = (char *)rt_pack_read_file(r.dirfd, "manifest.json", MAX_MANIFEST, &mn, why,
                                           sizeof why);
    if (!text) {
        rt_fail(e, RT_E_IO, "read", manifest, why);
        goto done;
    }
    json_error_t je;
    root = json_loadb(text, mn, JSON_REJECT_DUPLICATES, &je);
    free(text);
    if (!root) {
        rt_fail(e, RT_E_PACK_JSON, manifest, je.line, je.column, je.text);
        goto done;
    }
    const char *format;
    int version, abi;
    if (!get_string(&r, root, "format", "manifest", &format))
        goto done;
    if (strcmp(format, "splatc-pack")) {
        rt_fail(e, RT_E_PACK_VERSION, manifest, "format is not \"splatc-pack\"");
        goto done;
    }
    if (!get_int(&r, root, "version", "manifest", 0, 1 << 20, &version) ||
        !get_int(&r, root, "abi", "manifest", 0, 1 << 20, &abi))
        goto done;
    if (version != SPLAT_PACK_VERSION || abi != SPLAT_ABI_VERSION) {
        char what[128];
        snprintf(what, sizeof what, "pack version %d / abi %d; this runtime reads version %d / "
                 "abi %d", version, abi, SPLAT_PACK_VERSION, SPLAT_ABI_VERSION);
        rt_fail(e, RT_E_PACK_VERSION, manifest, what);
        goto done;
    }
    ok = read_scene(&r, root) && read_materials(&r, root) && read_params(&r, root) &&
         read_textures(&r, root) && read_painted(&r, root) && read_sites(&r, root) &&
         read_combos(&r, root) && read_quadtree(&r, root) && read_undergrowth(&r, root) &&
         read_far(&r, root) && read_vectors(&r, root);
    if (ok) {
        json_t *vx = get(&r, root, "vertex", "manifest", true);
        ok = vx && read_spirv(&r, vx, "vertex", &p->vertex);
    }
    if (ok) {
        json_t *ub = get(&r, root, "uber", "manifest", false);
        if (ub && !json_is_null(ub))
            ok = read_spirv(&r, ub, "uber", &p->uber) &&
                 read_fragment_glsl(&r, ub, "uber", &p->uber_frag_path) &&
                 read_compute(&r, ub, "compute", "uber", &p->uber_compute,
                              &p->uber_compute_spirv);
    }
    ok = ok && validate_all(&r) && check_shaders(&r);
done:
    for (int k = 0; k < r.nunchecked; k++)
        free(r.unchecked[k].path);
    free(r.unchecked);
    if (r.dirfd >= 0)
        close(r.dirfd);
    json_decref(root);
    free(manifest);
    if (!ok) {
        if (!e->msg)
            rt_fail(e, RT_E_PACK_FIELD, dir, "out of memory");
        rt_pack_free(p);
    }
    rt_error_clear(&local);
    return ok;
}

static void free_spirv(rt_spirv *s)
{
    free(s->path);
    free(s->words);
}

void rt_pack_free(rt_pack *p)
{
    for (int i = 0; i < p->ncameras && p->cameras; i++)
        free(p->cameras[i].name);
    for (int i = 0; i < p->nmaterials && p->materials; i++) {
        free(p->materials[i].name);
        free(p->materials[i].source);
        free_spirv(&p->materials[i].reference);
    }
    for (int i = 0; i < p->nparams && p->params; i++)
        free(p->params[i].name);
    for (int i = 0; i < p->ntextures && p->textures; i++) {
        free(p->textures[i].file);
        stbi_image_free(p->textures[i].rgba);
        for (int k = 0; k < p->textures[i].nmips && p->textures[i].mips; k++)
            stbi_image_free(p->textures[i].mips[k]);
        free(p->textures[i].mips);
    }
    for (int a = 0; a < p->narrays && p->arrays; a++)
        free(p->arrays[a].textures);
    for (int i = 0; i < p->ncombos && p->combos; i++) {
        free(p->combos[i].materials);
        free(p->combos[i].compute);
        free(p->combos[i].ug_compute);
        free(p->combos[i].glsl);
        free(p->combos[i].frag_path);
        free_spirv(&p->combos[i].spirv);
        free_spirv(&p->combos[i].compute_spirv);
        free_spirv(&p->combos[i].ug_spirv);
    }
    for (int i = 0; i < p->nlevels && p->levels; i++)
        free(p->levels[i].ids);
    free(p->holes);
    free_spirv(&p->uber);
    free(p->uber_compute);
    free_spirv(&p->uber_compute_spirv);
    free(p->uber_frag_path);
    for (int i = 0; i < p->ug.ntextures; i++)
        free(p->ug.textures[i].rgba);
    free(p->ug.textures);
    free(p->ug.blocks);
    free(p->ug.meshes);
    free(p->ug.vertices);
    free(p->ug.indices);
    free(p->far.data);
    free(p->vectors);
    free_spirv(&p->vertex);
    free(p->cameras);
    free(p->materials);
    free(p->params);
    free(p->textures);
    free(p->arrays);
    free(p->combos);
    free(p->levels);
    free(p->painted);
    if (p->sparse)
        sparse_free(p->sparse);
    free(p->sparse);
    free(p->heights);
    free(p->name);
    free(p->scene_path);
    free(p->dir);
    memset(p, 0, sizeof *p);
}

int rt_pack_material_find(const rt_pack *p, const char *name)
{
    for (int i = 0; i < p->nmaterials; i++)
        if (!strcmp(p->materials[i].name, name))
            return i;
    return -1;
}

int rt_pack_camera_find(const rt_pack *p, const char *name)
{
    for (int i = 0; i < p->ncameras; i++)
        if (!strcmp(p->cameras[i].name, name))
            return i;
    return -1;
}

/* ---- the pack against the device ------------------------------------------ */

static bool limit(const rt_pack *p, const char *what, uint64_t v, const char *name,
                  uint64_t max, rt_error *e)
{
    if (v <= max)
        return true;
    char where[1024], lim[128];
    snprintf(where, sizeof where, "%s/manifest.json", p->dir);
    snprintf(lim, sizeof lim, "the device's %s", name);
    return rt_fail(e, RT_E_PACK_LIMIT, where, what, (unsigned long long)v, lim,
                   (unsigned long long)max);
}

bool rt_pack_check_device(const rt_pack *p, const rt_device *d, rt_error *e)
{
    const VkPhysicalDeviceLimits *L = &d->props.limits;
    const uint32_t dim = L->maxImageDimension2D, layers = L->maxImageArrayLayers;
    if (!limit(p, "the heightfield's width", (uint64_t)p->hf_width, "maxImageDimension2D", dim, e) ||
        !limit(p, "the heightfield's height", (uint64_t)p->hf_height, "maxImageDimension2D", dim, e))
        return false;
    for (int i = 0; i < p->ntextures; i++) {
        char what[256];
        snprintf(what, sizeof what, "textures[%d] (%s): the larger side", i, p->textures[i].file);
        int side = p->textures[i].width > p->textures[i].height ? p->textures[i].width
                                                                : p->textures[i].height;
        if (!limit(p, what, (uint64_t)side, "maxImageDimension2D", dim, e))
            return false;
    }
    if (p->painted && !limit(p, "the dense painted layer count", (uint64_t)p->npainted,
                             "maxImageArrayLayers", layers, e))
        return false;
    if (p->sparse) {
        const sparse_masks *s = p->sparse;
        int side = s->atlas_width > s->atlas_height ? s->atlas_width : s->atlas_height;
        int cells = s->cells_x > s->cells_z ? s->cells_x : s->cells_z;
        if (!limit(p, "the painted atlas's larger side", (uint64_t)side, "maxImageDimension2D",
                   dim, e) ||
            !limit(p, "the painted index's larger side", (uint64_t)cells, "maxImageDimension2D",
                   dim, e) ||
            !limit(p, "the painted index's layer count", (uint64_t)s->layers,
                   "maxImageArrayLayers", layers, e))
            return false;
    }
    if (p->has_destruction) {
        double side = p->destr_size[0] > p->destr_size[1] ? p->destr_size[0] : p->destr_size[1];
        if (!limit(p, "the destruction grid's cells per side", (uint64_t)ceil(side / p->destr_cell),
                   "maxImageDimension2D", dim, e))
            return false;
    }
    for (int a = 0; a < p->narrays; a++) {
        char what[96];
        snprintf(what, sizeof what, "texture array %d's layer count", a);
        if (!limit(p, what, (uint64_t)p->arrays[a].nlayers, "maxImageArrayLayers", layers, e))
            return false;
    }
    /* fragment stage: set 0's six samplers and set 1's texture arrays */
    uint64_t samplers = 6 + (uint64_t)p->narrays;
    return limit(p, "the fragment stage's sampler count (6 + texture arrays)", samplers,
                 "maxPerStageDescriptorSamplers", L->maxPerStageDescriptorSamplers, e) &&
           limit(p, "the fragment stage's sampled image count (6 + texture arrays)", samplers,
                 "maxPerStageDescriptorSampledImages", L->maxPerStageDescriptorSampledImages, e) &&
           limit(p, "params_size", p->params_size, "maxUniformBufferRange",
                 L->maxUniformBufferRange, e) &&
           limit(p, "the push-constant block (bytes)", sizeof(splat_push),
                 "maxPushConstantsSize", L->maxPushConstantsSize, e);
}
