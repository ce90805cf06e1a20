/* render_track.c — the frame plan's generic half: passes appended with
 * their declared uses, the resource-state tracker that turns the
 * declarations into barriers (render_plan.c says how), and the plan as
 * text.  Knows nothing of the renderer. */
#include "render_plan.h"

#include <stdlib.h>
#include <string.h>

static const char *const pass_names[RT_PASS_KINDS] = {
#define X(id, name, what) [RT_PASS_##id] = name,
    RT_PASSES(X)
#undef X
};

static const char *const res_names[RT_RES_COUNT] = {
#define X(id, name, what) [RT_RES_##id] = name,
    RT_RESOURCES(X)
#undef X
};

const char *rt_pass_name(rt_pass_kind k)
{
    return (unsigned)k < RT_PASS_KINDS ? pass_names[k] : "?";
}

const char *rt_res_name(rt_resource r)
{
    return (unsigned)r < RT_RES_COUNT ? res_names[r] : "?";
}

/* ---- building ---------------------------------------------------------------- */

rt_pass *rt_plan_add(rt_plan *pl, rt_pass_kind k)
{
    /* RT_PLAN_MAX_PASSES is over the kinds: each appears at most once */
    rt_pass *p = &pl->pass[pl->npasses++];
    memset(p, 0, sizeof *p);
    p->kind = k;
    p->gpu_ms = -1;
    return p;
}

void rt_pass_use(rt_pass *p, rt_resource res, bool write, VkPipelineStageFlags stage,
                 VkAccessFlags access, VkImageLayout layout, VkImageLayout after)
{
    if (p->nuse == RT_PASS_MAX_USES)
        return;   /* the builder below declares fewer */
    p->use[p->nuse++] = (rt_use){ .res = (uint8_t)res, .write = write, .stage = stage,
                                  .access = access, .layout = layout, .after = after };
}

#include "render_sync.h"

/* ---- barriers ------------------------------------------------------------------ */

void rt_tracker_init(rt_tracker *t, VkImage color)
{
    memset(t, 0, sizeof *t);
    /* SPLAT_PLAN_BARRIERS=0: none (a test shows validation then speaks) */
    const char *env = getenv("SPLAT_PLAN_BARRIERS");
    t->off = env && !strcmp(env, "0");
    t->image[RT_RES_COLOR] = color;
    t->rest[RT_RES_COLOR] = SRC;   /* what the viewer blits and readback copies */
    t->host_read[RT_RES_COUNTERS_HOST] = true;
    t->host_read[RT_RES_TILES_HOST] = true;
    t->host_read[RT_RES_READBACK] = true;
}

typedef struct barrier {
    VkMemoryBarrier      mem;
    VkPipelineStageFlags src, dst;
    VkImageMemoryBarrier img[RT_RES_COUNT];
    int                  nimg;
} barrier;

static void add_image(barrier *b, const rt_tracker *t, rt_resource res, VkImageLayout from,
                      VkImageLayout to, VkAccessFlags sa, VkAccessFlags da)
{
    b->img[b->nimg++] = (VkImageMemoryBarrier){
        .sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER,
        .srcAccessMask = sa, .dstAccessMask = da, .oldLayout = from, .newLayout = to,
        .srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED,
        .dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED,
        .image = t->image[res],
        .subresourceRange = { VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1 },
    };
}

static void emit(rt_tracker *t, VkCommandBuffer cb, barrier *b)
{
    if ((!b->src && !b->nimg) || t->off)
        return;
    bool mem = b->mem.srcAccessMask || b->mem.dstAccessMask;
    b->mem.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
    vkCmdPipelineBarrier(cb, b->src ? b->src : VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT,
                         b->dst ? b->dst : VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, 0,
                         mem ? 1 : 0, &b->mem, 0, NULL, (uint32_t)b->nimg, b->img);
    t->barriers++;
}

/* What use `u` waits for, against the state before its group. */
static void need(const rt_tracker *t, const rt_use *u, barrier *b)
{
    const rt_res_state *s = &t->res[u->res];
    bool image = t->image[u->res] != VK_NULL_HANDLE;
    bool move = image && u->layout != NONE && u->layout != s->layout;
    VkPipelineStageFlags src = 0;
    VkAccessFlags sa = 0;
    if (u->write || move) {   /* after every earlier access */
        src = s->write_stage | s->read_stages;
        sa = s->write_access;
    } else if (s->write_access && ((s->visible_stages & u->stage) != u->stage ||
                                   (s->visible_access & u->access) != u->access)) {
        src = s->write_stage;
        sa = s->write_access;
    }
    if (move) {
        add_image(b, t, (rt_resource)u->res, u->discard ? NONE : s->layout, u->layout, sa,
                  u->access);
        b->src |= src;
        b->dst |= u->stage;
    } else if (src) {
        b->src |= src;
        b->dst |= u->stage;
        b->mem.srcAccessMask |= sa;
        b->mem.dstAccessMask |= u->access;
    }
}

static void done(rt_tracker *t, const rt_use *u)
{
    rt_res_state *s = &t->res[u->res];
    if (u->write) {
        s->write_stage = u->stage;
        s->write_access = u->access & WRITES;
        s->read_stages = 0;
        s->visible_stages = u->stage;   /* a pass sees its own writes */
        s->visible_access = u->access;
    } else {
        s->read_stages |= u->stage;
        s->visible_stages |= u->stage;
        s->visible_access |= u->access;
    }
    if (u->after != NONE)
        s->layout = u->after;
    else if (u->layout != NONE)
        s->layout = u->layout;
}

void rt_tracker_before(rt_tracker *t, VkCommandBuffer cb, const rt_pass *first, int n)
{
    barrier b;
    memset(&b, 0, sizeof b);
    for (int i = 0; i < n; i++)
        for (int k = 0; k < first[i].nuse; k++)
            if (!(first[i].use[k].stage & HOST))
                need(t, &first[i].use[k], &b);
    emit(t, cb, &b);
    for (int i = 0; i < n; i++)
        for (int k = 0; k < first[i].nuse; k++)
            if (!(first[i].use[k].stage & HOST))
                done(t, &first[i].use[k]);
}

void rt_tracker_written(rt_tracker *t, rt_resource res, VkPipelineStageFlags stage,
                        VkAccessFlags access)
{
    rt_res_state *s = &t->res[res];
    s->write_stage = stage;
    s->write_access = access & WRITES;
    s->read_stages = s->visible_stages = 0;
    s->visible_access = 0;
}

void rt_tracker_finish(rt_tracker *t, VkCommandBuffer cb)
{
    barrier b;
    memset(&b, 0, sizeof b);
    for (int r = 0; r < RT_RES_COUNT; r++) {
        rt_res_state *s = &t->res[r];
        if (t->host_read[r] && s->write_access && !(s->visible_stages & HOST)) {
            b.src |= s->write_stage;
            b.dst |= HOST;
            b.mem.srcAccessMask |= s->write_access;
            b.mem.dstAccessMask |= VK_ACCESS_HOST_READ_BIT;
            s->read_stages |= HOST;
            s->visible_stages |= HOST;
            s->visible_access |= VK_ACCESS_HOST_READ_BIT;
        }
        if (t->rest[r] && s->layout != t->rest[r] && s->layout != NONE) {
            /* for whoever reads it next: a blit, a copy, a sampler */
            VkPipelineStageFlags dst = XFER | FRAG;
            add_image(&b, t, (rt_resource)r, s->layout, t->rest[r], s->write_access, XREAD | SREAD);
            b.src |= s->write_stage | s->read_stages;
            b.dst |= dst;
            s->layout = t->rest[r];
            s->write_stage = 0;
            s->write_access = 0;
            s->read_stages = dst;
            s->visible_stages = s->visible_access = 0;
        }
    }
    emit(t, cb, &b);
}

/* ---- printing ------------------------------------------------------------------ */

static void print_uses(const rt_pass *p, bool write, FILE *out)
{
    int n = 0;
    for (int k = 0; k < p->nuse; k++) {
        const rt_use *u = &p->use[k];
        if (u->write != write)
            continue;
        bool again = false;   /* a resource read and written: once */
        for (int j = 0; j < k; j++)
            again |= p->use[j].res == u->res && p->use[j].write == write;
        if (again)
            continue;
        fprintf(out, "%s%s", n++ ? " " : "", rt_res_name((rt_resource)u->res));
        /* a write's layout after it, a read's before it */
        VkImageLayout l = u->after != NONE ? u->after : u->layout;
        if (l != NONE)
            fprintf(out, "(%s)", l == SRC ? "transfer-src" : l == RO ? "shader-read"
                                 : l == ATT ? "attachment" : l == GEN ? "general" : "?");
    }
    if (!n)
        fputc('-', out);
}

void rt_plan_print(const rt_plan *pl, FILE *out, bool times)
{
    fprintf(out, "plan: %s path, %dx%d, %d passes, %d barriers\n", pl->path, pl->width,
            pl->height, pl->npasses, pl->barriers);
    for (int i = 0; i < pl->npasses; i++) {
        const rt_pass *p = &pl->pass[i];
        fprintf(out, "  %2d %-22s %-5s", i + 1, rt_pass_name(p->kind),
                p->host ? "host" : p->own ? "own" : p->group == 1 ? "rp" : p->group ? "group" : "");
        if (times) {
            if (p->gpu_ms >= 0)
                fprintf(out, " %8.3f ms", p->gpu_ms);
            else
                fprintf(out, " %11s", "-");
        }
        fputs("  reads ", out);
        print_uses(p, false, out);
        fputs("  writes ", out);
        print_uses(p, true, out);
        fputc('\n', out);
    }
}
