/* viewer.c — splatview's window: the renderer's RGBA32F frame tone-mapped
 * into a GLFW/Vulkan swapchain, a fly camera, debug views on number keys,
 * wireframe, frame time in the title, and hot reload of the scene's graph
 * files through libsplatc (splat_build in process, then the combination
 * pipelines swapped; compile errors go to the console and the title, the
 * old pipelines stay).
 *
 * Keys: W/A/S/D move, Space/Ctrl up/down, mouse with the right button
 * held looks around, wheel changes speed, 1 final, 2 combinations, 3 LOD,
 * 4 normal, 5 slope, 6 albedo, 7 mask (again: next material), 8 tiles,
 * 9 cost, 0 layers, F wireframe, G forward / screen-space shading, R rebuild now,
 * J/L/I/K the sun, +/- exposure, O shadows, U undergrowth, P the preview
 * scale (1, 1/2, 1/4: upscale.c), H the on-screen
 * help (overlay.c: these keys, the view, path, frame rate and shaders
 * still compiling), Q/Escape quit, left click: a crater there
 * (destruction.c).
 *
 * --script runs without a person: "frames=N" renders N frames,
 * "view=NAME", "key=K" acts as if K was pressed, "screenshot=FILE" writes
 * the swapchain image as the window shows it (after the pipelines being
 * made on the workers: the final picture, not a stand-in's), "wait_reload=SECONDS" renders
 * until a hot reload succeeded (compile errors on the way are shown and
 * survived; the time running out fails the script), "quit" ends. */
#include "rt_internal.h"
#include "vk_build.h"
#include "util.h"
#include "scene.h"

#define GLFW_INCLUDE_VULKAN
#include <GLFW/glfw3.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

static const char tonemap_vert[] =
    "#version 450\n"
    "void main() {\n"
    "    vec2 p = vec2((gl_VertexIndex << 1) & 2, gl_VertexIndex & 2);\n"
    "    gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);\n"
    "}\n";

/* The same curves as rt_tonemap_rgba8 (image.c). */
static const char tonemap_frag[] =
    "#version 450\n"
    "layout(set = 0, binding = 0) uniform sampler2D u_src;\n"
    "layout(push_constant) uniform pc { uint mode; } u_pc;\n"
    "layout(location = 0) out vec4 o_color;\n"
    "float srgb(float c) {\n"
    "    c = clamp(c, 0.0, 1.0);\n"
    "    return c <= 0.0031308 ? 12.92 * c : 1.055 * pow(c, 1.0 / 2.4) - 0.055;\n"
    "}\n"
    "void main() {\n"
    "    vec3 c = texelFetch(u_src, ivec2(gl_FragCoord.xy), 0).rgb;\n"
    "    if (u_pc.mode == 0u) {\n"
    "        c = max(c, vec3(0.0)) * 0.8;\n"
    "        c = c * (2.51 * c + 0.03) / (c * (2.43 * c + 0.59) + 0.14);\n"
    "    }\n"
    "    if (u_pc.mode != 2u) c = vec3(srgb(c.r), srgb(c.g), srgb(c.b));\n"
    "    o_color = vec4(clamp(c, 0.0, 1.0), 1.0);\n"
    "}\n";

typedef struct watch {
    char   **files;
    double  *mtimes;
    int      n;
} watch;

typedef struct viewer {
    const rt_viewer_desc *desc;
    GLFWwindow    *win;
    rt_device      dev;
    rt_pack       *pack;         /* the renderer points at it: heap, swapped whole */
    rt_renderer   *r;
    VkSurfaceKHR   surface;
    VkSwapchainKHR swapchain;
    VkFormat       format;
    VkExtent2D     extent;
    uint32_t       nimages;
    VkImage       *images;
    VkImageView   *views;
    VkFramebuffer *fbs;
    VkRenderPass   pass;
    VkDescriptorSetLayout set_layout;
    VkPipelineLayout layout;
    VkPipeline     pipeline;
    VkDescriptorPool dpool;
    VkDescriptorSet set;
    VkSampler      sampler;
    VkCommandBuffer cb;
    VkSemaphore    acquired, rendered;
    VkFence        fence;
    rt_buffer      shot;
    rt_overlay    *overlay;      /* the help (H), drawn after the tone map */
    rt_vk_list     keep;         /* pass, views, framebuffers, tone map, sync */
    bool           help;
    double         frame_ms;     /* smoothed, for the help                  */
    /* camera and state */
    rt_camera      cam;
    double         yaw, pitch, speed;
    splat_view     view;
    int            material;
    bool           wire, quit, dragging, no_shadows, no_undergrowth;
    int            scale;        /* the preview scale (P): 1, 2, 4          */
    double         mx, my;
    /* hot reload */
    watch          w;
    const char    *scene;
    char           scene_buf[2048];   /* the manifest's scene.source */
    int            reloads, reload_errors;
    double         last_check;
    char           status[256];
    int            status_code;
} viewer;

/* ---- camera ----------------------------------------------------------------- */

static void camera_from_angles(viewer *v)
{
    double f[3] = { cos(v->pitch) * sin(v->yaw), sin(v->pitch), -cos(v->pitch) * cos(v->yaw) };
    for (int i = 0; i < 3; i++)
        v->cam.look[i] = v->cam.position[i] + f[i] * 100.0;
}

static void angles_from_camera(viewer *v)
{
    double f[3], len = 0;
    for (int i = 0; i < 3; i++) {
        f[i] = v->cam.look[i] - v->cam.position[i];
        len += f[i] * f[i];
    }
    len = sqrt(len);
    if (len <= 0)
        return;
    v->pitch = asin(f[1] / len);
    v->yaw = atan2(f[0], -f[2]);
}

static void move_camera(viewer *v, double dt)
{
    GLFWwindow *w = v->win;
    double f[3] = { sin(v->yaw), 0, -cos(v->yaw) }, r[3] = { cos(v->yaw), 0, sin(v->yaw) };
    double d[3] = { 0, 0, 0 };
    if (glfwGetKey(w, GLFW_KEY_W) == GLFW_PRESS) for (int i = 0; i < 3; i++) d[i] += f[i];
    if (glfwGetKey(w, GLFW_KEY_S) == GLFW_PRESS) for (int i = 0; i < 3; i++) d[i] -= f[i];
    if (glfwGetKey(w, GLFW_KEY_D) == GLFW_PRESS) for (int i = 0; i < 3; i++) d[i] += r[i];
    if (glfwGetKey(w, GLFW_KEY_A) == GLFW_PRESS) for (int i = 0; i < 3; i++) d[i] -= r[i];
    if (glfwGetKey(w, GLFW_KEY_SPACE) == GLFW_PRESS) d[1] += 1;
    if (glfwGetKey(w, GLFW_KEY_LEFT_CONTROL) == GLFW_PRESS) d[1] -= 1;
    for (int i = 0; i < 3; i++)
        v->cam.position[i] += d[i] * v->speed * dt;
    camera_from_angles(v);
}

/* ---- keys (also from the script) -------------------------------------------- */

/* The P key: the next preview scale (1, 2, 4; rt_render_desc.preview_scale).
 * The renderer's targets have the internal size, so a new renderer is made
 * with the old one's switches (light, path, wireframe, shadows,
 * undergrowth) and the tone map reads its output; craters are not carried
 * over (the new one starts from the pack's heightfield).  On failure the
 * old renderer stays. */
static void cycle_preview(viewer *v)
{
    int next = v->scale >= 4 ? 1 : v->scale * 2;
    rt_render_desc rd = v->desc->render;
    rd.width = (int)v->extent.width;
    rd.height = (int)v->extent.height;
    rd.shading = v->pack->uber_compute.mod ? RT_SHADING_SCREEN : RT_SHADING_FORWARD;
    rd.preview_scale = next;
    rd.no_shadows = v->no_shadows;
    rt_error e = { 0 };
    rt_renderer *nr;
    vkDeviceWaitIdle(v->dev.dev);
    if (!rt_renderer_create(&v->dev, v->pack, &rd, &nr, &e)) {
        fprintf(stderr, "splatview: preview scale 1/%d: %s\n", next, e.msg);
        snprintf(v->status, sizeof v->status, "preview scale 1/%d failed (see console)", next);
        rt_error_clear(&e);
        return;
    }
    rt_renderer_set_light(nr, rt_renderer_light(v->r));
    rt_renderer_set_shading(nr, rt_renderer_shading(v->r));
    rt_renderer_set_wireframe(nr, v->wire);
    rt_renderer_set_undergrowth(nr, !v->no_undergrowth);
    rt_renderer_set_shadows(nr, !v->no_shadows);
    rt_renderer_destroy(v->r);
    v->r = nr;
    rt_vk_write_sets(&v->dev, &(rt_vk_write){ .set = v->set,
                                              .type = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
                                              .sampler = v->sampler,
                                              .view = rt_renderer_target(v->r)->view }, 1);
    v->scale = next;
    snprintf(v->status, sizeof v->status, "preview scale 1/%d", next);
    printf("splatview: preview scale 1/%d\n", next);
}

static void key_action(viewer *v, int key)
{
    int view = rt_view_by_key(key);   /* GLFW's digit keys are their ASCII */
    if (view == SPLAT_VIEW_MASK) {    /* again: the next material's mask */
        if (v->view == SPLAT_VIEW_MASK)
            v->material = (v->material + 1) % v->pack->nmaterials;
        v->view = SPLAT_VIEW_MASK;
    } else if (view >= 0) {
        v->view = (splat_view)view;
    } else if (key == GLFW_KEY_F) {
        v->wire = !v->wire;
        rt_renderer_set_wireframe(v->r, v->wire);
    } else if (key == GLFW_KEY_G) {
        bool screen = rt_renderer_shading(v->r) == RT_SHADING_SCREEN;
        if (!rt_renderer_set_shading(v->r, screen ? RT_SHADING_FORWARD : RT_SHADING_SCREEN))
            snprintf(v->status, sizeof v->status, "no screen-space path (pack without compute variants)");
    } else if (key == GLFW_KEY_R) {
        v->last_check = -1e9;   /* check the files on the next frame */
        for (int i = 0; i < v->w.n; i++)
            v->w.mtimes[i] = -1;
    } else if (key == GLFW_KEY_J || key == GLFW_KEY_L || key == GLFW_KEY_I ||
               key == GLFW_KEY_K || key == GLFW_KEY_EQUAL || key == GLFW_KEY_MINUS) {
        /* the light: J / L turn the sun by 15 degrees, I / K raise and
         * lower it by 5, + / - change the exposure by half a stop */
        rt_light l = *rt_renderer_light(v->r);
        l.sun[0] = fmod(l.sun[0] + (key == GLFW_KEY_L ? 15 : key == GLFW_KEY_J ? -15 : 0), 360.0);
        l.sun[1] += key == GLFW_KEY_I ? 5 : key == GLFW_KEY_K ? -5 : 0;
        l.sun[1] = l.sun[1] > 90 ? 90 : l.sun[1] < -10 ? -10 : l.sun[1];
        l.exposure += key == GLFW_KEY_EQUAL ? 0.5 : key == GLFW_KEY_MINUS ? -0.5 : 0;
        l.exposure = l.exposure > 20 ? 20 : l.exposure < -20 ? -20 : l.exposure;
        rt_renderer_set_light(v->r, &l);
        snprintf(v->status, sizeof v->status, "sun %.0f %.0f, exposure %+.1f EV", l.sun[0],
                 l.sun[1], l.exposure);
    } else if (key == GLFW_KEY_U) {
        v->no_undergrowth = !v->no_undergrowth;
        rt_renderer_set_undergrowth(v->r, !v->no_undergrowth);
        snprintf(v->status, sizeof v->status, "undergrowth %s",
                 v->no_undergrowth ? "off" : "on");
    } else if (key == GLFW_KEY_P) {
        cycle_preview(v);
    } else if (key == GLFW_KEY_H) {
        v->help = !v->help;
    } else if (key == GLFW_KEY_O) {
        v->no_shadows = !v->no_shadows;
        rt_renderer_set_shadows(v->r, !v->no_shadows);
        snprintf(v->status, sizeof v->status, "shadows %s", v->no_shadows ? "off" : "on");
    } else if (key == GLFW_KEY_Q || key == GLFW_KEY_ESCAPE) {
        v->quit = true;
    }
    rt_renderer_set_view(v->r, v->view, v->material);
}

static void on_key(GLFWwindow *w, int key, int sc, int action, int mods)
{
    if (action == GLFW_PRESS)
        key_action(glfwGetWindowUserPointer(w), key);
}

static void on_scroll(GLFWwindow *w, double dx, double dy)
{
    viewer *v = glfwGetWindowUserPointer(w);
    v->speed *= pow(1.25, dy);
}

/* A crater (1.5 destruction cells wide) where window pixel (x, y) shows
 * the terrain. */
static void click_crater(viewer *v, double x, double y)
{
    int ww, wh;
    glfwGetWindowSize(v->win, &ww, &wh);
    rt_crater_stats st;
    rt_error e = { 0 };
    double radius = v->pack->has_destruction ? 1.5 * v->pack->destr_cell : 1.0;
    if (!rt_renderer_crater_at_pixel(v->r, &v->cam, x, y, ww, wh, radius, &st, &e))
        fprintf(stderr, "splatview: crater: %s\n", e.msg);
    else
        printf("crater: %s, %d new tiles (%d of %d used), %.3f ms cpu\n",
               st.result == RT_CRATER_DONE ? "done" : st.result == RT_CRATER_REFUSED
               ? "refused (tile pool exhausted)" : "outside the destructible area",
               st.tiles_new, st.tiles_used, st.pool, st.cpu_ms);
    rt_error_clear(&e);
}

static void on_button(GLFWwindow *w, int button, int action, int mods)
{
    viewer *v = glfwGetWindowUserPointer(w);
    if (button == GLFW_MOUSE_BUTTON_LEFT && action == GLFW_PRESS) {
        double x, y;
        glfwGetCursorPos(w, &x, &y);
        click_crater(v, x, y);
    }
    if (button == GLFW_MOUSE_BUTTON_RIGHT) {
        v->dragging = action == GLFW_PRESS;
        glfwGetCursorPos(w, &v->mx, &v->my);
    }
}

static void on_cursor(GLFWwindow *w, double x, double y)
{
    viewer *v = glfwGetWindowUserPointer(w);
    if (!v->dragging)
        return;
    v->yaw += (x - v->mx) * 0.004;
    v->pitch -= (y - v->my) * 0.004;
    v->pitch = fmax(-1.55, fmin(1.55, v->pitch));
    v->mx = x;
    v->my = y;
    camera_from_angles(v);
}

/* ---- hot reload ---------------------------------------------------------------- */

static double mtime(const char *path)
{
    struct stat st;
    if (stat(path, &st) != 0)
        return -2;
    return (double)st.st_mtim.tv_sec + (double)st.st_mtim.tv_nsec * 1e-9;
}

static void watch_free(watch *w)
{
    for (int i = 0; i < w->n; i++)
        free(w->files[i]);
    free(w->files);
    free(w->mtimes);
    memset(w, 0, sizeof *w);
}

/* The files the scene reads (scene.sg and every import), with mtimes. */
static void watch_scene(viewer *v)
{
    watch_free(&v->w);
    /* the paths the build uses, so the watch list is the build's inputs */
    char **paths = splat_search_path(v->desc->include, v->desc->ninclude, v->scene);
    char **imports = splat_import_path(v->scene, (const char *const *)paths);
    sg_diags d;
    sg_diags_init(&d);
    sg_program *prog = sg_load(v->scene, (const char *const *)imports, &d);
    splat_search_path_free(imports);
    splat_search_path_free(paths);
    int n = prog ? sg_file_count(prog) : 0;
    v->w.files = calloc((size_t)n + 1, sizeof *v->w.files);
    v->w.mtimes = calloc((size_t)n + 1, sizeof *v->w.mtimes);
    if (v->w.files && v->w.mtimes) {
        if (n == 0) {   /* even a scene that does not parse is watched */
            v->w.files[0] = strdup(v->scene);
            v->w.mtimes[0] = mtime(v->scene);
            v->w.n = 1;
        }
        for (int i = 0; i < n; i++) {
            v->w.files[i] = strdup(sg_file_path(prog, i));
            v->w.mtimes[i] = mtime(v->w.files[i]);
        }
        if (n)
            v->w.n = n;
    }
    if (prog)
        sg_free(prog);
    sg_diags_free(&d);
}

/* The --far-atlas=N a pack's atlas was baked with (0: none). */
static int far_atlas_n(const rt_pack *p)
{
    for (int n = 1; p->far.data && n <= 64; n++)
        if ((p->hf_width + n - 1) / n == p->far.width && (p->hf_height + n - 1) / n == p->far.height)
            return n;
    return 0;
}

/* Rebuild the pack in process and swap pipelines; errors leave the old
 * pack drawing and are shown in the console and the title.  A far atlas
 * is rebaked on the viewer's device where that is a GPU (or where
 * $SPLAT_FAR_BAKE asks: gpu, or cpu for the compiler's reference), else
 * dropped: on a CPU the bake takes longer than an edit should wait. */
static void reload(viewer *v)
{
    char **paths = splat_search_path(v->desc->include, v->desc->ninclude, v->scene);
    sg_diags d;
    sg_diags_init(&d);
    splat_build_desc bd = { .scene = v->scene, .out = v->desc->pack_dir,
                            .search_paths = (const char *const *)paths, .jobs = 2,
                            .preview = v->desc->preview };
    splat_far_bake mode = SPLAT_FAR_BAKE_AUTO;
    bool asked = splat_far_bake_parse(getenv("SPLAT_FAR_BAKE"), &mode);
    rt_far_bake_host host = { .mode = mode, .device = &v->dev };
    int far_n = v->desc->preview ? 0 : far_atlas_n(v->pack);
    if (far_n && (asked || v->dev.props.deviceType != VK_PHYSICAL_DEVICE_TYPE_CPU)) {
        bd.far_atlas = far_n;
        bd.far_bake = host.mode;
        bd.far_device = rt_far_bake_device;
        bd.far_device_user = &host;
    } else if (far_n) {
        fprintf(stderr, "splatview: hot reload: the far atlas is dropped (%s is a CPU; "
                "SPLAT_FAR_BAKE=gpu or cpu rebakes it)\n", v->dev.props.deviceName);
    }
    splat_build_stats bs;
    double t0 = splat_now();
    bool ok = splat_build(&bd, &bs, &d);
    splat_search_path_free(paths);
    if (!ok || d.nerrors) {
        fprintf(stderr, "splatview: hot reload: the scene does not compile:\n");
        sg_diags_print(&d, stderr);
        snprintf(v->status, sizeof v->status, "COMPILE ERROR (see console)");
        v->reload_errors++;
        sg_diags_free(&d);
        return;
    }
    sg_diags_free(&d);
    rt_error e = { 0 };
    rt_pack *np = calloc(1, sizeof *np);
    if (!np || !rt_pack_load(np, v->desc->pack_dir, &e) ||
        !rt_renderer_swap_pack(v->r, np, &e)) {
        fprintf(stderr, "splatview: hot reload: %s\n", e.msg ? e.msg : "out of memory");
        snprintf(v->status, sizeof v->status, "RELOAD FAILED (see console)");
        rt_error_clear(&e);
        if (np && np->dir)
            rt_pack_free(np);
        free(np);
        v->reload_errors++;
        return;
    }
    rt_pack_free(v->pack);
    free(v->pack);
    v->pack = np;
    v->reloads++;
    snprintf(v->status, sizeof v->status, "reloaded in %.0f ms (%d compiled%s)",
             (splat_now() - t0) * 1e3, bs.shaders_compiled,
             bd.far_atlas ? bs.far_on_device ? ", far atlas baked on the device"
                                             : ", far atlas baked on the CPU" : "");
    fprintf(stderr, "splatview: %s\n", v->status);
}

static void check_files(viewer *v)
{
    double t = splat_now();
    if (!v->scene || t - v->last_check < 0.25)
        return;
    v->last_check = t;
    bool changed = false;
    for (int i = 0; i < v->w.n; i++)
        if (mtime(v->w.files[i]) != v->w.mtimes[i])
            changed = true;
    if (!changed)
        return;
    reload(v);
    watch_scene(v);   /* imports may have changed too */
}

/* ---- swapchain and the tone-map pass ------------------------------------------ */

static bool make_swapchain(viewer *v, rt_error *e)
{
    rt_device *d = &v->dev;
    VkSurfaceCapabilitiesKHR caps;
    RT_VK(e, vkGetPhysicalDeviceSurfaceCapabilitiesKHR(d->phys, v->surface, &caps));
    uint32_t n = 0;
    RT_VK(e, vkGetPhysicalDeviceSurfaceFormatsKHR(d->phys, v->surface, &n, NULL));
    VkSurfaceFormatKHR *fmts = calloc(n ? n : 1, sizeof *fmts);
    if (!fmts)
        return rt_fail(e, RT_E_WINDOW, "out of memory");
    vkGetPhysicalDeviceSurfaceFormatsKHR(d->phys, v->surface, &n, fmts);
    VkSurfaceFormatKHR f = fmts[0];
    for (uint32_t i = 0; i < n; i++)   /* UNORM: the shader encodes sRGB */
        if (fmts[i].format == VK_FORMAT_B8G8R8A8_UNORM || fmts[i].format == VK_FORMAT_R8G8B8A8_UNORM)
            f = fmts[i];
    free(fmts);
    if (f.format != VK_FORMAT_B8G8R8A8_UNORM && f.format != VK_FORMAT_R8G8B8A8_UNORM)
        return rt_fail(e, RT_E_WINDOW, "the surface offers no 8-bit UNORM format");
    v->format = f.format;
    v->extent = caps.currentExtent;
    if (v->extent.width == UINT32_MAX) {
        v->extent.width = (uint32_t)v->desc->width;
        v->extent.height = (uint32_t)v->desc->height;
    }
    if (!(caps.supportedUsageFlags & VK_IMAGE_USAGE_TRANSFER_SRC_BIT))
        return rt_fail(e, RT_E_WINDOW, "swapchain images cannot be copied (screenshots)");
    VkSwapchainCreateInfoKHR ci = {
        .sType = VK_STRUCTURE_TYPE_SWAPCHAIN_CREATE_INFO_KHR,
        .surface = v->surface,
        .minImageCount = caps.minImageCount + 1 <= caps.maxImageCount || caps.maxImageCount == 0
                             ? caps.minImageCount + 1 : caps.minImageCount,
        .imageFormat = f.format,
        .imageColorSpace = f.colorSpace,
        .imageExtent = v->extent,
        .imageArrayLayers = 1,
        .imageUsage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
        .imageSharingMode = VK_SHARING_MODE_EXCLUSIVE,
        .preTransform = caps.currentTransform,
        .compositeAlpha = VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR,
        .presentMode = VK_PRESENT_MODE_FIFO_KHR,
        .clipped = VK_TRUE,
    };
    RT_VK(e, vkCreateSwapchainKHR(d->dev, &ci, NULL, &v->swapchain));
    RT_VK(e, vkGetSwapchainImagesKHR(d->dev, v->swapchain, &v->nimages, NULL));
    v->images = calloc(v->nimages, sizeof *v->images);
    v->views = calloc(v->nimages, sizeof *v->views);
    v->fbs = calloc(v->nimages, sizeof *v->fbs);
    if (!v->images || !v->views || !v->fbs)
        return rt_fail(e, RT_E_WINDOW, "out of memory");
    RT_VK(e, vkGetSwapchainImagesKHR(d->dev, v->swapchain, &v->nimages, v->images));

    VkSubpassDependency dep = {
        VK_SUBPASS_EXTERNAL, 0, VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT,
        VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT, 0, VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT, 0,
    };
    if (!rt_vk_pass(d, &v->keep, &(rt_vk_pass_desc){ .label = "swapchain",
                        .color = { { .format = v->format, .load = VK_ATTACHMENT_LOAD_OP_DONT_CARE,
                                     .final = VK_IMAGE_LAYOUT_PRESENT_SRC_KHR } },
                        .ncolor = 1, .deps = &dep, .ndeps = 1 }, &v->pass, e))
        return false;
    for (uint32_t i = 0; i < v->nimages; i++) {
        VkImageViewCreateInfo vi = {
            .sType = VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO,
            .image = v->images[i],
            .viewType = VK_IMAGE_VIEW_TYPE_2D,
            .format = v->format,
            .subresourceRange = { VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1 },
        };
        RT_VK(e, vkCreateImageView(d->dev, &vi, NULL, &v->views[i]));
        if (!rt_vk_keep(d, &v->keep, VK_OBJECT_TYPE_IMAGE_VIEW, RT_VK_H(v->views[i]), e) ||
            !rt_vk_fb(d, &v->keep, &(rt_vk_fb_desc){ .label = "swapchain", .pass = v->pass,
                          .views = &v->views[i], .nviews = 1, .width = v->extent.width,
                          .height = v->extent.height }, &v->fbs[i], e))
            return false;
    }
    return rt_buffer_create(d, (VkDeviceSize)v->extent.width * v->extent.height * 4,
                            VK_BUFFER_USAGE_TRANSFER_DST_BIT, true, &v->shot, e);
}

static bool make_tonemap(viewer *v, rt_error *e)
{
    rt_device *d = &v->dev;
    rt_vk_list *k = &v->keep;
    VkDescriptorSetLayoutBinding b = { 0, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1,
                                       VK_SHADER_STAGE_FRAGMENT_BIT, NULL };
    VkDescriptorPoolSize ps = { VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1 };
    if (!rt_vk_set_layout(d, k, &(rt_vk_set_layout_desc){ "tone map", &b, 1 }, &v->set_layout,
                          e) ||
        !rt_vk_layout(d, k, &(rt_vk_layout_desc){ .label = "tone map", .sets = &v->set_layout,
                          .nsets = 1, .push_stages = VK_SHADER_STAGE_FRAGMENT_BIT,
                          .push_bytes = 4 }, &v->layout, e) ||
        !rt_vk_sampler(d, k, &(rt_vk_sampler_desc){ .label = "tone map",
                           .wrap = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE }, &v->sampler, e) ||
        !rt_vk_sets(d, k, &(rt_vk_sets_desc){ .label = "tone map", .sizes = &ps, .nsizes = 1,
                        .layouts = &v->set_layout, .nsets = 1 }, &v->dpool, &v->set, e))
        return false;
    rt_vk_write_sets(d, &(rt_vk_write){ .set = v->set, .type = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
                                        .sampler = v->sampler,
                                        .view = rt_renderer_target(v->r)->view }, 1);
    if (!rt_vk_gfx(d, k, &(rt_vk_gfx_desc){ .label = "tone map", .vs_glsl = tonemap_vert,
                       .fs_glsl = tonemap_frag, .ncolor = 1, .viewport = v->extent,
                       .layout = v->layout, .pass = v->pass }, &v->pipeline, e))
        return false;
    VkCommandBufferAllocateInfo cai = {
        .sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO,
        .commandPool = d->pool, .level = VK_COMMAND_BUFFER_LEVEL_PRIMARY, .commandBufferCount = 1,
    };
    RT_VK(e, vkAllocateCommandBuffers(d->dev, &cai, &v->cb));
    VkSemaphoreCreateInfo sci = { .sType = VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO };
    RT_VK(e, vkCreateSemaphore(d->dev, &sci, NULL, &v->acquired));
    if (!rt_vk_keep(d, k, VK_OBJECT_TYPE_SEMAPHORE, RT_VK_H(v->acquired), e))
        return false;
    RT_VK(e, vkCreateSemaphore(d->dev, &sci, NULL, &v->rendered));
    if (!rt_vk_keep(d, k, VK_OBJECT_TYPE_SEMAPHORE, RT_VK_H(v->rendered), e))
        return false;
    VkFenceCreateInfo fci = { .sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO };
    RT_VK(e, vkCreateFence(d->dev, &fci, NULL, &v->fence));
    return rt_vk_keep(d, k, VK_OBJECT_TYPE_FENCE, RT_VK_H(v->fence), e);
}

/* Tone-map the renderer's frame into the next swapchain image, present it;
 * with `shot`, also copy it out and write a PNG. */
static bool present(viewer *v, const char *shot, rt_error *e)
{
    rt_device *d = &v->dev;
    uint32_t idx;
    VkResult r = vkAcquireNextImageKHR(d->dev, v->swapchain, UINT64_MAX, v->acquired, VK_NULL_HANDLE, &idx);
    if (r != VK_SUCCESS && r != VK_SUBOPTIMAL_KHR)
        return rt_fail(e, RT_E_VULKAN, "vkAcquireNextImageKHR", rt_vk_result_name(r));
    VkCommandBuffer cb = v->cb;
    RT_VK(e, vkResetCommandBuffer(cb, 0));
    VkCommandBufferBeginInfo bi = { .sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO,
                                    .flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT };
    RT_VK(e, vkBeginCommandBuffer(cb, &bi));
    rt_cmd_image_barrier(cb, rt_renderer_target(v->r)->img, 0, 1, 1, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                  VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT,
                  VK_ACCESS_SHADER_READ_BIT, VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT,
                  VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT);
    VkRenderPassBeginInfo rb = {
        .sType = VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO, .renderPass = v->pass,
        .framebuffer = v->fbs[idx], .renderArea = { { 0, 0 }, v->extent },
    };
    vkCmdBeginRenderPass(cb, &rb, VK_SUBPASS_CONTENTS_INLINE);
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, v->pipeline);
    vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, v->layout, 0, 1, &v->set, 0, NULL);
    _Static_assert(RT_TONEMAP_FILMIC == 0 && RT_TONEMAP_NONE == 2, "the blit's u_pc.mode");
    uint32_t mode = (uint32_t)rt_view_tonemap(v->view);
    vkCmdPushConstants(cb, v->layout, VK_SHADER_STAGE_FRAGMENT_BIT, 0, 4, &mode);
    vkCmdDraw(cb, 3, 1, 0, 0);
    if (v->help)
        rt_overlay_record(v->overlay, cb, v->extent.width, v->extent.height);
    vkCmdEndRenderPass(cb);
    if (shot) {
        rt_cmd_image_barrier(cb, v->images[idx], 0, 1, 1, VK_IMAGE_LAYOUT_PRESENT_SRC_KHR,
                      VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT,
                      VK_ACCESS_TRANSFER_READ_BIT, VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT,
                      VK_PIPELINE_STAGE_TRANSFER_BIT);
        VkBufferImageCopy copy = {
            .imageSubresource = { VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1 },
            .imageExtent = { v->extent.width, v->extent.height, 1 },
        };
        vkCmdCopyImageToBuffer(cb, v->images[idx], VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                               v->shot.buf, 1, &copy);
        rt_cmd_image_barrier(cb, v->images[idx], 0, 1, 1, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                      VK_IMAGE_LAYOUT_PRESENT_SRC_KHR, VK_ACCESS_TRANSFER_READ_BIT, 0,
                      VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT);
    }
    RT_VK(e, vkEndCommandBuffer(cb));
    VkPipelineStageFlags wait = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT;
    VkSubmitInfo si = {
        .sType = VK_STRUCTURE_TYPE_SUBMIT_INFO,
        .waitSemaphoreCount = 1, .pWaitSemaphores = &v->acquired, .pWaitDstStageMask = &wait,
        .commandBufferCount = 1, .pCommandBuffers = &cb,
        .signalSemaphoreCount = 1, .pSignalSemaphores = &v->rendered,
    };
    RT_VK(e, vkQueueSubmit(d->queue, 1, &si, v->fence));
    VkPresentInfoKHR pi = {
        .sType = VK_STRUCTURE_TYPE_PRESENT_INFO_KHR,
        .waitSemaphoreCount = 1, .pWaitSemaphores = &v->rendered,
        .swapchainCount = 1, .pSwapchains = &v->swapchain, .pImageIndices = &idx,
    };
    r = vkQueuePresentKHR(d->queue, &pi);
    if (r != VK_SUCCESS && r != VK_SUBOPTIMAL_KHR)
        return rt_fail(e, RT_E_VULKAN, "vkQueuePresentKHR", rt_vk_result_name(r));
    RT_VK(e, vkWaitForFences(d->dev, 1, &v->fence, VK_TRUE, UINT64_MAX));
    RT_VK(e, vkResetFences(d->dev, 1, &v->fence));
    if (shot) {
        size_t n = (size_t)v->extent.width * v->extent.height;
        uint8_t *px = malloc(n * 4);
        if (!px)
            return rt_fail(e, RT_E_WINDOW, "out of memory");
        memcpy(px, v->shot.map, n * 4);
        if (v->format == VK_FORMAT_B8G8R8A8_UNORM)
            for (size_t i = 0; i < n; i++) {
                uint8_t t = px[4 * i];
                px[4 * i] = px[4 * i + 2];
                px[4 * i + 2] = t;
            }
        bool ok = rt_write_png(shot, px, (int)v->extent.width, (int)v->extent.height, e);
        free(px);
        if (!ok)
            return false;
        fprintf(stderr, "splatview: screenshot %s\n", shot);
    }
    return true;
}

/* ---- the loop ------------------------------------------------------------------ */

static bool frame(viewer *v, const char *shot, double *last, rt_error *e)
{
    double t = splat_now(), dt = t - *last;
    *last = t;
    glfwPollEvents();
    move_camera(v, dt > 0.25 ? 0.25 : dt);
    v->cam.time += dt > 0.25 ? 0.25 : dt;   /* the undergrowth's wind */
    check_files(v);
    rt_frame_stats st;
    if (!rt_renderer_frame(v->r, &v->cam, &st, e))
        return false;
    v->frame_ms = v->frame_ms > 0 ? 0.9 * v->frame_ms + 100.0 * dt : 1e3 * dt;
    if (v->help) {
        char text[2048];
        rt_overlay_info in = {
            .pack = v->pack->name, .view = v->view, .wire = v->wire,
            .material = v->view == SPLAT_VIEW_MASK ? v->pack->materials[v->material].name : NULL,
            .screen = st.screen, .frame_ms = v->frame_ms, .pending = st.pipelines_pending,
            .status = v->status,
        };
        rt_overlay_text(&in, text, sizeof text);
        if (!rt_overlay_layout(v->overlay, text, v->extent.width, v->extent.height, e))
            return false;
    }
    if (!present(v, shot, e))
        return false;
    static double shown;
    if (t - shown > 0.25) {
        shown = t;
        char title[640], pending[160] = "";
        const rt_screen_stats *ts = &st.tiles;
        if (st.pipelines_pending > 0 || ts->tiles_stand_in > 0)   /* stand-ins meanwhile */
            snprintf(pending, sizeof pending,
                     " (%d shaders compiling; stand-in tiles: %d uber, %d atlas, %d flat)",
                     st.pipelines_pending, ts->tiles_stand_in_uber, ts->tiles_stand_in_atlas,
                     ts->tiles_stand_in_flat);
        snprintf(title, sizeof title,
                 "splatview %s | %s%s | %s | %.1f ms/frame (gpu %.1f) | %d patches, %d pipelines%s | %s",
                 v->pack->name, rt_view_name(v->view), v->wire ? " wire" : "",
                 st.screen ? "screen" : "forward", dt * 1e3,
                 st.gpu_ms, st.patches, st.pipelines, pending, v->status);
        glfwSetWindowTitle(v->win, title);
    }
    return true;
}

/* One script step: "name=value" or "name". */
static bool script_step(viewer *v, const char *step, double *last, rt_error *e)
{
    char key[64] = "", val[1024] = "";
    const char *eq = strchr(step, '=');
    size_t kn = eq ? (size_t)(eq - step) : strlen(step);
    if (kn >= sizeof key)
        return rt_fail(e, RT_E_WINDOW, "script step name too long");
    memcpy(key, step, kn);
    if (eq)
        snprintf(val, sizeof val, "%s", eq + 1);
    if (!strcmp(key, "frames")) {
        int n = atoi(val);
        for (int i = 0; i < n && !v->quit; i++)
            if (!frame(v, NULL, last, e))
                return false;
    } else if (!strcmp(key, "screenshot")) {
        /* the final picture: the pipelines the workers are making first
         * (the stand-ins shade their tiles until then) */
        return rt_renderer_wait_pipelines(v->r, e) && frame(v, val, last, e);
    } else if (!strcmp(key, "view")) {
        splat_view view;
        int m;
        if (!rt_parse_view(val, v->pack, &view, &m, e))
            return false;
        v->view = view;
        v->material = m;
        rt_renderer_set_view(v->r, view, m);
    } else if (!strcmp(key, "key")) {
        int k = !strcmp(val, "ESC") ? GLFW_KEY_ESCAPE : val[0] >= 'a' && val[0] <= 'z' ? val[0] - 32 : val[0];
        key_action(v, k);
    } else if (!strcmp(key, "wait_reload")) {
        /* compile errors on the way are shown and survived; only a
         * successful reload ends the wait */
        int before = v->reloads;
        double until = splat_now() + atof(val);
        while (v->reloads == before && splat_now() < until && !v->quit)
            if (!frame(v, NULL, last, e))
                return false;
        if (v->reloads == before)
            return rt_fail(e, RT_E_RELOAD, "no reload within the time given");
    } else if (!strcmp(key, "click")) {   /* click=X,Y: a left click there */
        double x = 0, y = 0;
        if (sscanf(val, "%lf,%lf", &x, &y) != 2)
            return rt_fail(e, RT_E_WINDOW, "click expects X,Y (window pixels)");
        click_crater(v, x, y);
    } else if (!strcmp(key, "quit")) {
        v->quit = true;
    } else if (key[0]) {
        char what[128];
        snprintf(what, sizeof what, "unknown script step '%s'", key);
        return rt_fail(e, RT_E_WINDOW, what);
    }
    return true;
}

static bool run_script(viewer *v, const char *script, double *last, rt_error *e)
{
    char *s = strdup(script), *save = NULL;
    if (!s)
        return rt_fail(e, RT_E_WINDOW, "out of memory");
    bool ok = true;
    for (char *t = strtok_r(s, ";", &save); t && ok && !v->quit; t = strtok_r(NULL, ";", &save))
        ok = script_step(v, t, last, e);
    free(s);
    v->quit = true;   /* a script always ends the viewer */
    return ok;
}

static void teardown(viewer *v)
{
    rt_device *d = &v->dev;
    if (d->dev) {
        vkDeviceWaitIdle(d->dev);
        rt_renderer_destroy(v->r);
        v->r = NULL;
        rt_overlay_destroy(v->overlay);
        v->overlay = NULL;
        rt_vk_list_destroy(d, &v->keep);   /* the passes' and tone map's objects */
        if (v->swapchain) vkDestroySwapchainKHR(d->dev, v->swapchain, NULL);
        rt_buffer_destroy(d, &v->shot);
    }
    if (v->surface)
        vkDestroySurfaceKHR(d->instance, v->surface, NULL);
    free(v->images);
    free(v->views);
    free(v->fbs);
    rt_device_destroy(d);
    if (v->win)
        glfwDestroyWindow(v->win);
    glfwTerminate();
    if (v->pack)
        rt_pack_free(v->pack);
    free(v->pack);
    watch_free(&v->w);
}

/* The view and camera the desc asks for (--view, --camera-preset,
 * --camera), the fly speed from the terrain's size. */
static bool start_view(viewer *v, rt_error *e)
{
    const rt_viewer_desc *desc = v->desc;
    if (desc->view_name && !rt_parse_view(desc->view_name, v->pack, &v->view, &v->material, e))
        return false;
    rt_default_camera(v->pack, &v->cam);
    if (desc->preset) {
        int c = rt_pack_camera_find(v->pack, desc->preset);
        if (c < 0)
            return rt_fail(e, RT_E_WINDOW, "the pack has no such camera preset");
        memcpy(v->cam.position, v->pack->cameras[c].position, sizeof v->cam.position);
        memcpy(v->cam.look, v->pack->cameras[c].look, sizeof v->cam.look);
    }
    if (desc->have_camera && !desc->preset)
        v->cam = desc->camera;
    angles_from_camera(v);
    camera_from_angles(v);
    double ext = v->pack->size[0] > v->pack->size[1] ? v->pack->size[0] : v->pack->size[1];
    v->speed = ext / 20.0;
    return true;
}

/* The scene to watch: --scene, else the manifest's scene.source. */
static void start_watch(viewer *v)
{
    v->scene = v->desc->scene;
    if (!v->scene && v->pack->scene_path) {
        snprintf(v->scene_buf, sizeof v->scene_buf, "%s/%s", v->desc->pack_dir,
                 v->pack->scene_path);
        struct stat st;
        if (stat(v->scene_buf, &st) == 0)
            v->scene = v->scene_buf;
    }
    if (v->scene) {
        watch_scene(v);
        snprintf(v->status, sizeof v->status, "watching %d files", v->w.n);
    } else {
        snprintf(v->status, sizeof v->status, "no scene source: hot reload off");
    }
}

/* GLFW's window, the device and a surface it can present to. */
static bool open_window(viewer *v, rt_error *e)
{
    const rt_viewer_desc *desc = v->desc;
    if (!glfwInit()) {
        rt_fail(e, RT_E_WINDOW, "glfwInit failed (no display?)");
        return false;
    }
    if (!glfwVulkanSupported()) {
        rt_fail(e, RT_E_WINDOW, "GLFW finds no Vulkan loader");
        return false;
    }
    glfwWindowHint(GLFW_CLIENT_API, GLFW_NO_API);
    glfwWindowHint(GLFW_RESIZABLE, GLFW_FALSE);   /* fixed-size targets */
    v->win = glfwCreateWindow(desc->width, desc->height, "splatview", NULL, NULL);
    if (!v->win) {
        rt_fail(e, RT_E_WINDOW, "cannot open a window");
        return false;
    }
    glfwSetWindowUserPointer(v->win, v);
    uint32_t next = 0;
    const char **exts = glfwGetRequiredInstanceExtensions(&next);
    rt_device_desc dd = { .instance_exts = exts, .ninstance_exts = next, .swapchain = true };
    if (!rt_device_create(&v->dev, &dd, e))
        return false;
    VkResult vr = glfwCreateWindowSurface(v->dev.instance, v->win, NULL, &v->surface);
    if (vr != VK_SUCCESS) {
        rt_fail(e, RT_E_VULKAN, "glfwCreateWindowSurface", rt_vk_result_name(vr));
        return false;
    }
    VkBool32 can_present = VK_FALSE;
    vkGetPhysicalDeviceSurfaceSupportKHR(v->dev.phys, v->dev.queue_family, v->surface, &can_present);
    if (!can_present) {
        rt_fail(e, RT_E_WINDOW, "the chosen device's graphics queue cannot present to the window");
        return false;
    }
    return true;
}

/* The renderer (screen-capable where the device allows), the tone map
 * and the help overlay. */
static bool make_renderer(viewer *v, rt_error *e)
{
    const rt_viewer_desc *desc = v->desc;
    rt_render_desc rd = desc->render;
    v->no_shadows = rd.no_shadows;
    v->scale = rd.preview_scale > 1 ? rd.preview_scale : 1;
    rd.width = (int)v->extent.width;
    rd.height = (int)v->extent.height;
    /* Screen-capable whenever the pack has compute variants, so the G key
     * can switch paths. */
    rd.shading = v->pack->uber_compute.mod ? RT_SHADING_SCREEN : RT_SHADING_FORWARD;
    bool made = rt_renderer_create(&v->dev, v->pack, &rd, &v->r, e);
    if (!made && rd.shading == RT_SHADING_SCREEN && desc->render.shading != RT_SHADING_SCREEN) {
        rt_error_clear(e);   /* the device cannot do the screen path */
        rd.shading = RT_SHADING_FORWARD;
        made = rt_renderer_create(&v->dev, v->pack, &rd, &v->r, e);
    }
    return made && make_tonemap(v, e) && rt_overlay_create(&v->dev, v->pass, &v->overlay, e);
}

int rt_viewer_run(const rt_viewer_desc *desc)
{
    viewer vw;
    viewer *v = &vw;
    memset(v, 0, sizeof *v);
    v->desc = desc;
    v->speed = 50.0;
    rt_error e = { 0 };
    int status = 1;
    v->pack = calloc(1, sizeof *v->pack);
    if (!v->pack || !rt_pack_load(v->pack, desc->pack_dir, &e)) {
        fprintf(stderr, "splatview: %s\n", e.msg ? e.msg : "out of memory");
        rt_error_clear(&e);
        free(v->pack);
        return 1;
    }
    if (!start_view(v, &e))
        goto done;
    if (!open_window(v, &e))
        goto done;
    if (!make_swapchain(v, &e))
        goto done;
    if (!make_renderer(v, &e))
        goto done;
    /* the path asked for, else screen where the pack can (splatview's
     * headless default) */
    rt_shading want = desc->render.shading;
    if (!desc->shading_set)
        want = v->pack->uber_compute.mod && desc->render.reference != RT_REF_MULTIPASS
                   ? RT_SHADING_SCREEN : RT_SHADING_FORWARD;
    rt_renderer_set_shading(v->r, want);
    printf("splatview: %s shading\n",
           rt_renderer_shading(v->r) == RT_SHADING_SCREEN ? "screen-space" : "forward");
    rt_renderer_set_view(v->r, v->view, v->material);
    start_watch(v);
    glfwSetKeyCallback(v->win, on_key);
    glfwSetScrollCallback(v->win, on_scroll);
    glfwSetMouseButtonCallback(v->win, on_button);
    glfwSetCursorPosCallback(v->win, on_cursor);

    double last = splat_now();
    if (desc->script) {
        if (!run_script(v, desc->script, &last, &e))
            goto done;
    } else {
        while (!v->quit && !glfwWindowShouldClose(v->win))
            if (!frame(v, NULL, &last, &e))
                goto done;
    }
    status = 0;
done:
    if (e.msg)
        fprintf(stderr, "splatview: %s\n", e.msg);
    rt_error_clear(&e);
    teardown(v);
    if (v->dev.validating && v->dev.messages) {
        fprintf(stderr, "splatview: %d validation message(s)\n", v->dev.messages);
        status = status ? status : 3;
    }
    return status;
}
