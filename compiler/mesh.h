/* mesh.h — the meshes undergrowth instances are drawn with (seed 000 §5.5,
 * DESIGN.md §3 "Undergrowth"): a few built-in procedural ones and OBJ
 * files.
 *
 * A mesh is an indexed triangle list in metres at scale 1, y up, the root
 * (where the instance stands on the terrain) at the origin; uv.y is 0 at
 * the root and 1 at the tip.  Everything is deterministic: the same name
 * or file gives the same bytes on every run and machine.
 *
 * Sections: mesh.c (built-ins, OBJ post-processing), mesh_obj.cpp (reading
 * OBJ files through tinyobjloader).
 */
#ifndef SPLAT_MESH_H
#define SPLAT_MESH_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif


/* ---- mesh.c ---------------------------------------------------------------- */

typedef struct splat_mesh_vertex {
    float pos[3];   /* metres at scale 1, root at the origin, y up   */
    float nrm[3];   /* unit length                                   */
    float uv[2];    /* uv.y = 0 at the root, 1 at the tip            */
} splat_mesh_vertex;

typedef struct splat_mesh {
    splat_mesh_vertex *v;    uint32_t nv;     /* malloc'd                  */
    uint32_t          *idx;  uint32_t nidx;   /* triangle list, nidx % 3 == 0 */
} splat_mesh;

/* The built-in meshes' names, NULL-terminated: "grass" (a clump of 12
 * tapered blades, 0.35-0.5 m, normals mostly up: lit like the ground),
 * "plant" (two crossed 0.6 x 0.6 m quads; the shader cuts a leaf from uv,
 * drawn double-sided), "stone" (a low-poly rock 0.4 m wide, 0.2 m high,
 * sunk 5 cm into the ground, flat normals). */
extern const char *const splat_mesh_builtins[];
/* Build built-in mesh `name` into *m; false for an unknown name. */
bool splat_mesh_builtin(const char *name, splat_mesh *m);
/* Its far version, drawn beyond the runtime's LOD distance where a clump
 * covers a few pixels: the same cover from a sixth of the triangles
 * ("grass": 4 wide single-quad blades, 8 triangles instead of 48;
 * "stone": 5 faces instead of 24).  False where there is none ("plant",
 * 4 triangles, is its own). */
bool splat_mesh_builtin_far(const char *name, splat_mesh *m);
/* Load an OBJ file: triangulated, identical vertices merged; normals from
 * the file or flat where it has none; uv from the file (uv.y clamped to
 * 0..1) or, where it has none, (0.5, height over the mesh's height).
 * Before tinyobjloader sees it, the file is read as an untrusted input
 * (util.h: a regular file of at most SPLAT_MAX_MESH_BYTES) and its text
 * is checked line by line (splat_obj_scan).  The merged mesh's own limits
 * (abi.h SPLAT_MAX_MESH_*) are the caller's.  False with a malloc'd
 * message in *err (a missing file: strerror's text; a bad line:
 * "line N: ..."). */
bool splat_mesh_obj(const char *path, splat_mesh *m, char **err);
void splat_mesh_free(splat_mesh *m);

/* The most corners of one OBJ face: tinyobjloader triangulates a polygon
 * in time quadratic in its corners (100000 took 30 s), and no mesh within
 * the index limit needs a face this large. */
#define SPLAT_OBJ_MAX_FACE_CORNERS 1024
/* Check an OBJ file's text before it is parsed, so that nothing the limits
 * refuse is ever built: every number of a `v`, `vn` or `vt` line finite
 * (strtod reads "nan" and "inf", which tinyobjloader reads as 0), a `v`
 * coordinate within SPLAT_MAX_MESH_VALUE, at most SPLAT_MAX_MESH_INDICES
 * of each of `v`, `vn` and `vt` (no mesh within the limits can use more),
 * faces of at most SPLAT_OBJ_MAX_FACE_CORNERS corners, and the faces'
 * triangles within SPLAT_MAX_MESH_INDICES indices.  False with a
 * malloc'd "line N: ..." in *err. */
bool splat_obj_scan(const char *text, size_t len, char **err);

/* ---- mesh_obj.cpp ---------------------------------------------------------- */

/* An OBJ text's triangles as corners (3 per triangle), all malloc'd: pos
 * 3 floats a corner; nrm 3 (all 0 where the file gives none); uv 2 (NaN
 * where the file gives none).  `mtllib` is ignored. */
typedef struct splat_obj_corners {
    float   *pos, *nrm, *uv;
    uint32_t n;
} splat_obj_corners;
bool splat_obj_parse(const char *text, size_t len, splat_obj_corners *c, char **err);

#ifdef __cplusplus
}
#endif

#endif
