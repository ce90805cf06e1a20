/* stand_in.h — the screen path's stand-ins (issue 29, first picture;
 * runtime/DESIGN.md "Stand-ins", PACK.md "Stand-ins"): while async
 * pipelines are made, tiles whose composite is not made yet are shaded by
 * the flat stand-in (the lit terrain in one neutral albedo) or the far
 * atlas's shader.  Both are the über-shader's compute GLSL cut at
 * SPLAT_GLSL_PRELUDE (abi.c) around a main of their own.  `splatc build`
 * compiles them into the pack ("uber": {"stand_in": …}); the runtime
 * assembles the same text for a pack without them and for the variants
 * with a `#define` added (counting), so both sides use this one source. */
#ifndef SPLAT_STAND_IN_H
#define SPLAT_STAND_IN_H

typedef enum splat_stand_in_kind {
    SPLAT_STAND_IN_FLAT,    /* the flat stand-in: splat_finish over the
                               terrain's own normal, one neutral albedo  */
    SPLAT_STAND_IN_ATLAS,   /* the far atlas's shader: albedo, normal and
                               roughness from the atlas at set 2 bindings
                               5-7 (far_atlas.h)                          */
    SPLAT_STAND_IN_KINDS
} splat_stand_in_kind;

/* Its manifest key under "uber"."stand_in" ("flat", "atlas") and its pack
 * file ("shaders/flat_stand_in.comp.spv.zst" as written). */
const char *splat_stand_in_name(splat_stand_in_kind k);
const char *splat_stand_in_file(splat_stand_in_kind k);

/* The main of stand-in k (the GLSL after the prelude). */
const char *splat_stand_in_main(splat_stand_in_kind k);

/* `uber` (an über-shader's GLSL, compute or fragment) cut at the prelude:
 * "#version 450\n", its head (the defines before the prelude: painted
 * storage and places, so set 0 is declared as the composites declare
 * it), then `defs` (e.g. "#define SPLAT_COUNT 1\n"), SPLAT_GLSL_PRELUDE
 * and `main_text`.  malloc'd; NULL where `uber` is NULL or holds no
 * "#version 450" line followed by the prelude, or out of memory. */
char *splat_prelude_source(const char *uber, const char *defs, const char *main_text);

/* splat_prelude_source(uber_compute, defs, splat_stand_in_main(k)). */
char *splat_stand_in_glsl(splat_stand_in_kind k, const char *uber_compute, const char *defs);

#endif
