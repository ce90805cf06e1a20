/* render_plan.h — the frame as a plan: a list of passes, each declaring
 * the images and buffers it reads and writes (stage, access, layout).
 * render_plan.c makes the plan from the renderer's state; render_track.c
 * keeps the plan's passes and derives the barriers between them from the
 * declarations (rt_tracker); render_record.c records each pass.
 * Runtime-internal. */
#ifndef SPLAT_RENDER_PLAN_H
#define SPLAT_RENDER_PLAN_H
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <vulkan/vulkan.h>

/* What the passes read and write.  The images keep their layout between
 * frames (the tracker remembers it); RT_RES_FRAME is host-written before
 * the submission, which makes it visible (no barrier). */
#define RT_RESOURCES(X)                                                              \
    X(FRAME,        "frame",        "the frame block (uniform, host-written)")      \
    X(HEIGHT,       "height",       "the heightfield image (craters lower it)")     \
    X(DESTRUCTION,  "destruction",  "the crater atlas and its index")               \
    X(SHADOW,       "shadow",       "the sun's shadow map")                         \
    X(FAR,          "far-atlas",    "the far atlas (read only)")                    \
    X(COLOR,        "color",        "the RGBA32F target")                           \
    X(DEPTH,        "depth",        "the D32 depth target")                         \
    X(GBUFFER,      "gbuffer",      "the multi-pass reference's three targets")     \
    X(RAYDEPTH,     "ray-depth",    "the ray caster's depth (R32F storage)")        \
    X(TILES,        "tiles",        "the screen path's tile lists, arguments, counters") \
    X(TILES_HOST,   "tiles-host",   "their copy for the host")                      \
    X(COUNTERS,     "counters",     "the forward path's counters (device)")         \
    X(COUNTERS_HOST, "counters-host", "their copy for the host")                    \
    X(UG,           "undergrowth",  "the undergrowth's cells, instances, arguments") \
    X(OUTPUT,       "output",       "the full-size picture (preview scale)")        \
    X(READBACK,     "readback",     "the target's copy for the host")

typedef enum rt_resource {
#define X(id, name, what) RT_RES_##id,
    RT_RESOURCES(X)
#undef X
    RT_RES_COUNT
} rt_resource;

/* The passes, in the order a frame can hold them. */
#define RT_PASSES(X)                                                                  \
    X(SHADOW,      "shadow update",      "the shadow map, when the sun moved or a crater landed (its own submission)") \
    X(DESTRUCTION, "destruction upload", "the crater table into the frame block") \
    X(UG_GENERATE, "undergrowth generation", "new cells' instances, every cell's LOD") \
    X(DEPTH,       "depth",              "the patches, depth only (screen path)") \
    X(RAYCAST,     "depth (ray cast)",   "the heightfield ray cast (screen path)") \
    X(TILES_RESET, "tile lists reset",   "the lists' arguments and counters zeroed") \
    X(CLASSIFY,    "classification",     "tiles into lists by layer set; the background") \
    X(SHADE,       "shading",            "one indirect dispatch per list") \
    X(SHADE_FAR,   "far",                "the far list from the far atlas") \
    X(TILE_COUNTS, "tile counts",        "the lists' sizes and counters to the host") \
    X(COUNT_RESET, "counters reset",     "the forward counting variant's counters zeroed") \
    X(FORWARD,     "forward",            "each combination's patches with its composite") \
    X(FAR,         "far",                "the far group from the far atlas") \
    X(UBER,        "uber",               "patches no combination covers, über-shaded") \
    X(SKY,         "sky",                "the analytic sky where no terrain is") \
    X(MULTIPASS,   "multipass",          "every material blended over every patch") \
    X(RESOLVE,     "resolve",            "the blended surface lit") \
    X(COUNT_READ,  "counters read",      "the counters to the host") \
    X(DEPTH_COPY,  "depth copy",         "the ray-cast depth into the depth target") \
    X(UG_DRAW,     "undergrowth draw",   "the visible cells' plants and contact shadows") \
    X(UPSCALE,     "upscale",            "the preview scale's target to the full size") \
    X(READBACK,    "readback",           "the target to the host")

typedef enum rt_pass_kind {
#define X(id, name, what) RT_PASS_##id,
    RT_PASSES(X)
#undef X
    RT_PASS_KINDS
} rt_pass_kind;

enum { RT_PLAN_MAX_PASSES = 24, RT_PASS_MAX_USES = 10 };

/* One declared access. */
typedef struct rt_use {
    uint8_t              res;      /* rt_resource                                  */
    bool                 write;
    VkPipelineStageFlags stage;
    VkAccessFlags        access;
    VkImageLayout        layout;   /* needed at the start; UNDEFINED: any (the
                                      pass's render pass moves it, or the pass
                                      writes it whole: `discard`)             */
    VkImageLayout        after;    /* left at the end; UNDEFINED: as it was   */
    bool                 discard;  /* the old contents are not read           */
} rt_use;

typedef struct rt_pass {
    rt_pass_kind kind;
    bool         host;             /* CPU work (and its own submission)       */
    bool         own;              /* recorded in a command buffer of its own
                                      (readback: rt_renderer_read)            */
    int          group;            /* > 0: one barrier before the neighbours
                                      of the same group, none between them;
                                      1: the main render pass                 */
    int          nuse;
    rt_use       use[RT_PASS_MAX_USES];
    int          query;            /* its timestamp's query (0: none)        */
    double       gpu_ms;           /* after the frame, with timestamps; < 0  */
} rt_pass;

typedef struct rt_plan {
    const char *path;              /* "forward", "screen", "multipass"       */
    int         width, height;
    int         npasses;
    int         barriers;          /* the tracker recorded for them      */
    rt_pass     pass[RT_PLAN_MAX_PASSES];
} rt_plan;

/* The state of each resource between passes (and frames): the last
 * write not yet made visible, the reads since it, the layout. */
typedef struct rt_res_state {
    VkPipelineStageFlags write_stage, read_stages, visible_stages;
    VkAccessFlags        write_access, visible_access;
    VkImageLayout        layout;
} rt_res_state;

typedef struct rt_tracker {
    rt_res_state res[RT_RES_COUNT];
    VkImage      image[RT_RES_COUNT];   /* VK_NULL_HANDLE: a buffer        */
    VkImageAspectFlags aspect[RT_RES_COUNT];
    VkImageLayout rest[RT_RES_COUNT];   /* the layout between frames, or 0 */
    bool         host_read[RT_RES_COUNT];
    int          barriers;              /* recorded this frame (stats)    */
    bool         off;                   /* SPLAT_PLAN_BARRIERS=0 (tests)  */
} rt_tracker;

const char *rt_pass_name(rt_pass_kind k);
const char *rt_res_name(rt_resource r);

/* Passes: appended in order by render_plan.c's builder; the readback
 * pass alone (rt_renderer_read). */
void rt_plan_readback(rt_plan *pl, bool scaled);
rt_pass *rt_plan_add(rt_plan *pl, rt_pass_kind k);
void rt_pass_use(rt_pass *p, rt_resource res, bool write, VkPipelineStageFlags stage,
                 VkAccessFlags access, VkImageLayout layout, VkImageLayout after);

/* Colour is the one image whose layout the tracker moves (the screen
 * path's storage writes, the undergrowth's and readback's needs). */
void rt_tracker_init(rt_tracker *t, VkImage color);
/* The barrier passes [first, last] need before they run (one call for
 * the passes of one render pass), recorded into cb; then the tracker
 * takes their accesses as done. */
void rt_tracker_before(rt_tracker *t, VkCommandBuffer cb, const rt_pass *first, int n);
/* A write outside the frame's command buffer (a crater, a shadow map):
 * the next reader waits for it. */
void rt_tracker_written(rt_tracker *t, rt_resource res, VkPipelineStageFlags stage,
                        VkAccessFlags access);
/* The end of a command buffer: host reads made visible, images back in
 * their resting layouts. */
void rt_tracker_finish(rt_tracker *t, VkCommandBuffer cb);

/* The plan as text, one pass a line (with GPU times when `times`). */
void rt_plan_print(const rt_plan *pl, FILE *out, bool times);

#endif
