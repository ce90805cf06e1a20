/* cache.c — the content-addressed SPIR-V cache of `splatc build`.
 *
 * A shader's SPIR-V depends only on its GLSL text, its stage and the
 * compiler that turned one into the other, so the key is the XXH3-128 hash
 * of exactly those: "splatc <version>", the ABI version, the stage and the
 * GLSL (which already names every binding and param slot).  Editing one
 * material changes the GLSL of the composites that contain it and of no
 * other, so only those miss.
 *
 * Layout: DIR/spv1/ab/abcdef….spv (two-hex-digit fan-out).  An entry is
 * the module followed by a 4-word trailer (ENTRY_MAGIC, the module's word
 * count, its XXH3-64 as two words).  Only validated modules are stored and
 * the trailer proves an entry is the one stored, so a hit needs no new
 * spirv-val run (which would cost more than the whole warm build).
 * Entries are written through spv_write_file (temporary file + rename),
 * so a reader — another `splatc build` running at the same time — never
 * sees half an entry; a damaged entry reads as a miss.
 */
#include "cache.h"
#include "util.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <xxhash.h>

#include "abi.h"
#include "spv.h"

#ifndef SPLATC_VERSION
#define SPLATC_VERSION "0"
#endif

#define SPIRV_MAGIC 0x07230203u
#define ENTRY_MAGIC 0x434c5053u   /* "SPLC" */
#define TRAILER 4                  /* words after the module               */

void splat_shader_key(const char *glsl, int stage, char key[SPLAT_KEY_CHARS + 1])
{
    XXH3_state_t *st = XXH3_createState();
    if (!st)
        abort();
    XXH3_128bits_reset(st);
    char head[96];
    int n = snprintf(head, sizeof head, "splatc %s\nabi %d\nstage %d\n",
                     SPLATC_VERSION, SPLAT_ABI_VERSION, stage);
    XXH3_128bits_update(st, head, (size_t)n);
    XXH3_128bits_update(st, glsl, strlen(glsl));
    XXH128_hash_t h = XXH3_128bits_digest(st);
    XXH3_freeState(st);
    snprintf(key, SPLAT_KEY_CHARS + 1, "%016llx%016llx",
             (unsigned long long)h.high64, (unsigned long long)h.low64);
}

static char *join(const char *a, const char *b)
{
    size_t n = strlen(a) + strlen(b) + 2;
    char *s = xmalloc(n);
    snprintf(s, n, "%s/%s", a, b);
    return s;
}

char *splat_cache_default_dir(void)
{
    const char *env = getenv("SPLATC_CACHE");
    if (env && *env)
        return strdup(env);
    env = getenv("XDG_CACHE_HOME");
    if (env && *env)
        return join(env, "splatc");
    env = getenv("HOME");
    if (env && *env)
        return join(env, ".cache/splatc");
    return NULL;
}

bool splat_cache_open(splat_cache *c, const char *dir)
{
    memset(c, 0, sizeof *c);
    char *base = dir ? strdup(dir) : splat_cache_default_dir();
    if (!base)
        return false;
    c->dir = join(base, "spv1");
    free(base);
    if (!splat_make_dirs(c->dir)) {
        splat_cache_close(c);
        return false;
    }
    return true;
}

void splat_cache_close(splat_cache *c)
{
    free(c->dir);
    c->dir = NULL;
}

static char *entry_path_ext(const splat_cache *c, const char *key, bool make_fanout,
                            const char *ext)
{
    char sub[3] = {key[0], key[1], 0};
    char *fan = join(c->dir, sub);
    if (make_fanout)
        splat_make_dirs(fan);
    char file[SPLAT_KEY_CHARS + 8];
    snprintf(file, sizeof file, "%s%s", key, ext);
    char *path = join(fan, file);
    free(fan);
    return path;
}

static char *entry_path(const splat_cache *c, const char *key, bool make_fanout)
{
    return entry_path_ext(c, key, make_fanout, ".spv");
}

bool splat_cache_get(const splat_cache *c, const char *key, uint32_t **words,
                     size_t *nwords)
{
    *words = NULL;
    *nwords = 0;
    if (!c->dir)
        return false;
    char *path = entry_path(c, key, false);
    char why[256];   /* a regular file of bounded size, or a miss */
    FILE *f = splat_input_fopen(path, SPLAT_MAX_SPIRV_BYTES, why, sizeof why);
    free(path);
    if (!f)
        return false;
    bool ok = false;
    long size = -1;
    if (fseek(f, 0, SEEK_END) == 0)
        size = ftell(f);
    if (size >= 4 * (5 + TRAILER) && size % 4 == 0 && fseek(f, 0, SEEK_SET) == 0) {
        uint32_t *w = xmalloc((size_t)size);
        size_t n = (size_t)size / 4 - TRAILER;
        if (fread(w, 1, (size_t)size, f) == (size_t)size && w[0] == SPIRV_MAGIC) {
            uint64_t h = XXH3_64bits(w, 4 * n);
            const uint32_t *t = w + n;
            ok = t[0] == ENTRY_MAGIC && t[1] == (uint32_t)n && t[2] == (uint32_t)h &&
                 t[3] == (uint32_t)(h >> 32);
        }
        if (ok) {
            *words = w;
            *nwords = n;
        } else {
            free(w);
        }
    }
    fclose(f);
    return ok;
}

bool splat_cache_put(const splat_cache *c, const char *key, const uint32_t *words,
                     size_t nwords)
{
    if (!c->dir)
        return false;
    uint32_t *w = xmalloc(4 * (nwords + TRAILER));
    memcpy(w, words, 4 * nwords);
    uint64_t h = XXH3_64bits(words, 4 * nwords);
    w[nwords] = ENTRY_MAGIC;
    w[nwords + 1] = (uint32_t)nwords;
    w[nwords + 2] = (uint32_t)h;
    w[nwords + 3] = (uint32_t)(h >> 32);
    char *path = entry_path(c, key, true);
    bool ok = spv_write_file(path, w, nwords + TRAILER);
    free(path);
    free(w);
    return ok;
}

/* ---- validation by shape --------------------------------------------------- */

#define VALID_MAGIC   "splatc validated shape\n"

bool splat_spirv_shape_key(const uint32_t *words, size_t nwords,
                           char key[SPLAT_KEY_CHARS + 1])
{
    uint64_t h[2];
    if (!spv_shape(words, nwords, h))
        return false;
    /* under the versions: a new splatc (its SPIRV-Tools) validates again */
    char head[128];
    int n = snprintf(head, sizeof head, "splatc %s\nabi %d\nshape %016llx%016llx\n",
                     SPLATC_VERSION, SPLAT_ABI_VERSION, (unsigned long long)h[0],
                     (unsigned long long)h[1]);
    XXH128_hash_t k = XXH3_128bits(head, (size_t)n);
    snprintf(key, SPLAT_KEY_CHARS + 1, "%016llx%016llx", (unsigned long long)k.high64,
             (unsigned long long)k.low64);
    return true;
}

bool splat_cache_valid(const splat_cache *c, const char *key)
{
    if (!c->dir)
        return false;
    char *path = entry_path_ext(c, key, false, ".val");
    char why[256];
    FILE *f = splat_input_fopen(path, 64, why, sizeof why);
    free(path);
    if (!f)
        return false;
    char buf[64] = {0};
    size_t n = fread(buf, 1, sizeof buf - 1, f);
    fclose(f);
    return n == sizeof VALID_MAGIC - 1 && memcmp(buf, VALID_MAGIC, n) == 0;
}

bool splat_cache_mark_valid(const splat_cache *c, const char *key)
{
    if (!c->dir)
        return false;
    char *path = entry_path_ext(c, key, true, ".val");
    bool ok = splat_write_atomic(path, VALID_MAGIC, sizeof VALID_MAGIC - 1);
    free(path);
    return ok;
}
