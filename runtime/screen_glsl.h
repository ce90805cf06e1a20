/* screen_glsl.h — the screen-space path's own compute shaders
 * (screen_glsl.c).  screen.c's own_pipeline puts before each a head of
 * #defines, SPLAT_GLSL_TERRAIN and SPLAT_GLSL_SKY.  Internal to the
 * runtime. */
#ifndef SPLAT_SCREEN_GLSL_H
#define SPLAT_SCREEN_GLSL_H

/* WORDS, SLACK, and WIDE or AGGREGATE */
extern const char rt_screen_classify_glsl[];
/* G (tiles per sorting workgroup) */
extern const char rt_screen_group_glsl[];
/* TOP, PW, PH (the height pyramid) */
extern const char rt_screen_raycast_glsl[];

#endif
