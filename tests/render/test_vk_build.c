/* test_vk_build.c — the runtime's Vulkan builder (runtime/vk_build.c) on
 * the device, with SPLAT_VALIDATE=1 (any validation message fails):
 *   - a sampler, a set layout, a pipeline layout with push constants, a
 *     render pass of one RGBA8 colour and a D32 depth attachment (cleared),
 *     its framebuffer, a graphics pipeline from GLSL with every other
 *     field at its default (triangle list, fill, no culling, dynamic
 *     viewport and scissor, no blending), a compute pipeline from GLSL and
 *     a pool with its set, all made into one destroy list;
 *   - one draw through them writes the push constant's colour where the
 *     triangle covers the target and leaves the clear colour elsewhere
 *     (so the descs' defaults make a pipeline that draws);
 *   - a compute shader that does not compile fails with the label in the
 *     message and adds nothing to the list;
 *   - rt_vk_list_destroy empties the list, and the device's teardown finds
 *     nothing left alive (the validation layer reports leaked objects).
 *
 *   test_vk_build */
#include "rt_internal.h"
#include "vk_build.h"
#include "kit.h"

#include <string.h>

enum { W = 16, H = 16 };

static const char vs[] =
    "#version 450\n"
    "void main() {\n"   /* on the middle row: x from -1 to -0.25 */
    "    vec2 p[3] = vec2[](vec2(-1.0, -1.0), vec2(0.0, -1.0), vec2(-1.0, 3.0));\n"
    "    gl_Position = vec4(p[gl_VertexIndex], 0.5, 1.0);\n"
    "}\n";
static const char fs[] =
    "#version 450\n"
    "layout(push_constant) uniform P { vec4 colour; } u_p;\n"
    "layout(location = 0) out vec4 o;\n"
    "void main() { o = u_p.colour; }\n";
static const char cs_ok[] =
    "#version 450\nlayout(local_size_x = 1) in;\n"
    "layout(set = 0, binding = 0) uniform sampler2D u_t;\n"
    "void main() {}\n";
static const char cs_bad[] = "#version 450\nvoid main() { this is not glsl }\n";

typedef struct objects {
    VkSampler             smp;
    VkDescriptorSetLayout sl;
    VkPipelineLayout      layout, clayout;
    VkRenderPass          pass;
    VkFramebuffer         fb;
    VkPipeline            gfx, comp;
    VkDescriptorPool      pool;
    VkDescriptorSet       set;
} objects;

static bool make(rt_device *d, rt_vk_list *k, const rt_image *color, const rt_image *depth,
                 objects *o, rt_error *e)
{
    VkDescriptorSetLayoutBinding b = { 0, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1,
                                       VK_SHADER_STAGE_COMPUTE_BIT, NULL };
    VkDescriptorPoolSize size = { VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1 };
    VkImageView views[2] = { color->view, depth->view };
    /* the colour's writes and its move to TRANSFER_SRC before the copy */
    static const VkSubpassDependency to_copy = {
        0, VK_SUBPASS_EXTERNAL, VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT,
        VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT,
        VK_ACCESS_TRANSFER_READ_BIT, 0 };
    return rt_vk_sampler(d, k, &(rt_vk_sampler_desc){ .label = "test" }, &o->smp, e) &&
           rt_vk_set_layout(d, k, &(rt_vk_set_layout_desc){ "test", &b, 1 }, &o->sl, e) &&
           rt_vk_layout(d, k, &(rt_vk_layout_desc){ .label = "test",
                            .push_stages = VK_SHADER_STAGE_FRAGMENT_BIT, .push_bytes = 16 },
                        &o->layout, e) &&
           rt_vk_layout(d, k, &(rt_vk_layout_desc){ .label = "test compute", .sets = &o->sl,
                            .nsets = 1 }, &o->clayout, e) &&
           rt_vk_pass(d, k, &(rt_vk_pass_desc){ .label = "test",
                          .color = { { .format = VK_FORMAT_R8G8B8A8_UNORM,
                                       .load = VK_ATTACHMENT_LOAD_OP_CLEAR,
                                       .final = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL } },
                          .ncolor = 1,
                          .depth = { .format = VK_FORMAT_D32_SFLOAT,
                                     .load = VK_ATTACHMENT_LOAD_OP_CLEAR,
                                     .store = VK_ATTACHMENT_STORE_OP_DONT_CARE,
                                     .final = VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL },
                          .deps = &to_copy, .ndeps = 1 },
                      &o->pass, e) &&
           rt_vk_fb(d, k, &(rt_vk_fb_desc){ .label = "test", .pass = o->pass, .views = views,
                        .nviews = 2, .width = W, .height = H }, &o->fb, e) &&
           rt_vk_gfx(d, k, &(rt_vk_gfx_desc){ .label = "test", .vs_glsl = vs, .fs_glsl = fs,
                         .depth_test = true, .depth_write = true,
                         .depth_compare = VK_COMPARE_OP_GREATER, .ncolor = 1,
                         .layout = o->layout, .pass = o->pass }, &o->gfx, e) &&
           rt_vk_compute(d, k, &(rt_vk_compute_desc){ .label = "test compute", .glsl = cs_ok,
                             .layout = o->clayout }, &o->comp, e) &&
           rt_vk_sets(d, k, &(rt_vk_sets_desc){ .label = "test", .sizes = &size, .nsizes = 1,
                          .layouts = &o->sl, .nsets = 1 }, &o->pool, &o->set, e);
}

/* One draw into the target, read back into buf. */
static bool draw(rt_device *d, const objects *o, const rt_image *color, rt_buffer *buf,
                 rt_error *e)
{
    VkCommandBuffer cb;
    if (!rt_oneshot_begin(d, &cb, e))
        return false;
    VkClearValue clear[2] = { { .color = { { 0.0f, 0.0f, 1.0f, 1.0f } } },
                              { .depthStencil = { 0.0f, 0 } } };
    VkRenderPassBeginInfo rb = {
        .sType = VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO, .renderPass = o->pass,
        .framebuffer = o->fb, .renderArea = { { 0, 0 }, { W, H } },
        .clearValueCount = 2, .pClearValues = clear,
    };
    vkCmdBeginRenderPass(cb, &rb, VK_SUBPASS_CONTENTS_INLINE);
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, o->gfx);
    VkViewport vp = { 0, 0, W, H, 0, 1 };
    VkRect2D sc = { { 0, 0 }, { W, H } };
    vkCmdSetViewport(cb, 0, 1, &vp);
    vkCmdSetScissor(cb, 0, 1, &sc);
    float colour[4] = { 1.0f, 0.5f, 0.0f, 1.0f };
    vkCmdPushConstants(cb, o->layout, VK_SHADER_STAGE_FRAGMENT_BIT, 0, sizeof colour, colour);
    vkCmdDraw(cb, 3, 1, 0, 0);
    vkCmdEndRenderPass(cb);
    VkBufferImageCopy copy = {
        .imageSubresource = { VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1 },
        .imageExtent = { W, H, 1 },
    };
    vkCmdCopyImageToBuffer(cb, color->img, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, buf->buf, 1,
                           &copy);
    rt_cmd_barrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                   VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_HOST_READ_BIT);
    return rt_oneshot_end(d, cb, e);
}

int main(void)
{
    rt_device d;
    rt_error e = { 0 };
    if (!rt_device_create(&d, &(rt_device_desc){ .validate = true }, &e)) {
        fprintf(stderr, "test_vk_build: %s\n", e.msg);
        return 1;
    }
    rt_image color = { 0 }, depth = { 0 };
    rt_buffer buf = { 0 };
    rt_vk_list keep = { 0 };
    objects o = { 0 };
    bool ok = rt_image_create(&d, W, H, 1, false, 1, VK_FORMAT_R8G8B8A8_UNORM,
                              VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT |
                                  VK_IMAGE_USAGE_SAMPLED_BIT,
                              VK_IMAGE_ASPECT_COLOR_BIT, &color, &e) &&
              rt_image_create(&d, W, H, 1, false, 1, VK_FORMAT_D32_SFLOAT,
                              VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT,
                              VK_IMAGE_ASPECT_DEPTH_BIT, &depth, &e) &&
              rt_buffer_create(&d, W * H * 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT, true, &buf, &e) &&
              make(&d, &keep, &color, &depth, &o, &e);
    CHECK(ok, "%s", e.msg ? e.msg : "");
    CHECK(keep.n == 9, "%d handles in the list, 9 made", keep.n);
    if (ok) {
        rt_vk_write_sets(&d, &(rt_vk_write){ .set = o.set,
                                             .type = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
                                             .sampler = o.smp, .view = color.view,
                                             .layout = VK_IMAGE_LAYOUT_GENERAL }, 1);
        CHECK(draw(&d, &o, &color, &buf, &e), "%s", e.msg ? e.msg : "");
        const uint8_t *px = buf.map;
        const uint8_t *in = px + (H / 2 * W + 2) * 4, *out = px + (H / 2 * W + W - 3) * 4;
        CHECK(in[0] == 255 && in[1] >= 127 && in[1] <= 128 && in[2] == 0 && in[3] == 255,
              "covered pixel %d %d %d %d, want 255 128 0 255", in[0], in[1], in[2], in[3]);
        CHECK(out[0] == 0 && out[1] == 0 && out[2] == 255 && out[3] == 255,
              "uncovered pixel %d %d %d %d, want the clear 0 0 255 255", out[0], out[1], out[2],
              out[3]);
    }
    /* a failure: false, the label in the message, nothing added */
    int before = keep.n;
    VkPipeline bad = VK_NULL_HANDLE;
    rt_error be = { 0 };
    CHECK(!rt_vk_compute(&d, &keep, &(rt_vk_compute_desc){ .label = "broken.comp",
                                                           .glsl = cs_bad,
                                                           .layout = o.clayout },
                         &bad, &be), "a shader that does not compile made a pipeline");
    CHECK(be.msg && strstr(be.msg, "broken.comp"), "message: %s", be.msg ? be.msg : "(none)");
    CHECK(keep.n == before && !bad, "the failed pipeline is in the list");
    rt_error_clear(&be);
    rt_vk_list_destroy(&d, &keep);
    CHECK(keep.n == 0 && keep.v == NULL, "the list is not empty after rt_vk_list_destroy");
    rt_buffer_destroy(&d, &buf);
    rt_image_destroy(&d, &color);
    rt_image_destroy(&d, &depth);
    rt_error_clear(&e);
    rt_device_destroy(&d);
    CHECK(rt_device_messages(&d) == 0, "%d validation message(s)", rt_device_messages(&d));
    return kit_finish("test_vk_build");
}
