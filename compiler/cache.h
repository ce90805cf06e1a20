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

/* The shape of a SPIR-V module for validation (spv.h spv_shape: every
 * instruction but the float-valued constants and debug names, ids renumbered, a use of
 * such a constant written as its type), under the compiler and ABI
 * versions, as 32 hex digits.  spirv-val's verdict does not depend on a
 * float constant's value or on which equal constants share an id (no rule
 * reads a float's value: sizes, indices and member numbers are integers),
 * so a module whose shape passed spirv-val passes it too: a one-colour
 * edit changes the über-shader's constants, not its shape (issue 29
 * "spirv-val runs once per module").
 * False (no key) for words that are not a well-formed SPIR-V stream. */
bool  splat_spirv_shape_key(const uint32_t *words, size_t nwords,
                            char key[SPLAT_KEY_CHARS + 1]);
/* Whether a module of shape `key` passed spirv-val before (an entry
 * DIR/spv1/ab/<key>.val, written by splat_cache_mark_valid). */
bool  splat_cache_valid(const splat_cache *c, const char *key);
bool  splat_cache_mark_valid(const splat_cache *c, const char *key);

#endif
