/* cache.h — the content-addressed SPIR-V cache (cache.c).
 */
#ifndef SPLAT_CACHE_H
#define SPLAT_CACHE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

/* ---- cache.c: content-addressed SPIR-V cache --------------------------- */

#define SPLAT_KEY_CHARS 32   /* hex digits of a shader key (XXH3-128)       */

/* The key of a shader: XXH3-128 of the compiler version, ABI version, stage
 * (spv_stage) and GLSL text, as 32 hex digits. */
void  splat_shader_key(const char *glsl, int stage, char key[SPLAT_KEY_CHARS + 1]);

typedef struct splat_cache {
    char *dir;                /* entries live under here; NULL = disabled    */
} splat_cache;

/* $SPLATC_CACHE, else $XDG_CACHE_HOME/splatc, else ~/.cache/splatc
 * (malloc'd), or NULL when none can be named. */
char *splat_cache_default_dir(void);
/* Open (creating folders) the cache under `dir` (NULL: the default).
 * False, with the cache disabled, if it cannot be created. */
bool  splat_cache_open(splat_cache *c, const char *dir);
void  splat_cache_close(splat_cache *c);
/* A hit gives a malloc'd module (a damaged entry is a miss). */
bool  splat_cache_get(const splat_cache *c, const char *key, uint32_t **words,
                      size_t *nwords);
/* Store atomically (temporary file + rename). */
bool  splat_cache_put(const splat_cache *c, const char *key,
                      const uint32_t *words, size_t nwords);

#endif
