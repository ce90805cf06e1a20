/* shader.h — whole GLSL fragment shaders around the IR's emitter (glsl.c):
 * the material set's resource declarations (shared with the composite
 * writer) and the single-material shader of `splatc glsl`.
 */
#ifndef SPLAT_SHADER_H
#define SPLAT_SHADER_H

#include "ir.h"

/* ---- shader.c ---------------------------------------------------------- */

/* How the ir's tables read in GLSL, as filled by glsl_declare_resources. */
typedef struct glsl_resources {
    char     **param;    /* per param: "u_params.cliff_wetness.x"           */
    char     **texture;  /* per texture: "t_tex0"                            */
    char     **painted;  /* per painted mask: "splat_painted(2)"             */
    glsl_names names;    /* the three arrays above, for glsl_emitter_new     */
} glsl_resources;

/* Write the material set's declarations for every param and texture of
 * `ir`: the uniform block `splat_params` at set 1 binding 0 (std140, one
 * vec4 slot per param in ir.params order, members named after the
 * qualified param: "cliff.wetness" -> cliff_wetness, made unique) as
 * `u_params`, and texture i as `layout(set=1, binding=1+i) uniform
 * sampler2D t_tex<i>;`.  Painted mask i reads splat_painted(layer[i])
 * (`painted_layer` NULL: layer i).  Fills `res` (free it with
 * glsl_resources_free). */
void glsl_declare_resources(const ir *ir, const int *painted_layer, ir_buf *out,
                            glsl_resources *res);
void glsl_resources_free(glsl_resources *res);

/* Lines for a shader's header comment ("//"-free, inside a block
 * comment, each starting with " * ") documenting those resources. */
void glsl_describe_resources(const ir *ir, const glsl_resources *res, ir_buf *out);

/* A complete Vulkan GLSL 450 fragment shader rendering material
 * `material` of `ir` (its roots "<material>.mask/albedo/normal/
 * roughness/height"; a missing root takes the material default) over the
 * terrain: #version, a header comment with the bindings, the ABI prelude,
 * the resources, and main() ending in splat_finish(). */
void glsl_material_shader(const ir *ir, const char *material, ir_buf *out);
/* The same for either stage: `compute` writes the compute variant (abi.h
 * "compute stage": #define SPLAT_COMPUTE before the prelude). */
void glsl_material_shader_stage(const ir *ir, const char *material, bool compute,
                                ir_buf *out);

#endif
