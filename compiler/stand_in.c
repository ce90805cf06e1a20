/* stand_in.c — the stand-ins' GLSL (stand_in.h), for `splatc build`
 * (build_jobs.c: their SPIR-V in the pack) and the runtime (far.c: the
 * fallback for a pack without it, the counting variants, and the forward
 * path's far fragment shader). */
#include "stand_in.h"

#include <stdlib.h>
#include <string.h>

#include "abi.h"

/* Set 2 bindings 5-7: the screen path's classification set with the
 * atlas (runtime/screen.c), the forward path's own (runtime/far.c).  The
 * pixel's own gradients (FC5's plane-through-the-pixel derivatives, as
 * the composites take theirs), splat_finish: the same lighting, fog and
 * views as the composites, from three samples. */
static const char far_main[] =
    "layout(set = 2, binding = 5) uniform sampler2D u_far_albedo;\n"
    "layout(set = 2, binding = 6) uniform sampler2D u_far_normal;\n"
    "layout(set = 2, binding = 7) uniform sampler2D u_far_rough;\n"
    "void main() {\n"
    "    vec2 gx = splat_dpdx.xz / u_frame.terrain.xy, gy = splat_dpdy.xz / u_frame.terrain.xy;\n"
    "    vec3 albedo = textureGrad(u_far_albedo, v_uv, gx, gy).rgb;\n"
    "    vec2 nxz = textureGrad(u_far_normal, v_uv, gx, gy).rg * 2.0 - 1.0;\n"
    "    vec3 n = vec3(nxz.x, sqrt(max(1.0 - dot(nxz, nxz), 0.0)), nxz.y);\n"
    "    float rough = textureGrad(u_far_rough, v_uv, gx, gy).r;\n"
    "    splat_count_samples(3u);\n"
    "    splat_finish(albedo, n, rough, 0.0, 1.0);\n"
    "}\n";

/* The flat stand-in's main: the terrain's own normal from the heightfield
 * (splat_begin_at's splat_nrm), lit, fogged and toned as the composites
 * are, over one neutral albedo (a warm mid grey): the default material
 * that Unreal shows while shaders compile, at the cost of a handful of
 * instructions.  One tint for all: a tint per combination showed the
 * classification's 8x8 tiles as a patchwork. */
static const char flat_main[] =
    "void main() {\n"
    "    splat_finish(vec3(0.20, 0.19, 0.17), splat_nrm, 0.9, 0.0, 1.0);\n"
    "}\n";

const char *splat_stand_in_name(splat_stand_in_kind k)
{
    return k == SPLAT_STAND_IN_ATLAS ? "atlas" : "flat";
}

const char *splat_stand_in_file(splat_stand_in_kind k)
{
    return k == SPLAT_STAND_IN_ATLAS ? "shaders/atlas_stand_in.comp" : "shaders/flat_stand_in.comp";
}

const char *splat_stand_in_main(splat_stand_in_kind k)
{
    return k == SPLAT_STAND_IN_ATLAS ? far_main : flat_main;
}

char *splat_prelude_source(const char *uber, const char *defs, const char *main_text)
{
    static const char version[] = "#version 450\n";
    const char *v = uber ? strstr(uber, version) : NULL;
    const char *at = v ? strstr(v, SPLAT_GLSL_PRELUDE) : NULL;
    if (!at)
        return NULL;
    v += strlen(version);
    size_t head = (size_t)(at - v);
    size_t n = strlen(version) + head + strlen(defs) + strlen(SPLAT_GLSL_PRELUDE) +
               strlen(main_text) + 1;
    char *s = malloc(n);
    if (!s)
        return NULL;
    const char *parts[4] = { defs, SPLAT_GLSL_PRELUDE, main_text, NULL };
    char *o = s;
    memcpy(o, version, strlen(version));
    o += strlen(version);
    memcpy(o, v, head);
    o += head;
    for (const char **q = parts; *q; q++) {
        size_t k = strlen(*q);
        memcpy(o, *q, k);
        o += k;
    }
    *o = '\0';
    return s;
}

char *splat_stand_in_glsl(splat_stand_in_kind k, const char *uber_compute, const char *defs)
{
    return splat_prelude_source(uber_compute, defs, splat_stand_in_main(k));
}
