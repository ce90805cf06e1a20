/* pack_internal.h — the pack loader's own declarations, shared by its
 * files (runtime/pack_load.c and the pack_*.c beside it):
 *
 *   pack_load.c      rt_pack_load, rt_pack_free, rt_pack_check_device
 *   pack_files.c     the pack folder as untrusted input; typed field access
 *   pack_shaders.c   SPIR-V and GLSL (read on first use), combinations,
 *                    classes, quadtree
 *   pack_sections.c  scene, light, materials, params, sites, undergrowth,
 *                    far atlas, vectors
 *   pack_textures.c  textures, their mips and arrays; painted masks
 *
 * Every function here takes the reader of one rt_pack_load call and, on
 * failure, leaves its message in r->e (naming the manifest field). */
#ifndef SPLAT_PACK_INTERNAL_H
#define SPLAT_PACK_INTERNAL_H

#include "rt_internal.h"
#include "ir.h"
#include "far_atlas.h"
#include "zst.h"

#include <jansson.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

typedef struct rt_pk_reader {
    const char *manifest;   /* path, for messages */
    rt_pack    *p;
    rt_error   *e;
    int         dirfd;      /* the pack folder: every file opened under it */
} rt_pk_reader;

/* Files bigger than these are refused before they are read. */
#define MAX_MANIFEST ((size_t)64 << 20)
#define MAX_SPIRV    ((size_t)64 << 20)
#define MAX_IMAGE    ((size_t)1 << 30)
#define MAX_BINARY   ((size_t)1 << 31)

/* ---- pack_files.c ---- */

char *rt_pk_strdup(const char *s);
char *rt_pk_join(const char *dir, const char *rel);
bool rt_pk_field_fail(rt_pk_reader *r, const char *where, const char *what);
json_t *rt_pk_get(rt_pk_reader *r, json_t *obj, const char *key, const char *where,
                   bool required);
bool rt_pk_get_number(rt_pk_reader *r, json_t *obj, const char *key, const char *where,
                       double *out);
bool rt_pk_get_int(rt_pk_reader *r, json_t *obj, const char *key, const char *where,
                    int lo, int hi, int *out);
bool rt_pk_get_string(rt_pk_reader *r, json_t *obj, const char *key, const char *where,
                       const char **out);
json_t *rt_pk_get_array(rt_pk_reader *r, json_t *obj, const char *key, const char *where,
                         bool required);
bool rt_pk_get_vec(rt_pk_reader *r, json_t *obj, const char *key, const char *where,
                    int n, double *out);
uint8_t *rt_pk_pack_file(rt_pk_reader *r, const char *field, const char *rel,
                          size_t want, size_t max, size_t *got);
uint32_t rt_pk_le32(const uint8_t *b);

/* ---- pack_shaders.c ---- */

/* p->shaders made (before any module is registered) and freed */
bool rt_pk_shaders_open(rt_pk_reader *r);
void rt_pk_shaders_free(struct rt_pack_shaders *s);
bool rt_pk_read_spirv(rt_pk_reader *r, json_t *obj, const char *where, rt_shader_role role,
                      rt_spirv *out);
bool rt_pk_read_compute(rt_pk_reader *r, json_t *obj, const char *key, const char *where,
                        rt_shader_role role, rt_text *out, rt_spirv *spv);
bool rt_pk_read_fragment_glsl(rt_pk_reader *r, json_t *c, const char *where, char **path);
bool rt_pk_read_stand_ins(rt_pk_reader *r, json_t *uber);
bool rt_pk_read_combos(rt_pk_reader *r, json_t *root);
bool rt_pk_read_quadtree(rt_pk_reader *r, json_t *root);

/* ---- pack_sections.c ---- */

bool rt_pk_read_far(rt_pk_reader *r, json_t *root);
bool rt_pk_read_vectors(rt_pk_reader *r, json_t *root);
bool rt_pk_read_undergrowth(rt_pk_reader *r, json_t *root);
bool rt_pk_read_scene(rt_pk_reader *r, json_t *root);
bool rt_pk_read_materials(rt_pk_reader *r, json_t *root);
bool rt_pk_read_params(rt_pk_reader *r, json_t *root);
bool rt_pk_read_sites(rt_pk_reader *r, json_t *root);

/* ---- pack_textures.c ---- */

bool rt_pk_read_textures(rt_pk_reader *r, json_t *root);
bool rt_pk_read_painted(rt_pk_reader *r, json_t *root);

#endif
