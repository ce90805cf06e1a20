/* overlay.c — the viewer's on-screen help (key H): a box at the top left
 * naming the keys and the current view, shading path, frame rate and the
 * shaders still compiling, drawn on the GPU after the tone map.
 *
 * The text is laid out on the CPU by stb_easy_font (Sean Barrett's public
 * domain bitmap font: each glyph a few axis-aligned quads, so there is no
 * font texture), each quad turned into two triangles of { pixel x, y,
 * RGBA8 colour }, behind them one dark translucent quad for the box.  One
 * small graphics pipeline draws them alpha-blended (SRC_ALPHA,
 * ONE_MINUS_SRC_ALPHA) into a render pass of the caller's: the viewer's
 * swapchain pass, whose UNORM values are already display-encoded, so white
 * is 1.0.  Viewport and scissor are dynamic; the vertex shader maps pixels
 * to clip space through a push constant holding the target's size.
 *
 * `splatview --headless --overlay` draws the same text onto its tone-mapped
 * picture (rt_overlay_draw_rgba8): the picture is uploaded into an RGBA8
 * image, the pipeline draws into it (loadOp LOAD), and it is read back, so
 * the test sees what the window shows.
 */
#include "rt_internal.h"
#include "vk_build.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#include <stb_easy_font.h>
#pragma GCC diagnostic pop

static const char overlay_vert[] =
    "#version 450\n"
    "layout(location = 0) in vec2 i_pos;\n"
    "layout(location = 1) in vec4 i_color;\n"
    "layout(push_constant) uniform pc { vec2 size; } u_pc;\n"
    "layout(location = 0) out vec4 v_color;\n"
    "void main() {\n"
    "    gl_Position = vec4(i_pos / u_pc.size * 2.0 - 1.0, 0.0, 1.0);\n"
    "    v_color = i_color;\n"
    "}\n";

static const char overlay_frag[] =
    "#version 450\n"
    "layout(location = 0) in vec4 v_color;\n"
    "layout(location = 0) out vec4 o_color;\n"
    "void main() { o_color = v_color; }\n";

typedef struct vertex {
    float   x, y;
    uint8_t rgba[4];
} vertex;

struct rt_overlay {
    rt_device       *d;
    VkPipelineLayout layout;
    VkPipeline       pipeline;
    rt_buffer        vb;          /* host visible, persistently mapped    */
    uint32_t         nverts;      /* laid out by rt_overlay_layout        */
    rt_vk_list       keep;        /* layout and pipeline                  */
};

void rt_overlay_text(const rt_overlay_info *in, char *buf, size_t n)
{
    size_t k = 0;
#define PUT(...) \
    (k += (size_t)snprintf(buf + (k < n ? k : n), k < n ? n - k : 0, __VA_ARGS__))
    PUT("splatview %s                  H hides this\n", in->pack ? in->pack : "");
    PUT("view %s%s%s%s   path %s", rt_view_name(in->view), in->material ? " " : "",
        in->material ? in->material : "", in->wire ? " (wireframe)" : "",
        in->screen ? "screen" : "forward");
    if (in->frame_ms > 0)
        PUT("   %.1f ms  %.0f fps", in->frame_ms, 1e3 / in->frame_ms);
    PUT("   shaders pending %d\n", in->pending);
    if (in->status && in->status[0])
        PUT("%s\n", in->status);
    PUT("\n");
    /* the digit keys, from the views' own table (abi.h SPLAT_VIEWS) */
    int col = 0;
    for (int key = '1'; key <= '9'; key++) {
        int v = rt_view_by_key(key);
        if (v < 0)
            continue;
        PUT("%c %-13s%s", key, rt_view_name((splat_view)v), ++col % 5 == 0 ? "\n" : "");
    }
    if (col % 5)
        PUT("\n");
    PUT("  (7 again: the next material's mask)\n"
        "W A S D move   Space / Ctrl up, down   right button: look   wheel: speed\n"
        "F wireframe   G forward / screen   R rebuild   O shadows   U undergrowth\n"
        "J L turn the sun   I K raise, lower it   + - exposure   P preview scale\n"
        "left click: a crater   Q / Esc quit");
#undef PUT
}

bool rt_overlay_create(rt_device *d, VkRenderPass pass, rt_overlay **out, rt_error *e)
{
    rt_overlay *o = calloc(1, sizeof *o);
    if (!o)
        return rt_fail(e, RT_E_WINDOW, "out of memory");
    o->d = d;
    *out = o;
    VkVertexInputBindingDescription vb = { 0, sizeof(vertex), VK_VERTEX_INPUT_RATE_VERTEX };
    VkVertexInputAttributeDescription va[2] = {
        { 0, 0, VK_FORMAT_R32G32_SFLOAT, offsetof(vertex, x) },
        { 1, 0, VK_FORMAT_R8G8B8A8_UNORM, offsetof(vertex, rgba) },
    };
    VkPipelineColorBlendAttachmentState alpha = {
        .blendEnable = VK_TRUE,
        .srcColorBlendFactor = VK_BLEND_FACTOR_SRC_ALPHA,
        .dstColorBlendFactor = VK_BLEND_FACTOR_ONE_MINUS_SRC_ALPHA,
        .colorBlendOp = VK_BLEND_OP_ADD,
        .srcAlphaBlendFactor = VK_BLEND_FACTOR_ZERO,
        .dstAlphaBlendFactor = VK_BLEND_FACTOR_ONE,
        .alphaBlendOp = VK_BLEND_OP_ADD,
        .colorWriteMask = 0xf,
    };
    return rt_vk_layout(d, &o->keep, &(rt_vk_layout_desc){ .label = "overlay",
                            .push_stages = VK_SHADER_STAGE_VERTEX_BIT, .push_bytes = 8 },
                        &o->layout, e) &&
           rt_vk_gfx(d, &o->keep, &(rt_vk_gfx_desc){ .label = "overlay",
                         .vs_glsl = overlay_vert, .fs_glsl = overlay_frag,
                         .vbufs = &vb, .nvbufs = 1, .attrs = va, .nattrs = 2,
                         .ncolor = 1, .blend = &alpha, .layout = o->layout, .pass = pass },
                     &o->pipeline, e);
}

void rt_overlay_destroy(rt_overlay *o)
{
    if (!o)
        return;
    rt_device *d = o->d;
    rt_vk_list_destroy(d, &o->keep);
    rt_buffer_destroy(d, &o->vb);
    free(o);
}

/* The text's scale: stb_easy_font's glyphs are about 6 x 12 pixels, too
 * small to read on a large window. */
static float text_scale(uint32_t h) { return h >= 900 ? 2.0f : 1.0f; }

bool rt_overlay_layout(rt_overlay *o, const char *text, uint32_t w, uint32_t h, rt_error *e)
{
    size_t len = strlen(text);
    char *t = malloc(len + 1);
    /* stb_easy_font: at most about 270 bytes of quads per character (its
     * widest glyphs have under 17 segments of 4 vertices of 16 bytes) */
    size_t qbytes = (len + 1) * 300;
    float *q = malloc(qbytes);
    if (!t || !q) {
        free(t);
        free(q);
        return rt_fail(e, RT_E_WINDOW, "out of memory");
    }
    memcpy(t, text, len + 1);
    const float s = text_scale(h), pad = 6.0f, x0 = 8.0f, y0 = 8.0f;
    unsigned char white[4] = { 255, 255, 255, 255 };
    int nq = stb_easy_font_print(0, 0, t, white, q, (int)qbytes);
    float tw = (float)stb_easy_font_width(t) * s, th = (float)stb_easy_font_height(t) * s;
    free(t);
    uint32_t need = 6u * (uint32_t)(nq + 1);
    if (o->vb.size < need * sizeof(vertex)) {
        vkDeviceWaitIdle(o->d->dev);   /* the old buffer may still be read */
        rt_buffer_destroy(o->d, &o->vb);
        if (!rt_buffer_create(o->d, (VkDeviceSize)need * 2 * sizeof(vertex),
                              VK_BUFFER_USAGE_VERTEX_BUFFER_BIT, true, &o->vb, e)) {
            free(q);
            return false;
        }
    }
    vertex *v = o->vb.map;
    uint32_t k = 0;
    /* the box: dark, 65 % opaque */
    float bx0 = x0 - pad, by0 = y0 - pad, bx1 = x0 + tw + pad, by1 = y0 + th + pad;
    if (bx1 > (float)w) bx1 = (float)w;
    if (by1 > (float)h) by1 = (float)h;
    const float box[4][2] = { { bx0, by0 }, { bx1, by0 }, { bx1, by1 }, { bx0, by1 } };
    static const int tri[6] = { 0, 1, 2, 0, 2, 3 };
    for (int i = 0; i < 6; i++)
        v[k++] = (vertex){ box[tri[i]][0], box[tri[i]][1], { 8, 10, 16, 166 } };
    for (int i = 0; i < nq; i++) {
        const float *quad = q + (size_t)i * 16;   /* 4 x { x, y, z, rgba } */
        for (int j = 0; j < 6; j++) {
            const float *p = quad + tri[j] * 4;
            vertex vx = { x0 + p[0] * s, y0 + p[1] * s, { 0 } };
            memcpy(vx.rgba, &p[3], 4);
            v[k++] = vx;
        }
    }
    free(q);
    o->nverts = k;
    return true;
}

void rt_overlay_record(rt_overlay *o, VkCommandBuffer cb, uint32_t w, uint32_t h)
{
    if (!o->nverts)
        return;
    VkViewport vp = { 0, 0, (float)w, (float)h, 0, 1 };
    VkRect2D sc = { { 0, 0 }, { w, h } };
    float size[2] = { (float)w, (float)h };
    VkDeviceSize off = 0;
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, o->pipeline);
    vkCmdSetViewport(cb, 0, 1, &vp);
    vkCmdSetScissor(cb, 0, 1, &sc);
    vkCmdPushConstants(cb, o->layout, VK_SHADER_STAGE_VERTEX_BIT, 0, sizeof size, size);
    vkCmdBindVertexBuffers(cb, 0, 1, &o->vb.buf, &off);
    vkCmdDraw(cb, o->nverts, 1, 0, 0);
}

bool rt_overlay_draw_rgba8(rt_device *d, const char *text, uint8_t *rgba, int w, int h,
                           rt_error *e)
{
    VkRenderPass pass = VK_NULL_HANDLE;
    VkFramebuffer fb = VK_NULL_HANDLE;
    rt_overlay *o = NULL;
    rt_image img = { 0 };
    rt_buffer buf = { 0 };
    VkDeviceSize bytes = (VkDeviceSize)w * (VkDeviceSize)h * 4;
    rt_vk_list keep = { 0 };
    const VkImageLayout att = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
    bool ok = rt_vk_pass(d, &keep, &(rt_vk_pass_desc){ .label = "overlay",
                             .color = { { .format = VK_FORMAT_R8G8B8A8_UNORM,
                                          .initial = att, .final = att } }, .ncolor = 1 },
                         &pass, e) &&
              rt_overlay_create(d, pass, &o, e) &&
         rt_overlay_layout(o, text, (uint32_t)w, (uint32_t)h, e) &&
         rt_image_create(d, (uint32_t)w, (uint32_t)h, 1, false, 1, VK_FORMAT_R8G8B8A8_UNORM,
                         VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT |
                             VK_IMAGE_USAGE_TRANSFER_DST_BIT,
                         VK_IMAGE_ASPECT_COLOR_BIT, &img, e) &&
         rt_buffer_create(d, bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT |
                                        VK_BUFFER_USAGE_TRANSFER_DST_BIT, true, &buf, e);
    ok = ok && rt_vk_fb(d, &keep, &(rt_vk_fb_desc){ .label = "overlay", .pass = pass,
                                 .views = &img.view, .nviews = 1, .width = (uint32_t)w,
                                 .height = (uint32_t)h }, &fb, e);
    VkCommandBuffer cb;
    if (ok && (ok = rt_oneshot_begin(d, &cb, e))) {
        memcpy(buf.map, rgba, (size_t)bytes);
        VkBufferImageCopy copy = {
            .imageSubresource = { VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1 },
            .imageExtent = { (uint32_t)w, (uint32_t)h, 1 },
        };
        rt_cmd_image_barrier(cb, img.img, 0, 1, 1, VK_IMAGE_LAYOUT_UNDEFINED,
                             VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 0, VK_ACCESS_TRANSFER_WRITE_BIT,
                             VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT);
        vkCmdCopyBufferToImage(cb, buf.buf, img.img, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1,
                               &copy);
        rt_cmd_image_barrier(cb, img.img, 0, 1, 1, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                             VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_ACCESS_TRANSFER_WRITE_BIT,
                             VK_ACCESS_COLOR_ATTACHMENT_READ_BIT |
                                 VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT,
                             VK_PIPELINE_STAGE_TRANSFER_BIT,
                             VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT);
        VkRenderPassBeginInfo rb = {
            .sType = VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO, .renderPass = pass,
            .framebuffer = fb, .renderArea = { { 0, 0 }, { (uint32_t)w, (uint32_t)h } },
        };
        vkCmdBeginRenderPass(cb, &rb, VK_SUBPASS_CONTENTS_INLINE);
        rt_overlay_record(o, cb, (uint32_t)w, (uint32_t)h);
        vkCmdEndRenderPass(cb);
        rt_cmd_image_barrier(cb, img.img, 0, 1, 1, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                             VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                             VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT, VK_ACCESS_TRANSFER_READ_BIT,
                             VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT,
                             VK_PIPELINE_STAGE_TRANSFER_BIT);
        vkCmdCopyImageToBuffer(cb, img.img, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, buf.buf, 1,
                               &copy);
        rt_cmd_barrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                       VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_HOST_READ_BIT);
        ok = rt_oneshot_end(d, cb, e);
        if (ok)
            memcpy(rgba, buf.map, (size_t)bytes);
    }
    rt_overlay_destroy(o);
    rt_vk_list_destroy(d, &keep);
    rt_image_destroy(d, &img);
    rt_buffer_destroy(d, &buf);
    return ok;
}
