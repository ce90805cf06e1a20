/* undergrowth.h — a pack's undergrowth (seed 000 §5.5): the `undergrowth`
 * blocks of the scene's materials, each undergrowth-bearing material's
 * slot in the mask shaders (abi.h "undergrowth masks") and the meshes the
 * blocks name, as the pack stores them (PACK.md "Undergrowth").
 */
#ifndef SPLAT_UNDERGROWTH_H
#define SPLAT_UNDERGROWTH_H

#include <stdio.h>

#include "mesh.h"
#include "scene_load.h"

typedef struct splat_ug_block {
    int                   material;  /* scene material index              */
    int                   slot;      /* its mask slot                     */
    int                   mesh;      /* index into meshes                 */
    const sg_undergrowth *u;         /* owned by the scene's program      */
    int                   texture;   /* index into textures, or -1        */
} splat_ug_block;

typedef struct splat_ug_texture {
    const char *path;                /* the block's (owned by the program) */
    int         width, height;
    uint8_t    *rgba;                /* width * height * 4, sRGB + alpha  */
} splat_ug_texture;

typedef struct splat_ug {
    int            nslots;           /* undergrowth-bearing materials     */
    int           *slot_of;          /* per scene material: slot or -1    */
    splat_ug_block *blocks;  int nblocks;
    splat_mesh    *meshes;           /* distinct: a built-in or OBJ file  */
    char         **mesh_names;       /* built-in name or the OBJ's basename */
    const char   **mesh_keys;        /* built-in name or the OBJ's path;
                                        NULL for a far version            */
    int           *far;              /* per mesh: its far version or -1   */
    int            nmeshes;
    splat_ug_texture *textures;  int ntextures;   /* distinct, <= SPLAT_MAX_UG_TEXTURES */
} splat_ug;

/* The scene's undergrowth (none: nblocks 0, slot_of all -1).  Meshes are
 * built or loaded here; a located error if an OBJ file fails now. */
bool splat_ug_init(splat_ug *u, const splat_scene *s, sg_diags *d);
void splat_ug_free(splat_ug *u);
/* Whether combination `materials` holds an undergrowth-bearing material. */
bool splat_ug_in(const splat_ug *u, const int *materials, int n);
/* meshes.bin (PACK.md): every mesh's vertices and indices. */
bool splat_ug_write_meshes(const splat_ug *u, FILE *f);
/* ugtex.bin (PACK.md): every texture's texels (only with textures). */
bool splat_ug_write_textures(const splat_ug *u, FILE *f);

#endif
