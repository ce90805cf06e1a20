/* device.c — errors, the Vulkan instance and device, buffers and images.
 *
 * Device choice: SPLAT_DEVICE=<index or name substring> if set; otherwise
 * the first discrete GPU, then integrated, virtual, and last the CPU
 * (lavapipe).  SPLAT_VALIDATE=1 turns on VK_LAYER_KHRONOS_validation and a
 * debug messenger that prints and counts every warning and error, so tests
 * can demand zero; asked for and not installed is an error
 * (RT_E_NO_VALIDATION), never a silent run without it. */
#include "rt_internal.h"
#include "ir.h"
#include "spv.h"

#include <ctype.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>

/* ---- errors ------------------------------------------------------------ */

static const char *const error_formats[] = {
    "",
#define X(id, fmt) fmt,
    RT_ERRORS(X)
#undef X
};

bool rt_fail(rt_error *e, rt_error_id id, ...)
{
    if (!e)
        return false;
    rt_error_clear(e);
    va_list ap, ap2;
    va_start(ap, id);
    va_copy(ap2, ap);
    int n = vsnprintf(NULL, 0, error_formats[id], ap);
    va_end(ap);
    e->id = id;
    e->msg = malloc((size_t)(n > 0 ? n : 0) + 1);
    if (e->msg)
        vsnprintf(e->msg, (size_t)n + 1, error_formats[id], ap2);
    va_end(ap2);
    return false;
}

void rt_error_clear(rt_error *e)
{
    if (!e)
        return;
    free(e->msg);
    e->msg = NULL;
    e->id = RT_OK;
}

const char *rt_vk_result_name(VkResult r)
{
    switch (r) {
#define C(x) case x: return #x;
    C(VK_SUCCESS) C(VK_NOT_READY) C(VK_TIMEOUT) C(VK_INCOMPLETE)
    C(VK_SUBOPTIMAL_KHR) C(VK_ERROR_OUT_OF_HOST_MEMORY)
    C(VK_ERROR_OUT_OF_DEVICE_MEMORY) C(VK_ERROR_INITIALIZATION_FAILED)
    C(VK_ERROR_DEVICE_LOST) C(VK_ERROR_MEMORY_MAP_FAILED)
    C(VK_ERROR_LAYER_NOT_PRESENT) C(VK_ERROR_EXTENSION_NOT_PRESENT)
    C(VK_ERROR_FEATURE_NOT_PRESENT) C(VK_ERROR_INCOMPATIBLE_DRIVER)
    C(VK_ERROR_TOO_MANY_OBJECTS) C(VK_ERROR_FORMAT_NOT_SUPPORTED)
    C(VK_ERROR_SURFACE_LOST_KHR) C(VK_ERROR_OUT_OF_DATE_KHR)
    C(VK_ERROR_INVALID_SHADER_NV) C(VK_ERROR_FRAGMENTED_POOL)
    C(VK_ERROR_OUT_OF_POOL_MEMORY) C(VK_ERROR_UNKNOWN)
#undef C
    default: return "unknown VkResult";
    }
}

/* ---- instance ---------------------------------------------------------- */

static VKAPI_ATTR VkBool32 VKAPI_CALL
on_message(VkDebugUtilsMessageSeverityFlagBitsEXT sev,
           VkDebugUtilsMessageTypeFlagsEXT type,
           const VkDebugUtilsMessengerCallbackDataEXT *data, void *user)
{
    rt_device *d = user;
    if (sev & (VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT |
               VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT)) {
        d->messages++;
        fprintf(stderr, "splatrt: validation %s: %s\n",
                (sev & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT) ? "error" : "warning",
                data->pMessage);
    }
    return VK_FALSE;
}

static bool has_layer(const char *name)
{
    uint32_t n = 0;
    if (vkEnumerateInstanceLayerProperties(&n, NULL) != VK_SUCCESS)
        return false;
    VkLayerProperties *ls = calloc(n ? n : 1, sizeof *ls);
    bool found = false;
    if (ls && vkEnumerateInstanceLayerProperties(&n, ls) == VK_SUCCESS)
        for (uint32_t i = 0; i < n; i++)
            if (!strcmp(ls[i].layerName, name))
                found = true;
    free(ls);
    return found;
}

static bool create_instance(rt_device *d, const rt_device_desc *desc, rt_error *e)
{
    const char *env = getenv("SPLAT_VALIDATE");
    bool validate = desc->validate || (env && !strcmp(env, "1"));
    const char *layer = "VK_LAYER_KHRONOS_validation";
    if (validate && !has_layer(layer))
        return rt_fail(e, RT_E_NO_VALIDATION, layer);
    const char *exts[16];
    uint32_t next = 0;
    for (uint32_t i = 0; i < desc->ninstance_exts && next < 15; i++)
        exts[next++] = desc->instance_exts[i];
    if (validate)
        exts[next++] = VK_EXT_DEBUG_UTILS_EXTENSION_NAME;

    VkApplicationInfo app = {
        .sType = VK_STRUCTURE_TYPE_APPLICATION_INFO,
        .pApplicationName = "splatview",
        .pEngineName = "splatrt",
        .apiVersion = VK_API_VERSION_1_2,
    };
    VkDebugUtilsMessengerCreateInfoEXT mci = {
        .sType = VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT,
        .messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT |
                           VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT,
        .messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT |
                       VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                       VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT,
        .pfnUserCallback = on_message,
        .pUserData = d,
    };
    /* synchronization validation too: hazards between the frame's passes
     * (render_plan.c's barriers) and between submissions */
    static const VkValidationFeatureEnableEXT sync[] = {
        VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT,
    };
    VkValidationFeaturesEXT features = {
        .sType = VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT,
        .enabledValidationFeatureCount = 1,
        .pEnabledValidationFeatures = sync,
    };
    mci.pNext = &features;
    VkInstanceCreateInfo ci = {
        .sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO,
        .pNext = validate ? &mci : NULL,
        .pApplicationInfo = &app,
        .enabledLayerCount = validate ? 1 : 0,
        .ppEnabledLayerNames = &layer,
        .enabledExtensionCount = next,
        .ppEnabledExtensionNames = exts,
    };
    RT_VK(e, vkCreateInstance(&ci, NULL, &d->instance));
    d->validating = validate;
    if (validate) {
        PFN_vkCreateDebugUtilsMessengerEXT create = (PFN_vkCreateDebugUtilsMessengerEXT)
            vkGetInstanceProcAddr(d->instance, "vkCreateDebugUtilsMessengerEXT");
        if (!create)
            return rt_fail(e, RT_E_VULKAN, "vkGetInstanceProcAddr(vkCreateDebugUtilsMessengerEXT)",
                           "not found");
        mci.pNext = NULL;   /* the features were the instance's */
        RT_VK(e, create(d->instance, &mci, NULL, &d->messenger));
    }
    return true;
}

/* ---- physical device ----------------------------------------------------- */

static int type_rank(VkPhysicalDeviceType t)
{
    switch (t) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU:   return 0;
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return 1;
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU:    return 2;
    case VK_PHYSICAL_DEVICE_TYPE_CPU:            return 3;
    default:                                     return 4;
    }
}

static bool contains_nocase(const char *hay, const char *needle)
{
    size_t n = strlen(needle);
    for (; *hay; hay++) {
        size_t i = 0;
        while (i < n && hay[i] &&
               tolower((unsigned char)hay[i]) == tolower((unsigned char)needle[i]))
            i++;
        if (i == n)
            return true;
    }
    return n == 0;
}

static int graphics_family(VkPhysicalDevice p)
{
    uint32_t n = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(p, &n, NULL);
    VkQueueFamilyProperties *q = calloc(n ? n : 1, sizeof *q);
    int found = -1;
    if (!q)
        return -1;
    vkGetPhysicalDeviceQueueFamilyProperties(p, &n, q);
    for (uint32_t i = 0; i < n && found < 0; i++)
        if (q[i].queueFlags & VK_QUEUE_GRAPHICS_BIT)
            found = (int)i;
    free(q);
    return found;
}

static bool pick_device(rt_device *d, const rt_device_desc *desc, rt_error *e)
{
    uint32_t n = 0;
    RT_VK(e, vkEnumeratePhysicalDevices(d->instance, &n, NULL));
    if (n == 0)
        return rt_fail(e, RT_E_NO_DEVICE, "the Vulkan loader reports no device");
    VkPhysicalDevice *all = calloc(n, sizeof *all);
    if (!all)
        return rt_fail(e, RT_E_NO_DEVICE, "out of memory");
    VkResult r = vkEnumeratePhysicalDevices(d->instance, &n, all);
    if (r != VK_SUCCESS) {
        free(all);
        return rt_fail(e, RT_E_VULKAN, "vkEnumeratePhysicalDevices", rt_vk_result_name(r));
    }
    const char *sel = desc->select ? desc->select : getenv("SPLAT_DEVICE");
    if (sel && !*sel)
        sel = NULL;
    char *end = NULL;
    long index = sel ? strtol(sel, &end, 10) : -1;
    bool by_index = sel && end && *end == '\0';

    int best = -1, best_rank = 99;
    for (uint32_t i = 0; i < n; i++) {
        VkPhysicalDeviceProperties pr;
        vkGetPhysicalDeviceProperties(all[i], &pr);
        if (pr.apiVersion < VK_API_VERSION_1_2 || graphics_family(all[i]) < 0)
            continue;
        if (by_index && (long)i != index)
            continue;
        if (sel && !by_index && !contains_nocase(pr.deviceName, sel))
            continue;
        int rank = type_rank(pr.deviceType);
        if (rank < best_rank) {
            best = (int)i;
            best_rank = rank;
        }
    }
    if (best < 0) {
        free(all);
        if (sel)
            return rt_fail(e, RT_E_NO_DEVICE, "SPLAT_DEVICE selects no Vulkan 1.2 device with graphics");
        return rt_fail(e, RT_E_NO_DEVICE, "no Vulkan 1.2 device with a graphics queue");
    }
    d->phys = all[best];
    free(all);
    vkGetPhysicalDeviceProperties(d->phys, &d->props);
    vkGetPhysicalDeviceMemoryProperties(d->phys, &d->mem);
    d->queue_family = (uint32_t)graphics_family(d->phys);
    return true;
}

/* glslang's one-time setup on a thread (rt_internal.h: why). */
static void *warm_up(void *arg)
{
    (void)arg;
    uint32_t *words = NULL;
    size_t n = 0;
    char *log = NULL;
    /* any stage: glslang sets up the tables of all of them at once */
    spv_compile("#version 450\nlayout(local_size_x = 1) in;\nvoid main() {}\n",
                SPV_STAGE_COMPUTE, "glslang warm-up", &words, &n, &log);
    free(words);
    free(log);
    return NULL;
}

static void glslang_warm_up(rt_device *d)
{
    const char *env = getenv("SPLAT_GLSLANG_WARM_UP");
    if (d->warming || (env && !strcmp(env, "0")))
        return;
    d->warming = pthread_create(&d->glslang_warm, NULL, warm_up, NULL) == 0;
}

bool rt_device_create(rt_device *d, const rt_device_desc *desc, rt_error *e)
{
    static const rt_device_desc zero;
    if (!desc)
        desc = &zero;
    memset(d, 0, sizeof *d);
    glslang_warm_up(d);   /* beside the instance and device creation */
    if (!create_instance(d, desc, e) || !pick_device(d, desc, e)) {
        rt_device_destroy(d);
        return false;
    }
    VkPhysicalDeviceFeatures have, want = {0};
    vkGetPhysicalDeviceFeatures(d->phys, &have);
    want.fillModeNonSolid = have.fillModeNonSolid;
    d->wireframe = have.fillModeNonSolid;
    want.textureCompressionBC = have.textureCompressionBC;   /* sparse masks */
    d->bc = have.textureCompressionBC;
    /* the forward path's counting variant (abi.h SPLAT_COUNT) */
    VkPhysicalDeviceSubgroupProperties sg = {
        .sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SUBGROUP_PROPERTIES,
    };
    VkPhysicalDeviceProperties2 p2 = {
        .sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, .pNext = &sg,
    };
    vkGetPhysicalDeviceProperties2(d->phys, &p2);
    want.fragmentStoresAndAtomics = have.fragmentStoresAndAtomics;
    d->count_fragments = have.fragmentStoresAndAtomics &&
                         (sg.supportedStages & VK_SHADER_STAGE_FRAGMENT_BIT) &&
                         (sg.supportedOperations & VK_SUBGROUP_FEATURE_VOTE_BIT);
    /* the shared vertex shader cuts terrain holes with a clip distance */
    if (!have.shaderClipDistance) {
        rt_device_destroy(d);
        return rt_fail(e, RT_E_NO_FORMAT, "write clip distances (shaderClipDistance: terrain holes)");
    }
    want.shaderClipDistance = VK_TRUE;
    /* 64-bit storage buffer atomics: the undergrowth's compute rasteriser
     * in one pass (undergrowth_craster.c), else its two-pass fallback */
    VkPhysicalDeviceShaderAtomicInt64Features a64 = {
        .sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SHADER_ATOMIC_INT64_FEATURES,
    };
    VkPhysicalDeviceFeatures2 f2 = { .sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2,
                                     .pNext = &a64 };
    vkGetPhysicalDeviceFeatures2(d->phys, &f2);
    d->int64_atomics = have.shaderInt64 && a64.shaderBufferInt64Atomics;
    want.shaderInt64 = d->int64_atomics;
    VkPhysicalDeviceShaderAtomicInt64Features a64_on = {
        .sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SHADER_ATOMIC_INT64_FEATURES,
        .shaderBufferInt64Atomics = VK_TRUE,
    };

    float prio = 1.0f;
    VkDeviceQueueCreateInfo qci = {
        .sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO,
        .queueFamilyIndex = d->queue_family,
        .queueCount = 1,
        .pQueuePriorities = &prio,
    };
    const char *swap = VK_KHR_SWAPCHAIN_EXTENSION_NAME;
    VkDeviceCreateInfo dci = {
        .sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO,
        .pNext = d->int64_atomics ? &a64_on : NULL,
        .queueCreateInfoCount = 1,
        .pQueueCreateInfos = &qci,
        .enabledExtensionCount = desc->swapchain ? 1 : 0,
        .ppEnabledExtensionNames = &swap,
        .pEnabledFeatures = &want,
    };
    VkResult r = vkCreateDevice(d->phys, &dci, NULL, &d->dev);
    if (r != VK_SUCCESS) {
        rt_device_destroy(d);
        return rt_fail(e, RT_E_VULKAN, "vkCreateDevice", rt_vk_result_name(r));
    }
    vkGetDeviceQueue(d->dev, d->queue_family, 0, &d->queue);
    VkCommandPoolCreateInfo pci = {
        .sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO,
        .flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT,
        .queueFamilyIndex = d->queue_family,
    };
    r = vkCreateCommandPool(d->dev, &pci, NULL, &d->pool);
    if (r != VK_SUCCESS) {
        rt_device_destroy(d);
        return rt_fail(e, RT_E_VULKAN, "vkCreateCommandPool", rt_vk_result_name(r));
    }
    return true;
}

void rt_device_destroy(rt_device *d)
{
    if (d->warming)   /* before exit can tear glslang down under it */
        pthread_join(d->glslang_warm, NULL);
    d->warming = false;
    if (d->dev) {
        vkDeviceWaitIdle(d->dev);
        if (d->pool)
            vkDestroyCommandPool(d->dev, d->pool, NULL);
        vkDestroyDevice(d->dev, NULL);
    }
    if (d->messenger) {
        PFN_vkDestroyDebugUtilsMessengerEXT destroy = (PFN_vkDestroyDebugUtilsMessengerEXT)
            vkGetInstanceProcAddr(d->instance, "vkDestroyDebugUtilsMessengerEXT");
        if (destroy)
            destroy(d->instance, d->messenger, NULL);
    }
    if (d->instance)
        vkDestroyInstance(d->instance, NULL);
    int messages = d->messages;
    bool validating = d->validating;
    memset(d, 0, sizeof *d);
    d->messages = messages;     /* still readable after teardown */
    d->validating = validating;
}

int rt_device_messages(const rt_device *d) { return d->messages; }

/* ---- memory ------------------------------------------------------------ */

static bool alloc_memory(rt_device *d, VkMemoryRequirements req,
                         VkMemoryPropertyFlags want, VkDeviceMemory *mem,
                         rt_error *e)
{
    for (uint32_t i = 0; i < d->mem.memoryTypeCount; i++) {
        if (!(req.memoryTypeBits & (1u << i)) ||
            (d->mem.memoryTypes[i].propertyFlags & want) != want)
            continue;
        VkMemoryAllocateInfo ai = {
            .sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO,
            .allocationSize = req.size,
            .memoryTypeIndex = i,
        };
        RT_VK(e, vkAllocateMemory(d->dev, &ai, NULL, mem));
        return true;
    }
    return rt_fail(e, RT_E_VULKAN, "finding a memory type", "none fits");
}

bool rt_buffer_create(rt_device *d, VkDeviceSize size, VkBufferUsageFlags usage,
                      bool host_visible, rt_buffer *b, rt_error *e)
{
    memset(b, 0, sizeof *b);
    VkBufferCreateInfo ci = {
        .sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO,
        .size = size ? size : 16,
        .usage = usage,
        .sharingMode = VK_SHARING_MODE_EXCLUSIVE,
    };
    RT_VK(e, vkCreateBuffer(d->dev, &ci, NULL, &b->buf));
    b->size = ci.size;
    VkMemoryRequirements req;
    vkGetBufferMemoryRequirements(d->dev, b->buf, &req);
    VkMemoryPropertyFlags want = host_visible
        ? VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT
        : VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT;
    if (!alloc_memory(d, req, want, &b->mem, e))
        return false;
    RT_VK(e, vkBindBufferMemory(d->dev, b->buf, b->mem, 0));
    if (host_visible)
        RT_VK(e, vkMapMemory(d->dev, b->mem, 0, VK_WHOLE_SIZE, 0, &b->map));
    return true;
}

void rt_buffer_destroy(rt_device *d, rt_buffer *b)
{
    if (b->buf)
        vkDestroyBuffer(d->dev, b->buf, NULL);
    if (b->mem)
        vkFreeMemory(d->dev, b->mem, NULL);
    memset(b, 0, sizeof *b);
}

bool rt_image_create(rt_device *d, uint32_t w, uint32_t h, uint32_t layers,
                     bool array, uint32_t mips, VkFormat fmt, VkImageUsageFlags usage,
                     VkImageAspectFlags aspect, rt_image *img, rt_error *e)
{
    memset(img, 0, sizeof *img);
    img->format = fmt;
    img->width = w;
    img->height = h;
    img->layers = layers ? layers : 1;
    img->mips = mips ? mips : 1;
    VkImageCreateInfo ci = {
        .sType = VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO,
        .imageType = VK_IMAGE_TYPE_2D,
        .format = fmt,
        .extent = { w, h, 1 },
        .mipLevels = img->mips,
        .arrayLayers = img->layers,
        .samples = VK_SAMPLE_COUNT_1_BIT,
        .tiling = VK_IMAGE_TILING_OPTIMAL,
        .usage = usage,
        .sharingMode = VK_SHARING_MODE_EXCLUSIVE,
        .initialLayout = VK_IMAGE_LAYOUT_UNDEFINED,
    };
    RT_VK(e, vkCreateImage(d->dev, &ci, NULL, &img->img));
    VkMemoryRequirements req;
    vkGetImageMemoryRequirements(d->dev, img->img, &req);
    if (!alloc_memory(d, req, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, &img->mem, e))
        return false;
    RT_VK(e, vkBindImageMemory(d->dev, img->img, img->mem, 0));
    VkImageViewCreateInfo vi = {
        .sType = VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO,
        .image = img->img,
        .viewType = array ? VK_IMAGE_VIEW_TYPE_2D_ARRAY : VK_IMAGE_VIEW_TYPE_2D,
        .format = fmt,
        .subresourceRange = { aspect, 0, img->mips, 0, img->layers },
    };
    RT_VK(e, vkCreateImageView(d->dev, &vi, NULL, &img->view));
    return true;
}

void rt_image_destroy(rt_device *d, rt_image *img)
{
    if (img->view)
        vkDestroyImageView(d->dev, img->view, NULL);
    if (img->img)
        vkDestroyImage(d->dev, img->img, NULL);
    if (img->mem)
        vkFreeMemory(d->dev, img->mem, NULL);
    memset(img, 0, sizeof *img);
}

bool rt_format_supports(rt_device *d, VkFormat f, VkFormatFeatureFlags need)
{
    VkFormatProperties fp;
    vkGetPhysicalDeviceFormatProperties(d->phys, f, &fp);
    return (fp.optimalTilingFeatures & need) == need;
}

bool rt_oneshot_begin(rt_device *d, VkCommandBuffer *cb, rt_error *e)
{
    VkCommandBufferAllocateInfo ai = {
        .sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO,
        .commandPool = d->pool,
        .level = VK_COMMAND_BUFFER_LEVEL_PRIMARY,
        .commandBufferCount = 1,
    };
    RT_VK(e, vkAllocateCommandBuffers(d->dev, &ai, cb));
    VkCommandBufferBeginInfo bi = {
        .sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO,
        .flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT,
    };
    RT_VK(e, vkBeginCommandBuffer(*cb, &bi));
    return true;
}

bool rt_oneshot_end(rt_device *d, VkCommandBuffer cb, rt_error *e)
{
    VkResult r = vkEndCommandBuffer(cb);
    if (r == VK_SUCCESS) {
        VkSubmitInfo si = {
            .sType = VK_STRUCTURE_TYPE_SUBMIT_INFO,
            .commandBufferCount = 1,
            .pCommandBuffers = &cb,
        };
        r = vkQueueSubmit(d->queue, 1, &si, VK_NULL_HANDLE);
        if (r == VK_SUCCESS)
            r = vkQueueWaitIdle(d->queue);
    }
    vkFreeCommandBuffers(d->dev, d->pool, 1, &cb);
    if (r != VK_SUCCESS)
        return rt_fail(e, RT_E_VULKAN, "one-time submit", rt_vk_result_name(r));
    return true;
}

VkSamplerAddressMode rt_sampler_wrap(int ir_wrap)
{
    switch ((enum ir_wrap)ir_wrap) {
    case IR_WRAP_CLAMP:  return VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
    case IR_WRAP_MIRROR: return VK_SAMPLER_ADDRESS_MODE_MIRRORED_REPEAT;
    case IR_WRAP_REPEAT: break;
    }
    return VK_SAMPLER_ADDRESS_MODE_REPEAT;
}

void rt_cmd_barrier(VkCommandBuffer cb, VkPipelineStageFlags src, VkAccessFlags sa,
                    VkPipelineStageFlags dst, VkAccessFlags da)
{
    VkMemoryBarrier mb = { .sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER,
                           .srcAccessMask = sa, .dstAccessMask = da };
    vkCmdPipelineBarrier(cb, src, dst, 0, 1, &mb, 0, NULL, 0, NULL);
}

void rt_cmd_image_barrier(VkCommandBuffer cb, VkImage img, uint32_t mip, uint32_t nmips,
                          uint32_t layers, VkImageLayout from, VkImageLayout to,
                          VkAccessFlags src_access, VkAccessFlags dst_access,
                          VkPipelineStageFlags src, VkPipelineStageFlags dst)
{
    VkImageMemoryBarrier b = {
        .sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER,
        .srcAccessMask = src_access,
        .dstAccessMask = dst_access,
        .oldLayout = from,
        .newLayout = to,
        .srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED,
        .dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED,
        .image = img,
        .subresourceRange = { VK_IMAGE_ASPECT_COLOR_BIT, mip, nmips, 0, layers },
    };
    vkCmdPipelineBarrier(cb, src, dst, 0, 0, NULL, 0, NULL, 1, &b);
}

bool rt_image_upload(rt_device *d, rt_image *img, const void *data,
                     size_t bytes, rt_error *e)
{
    rt_buffer staging;
    if (!rt_buffer_create(d, bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, true, &staging, e))
        return false;
    memcpy(staging.map, data, bytes);
    VkCommandBuffer cb;
    if (!rt_oneshot_begin(d, &cb, e)) {
        rt_buffer_destroy(d, &staging);
        return false;
    }
    rt_cmd_image_barrier(cb, img->img, 0, img->mips, img->layers, VK_IMAGE_LAYOUT_UNDEFINED,
            VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 0, VK_ACCESS_TRANSFER_WRITE_BIT,
            VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT);
    VkBufferImageCopy copy = {
        .imageSubresource = { VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, img->layers },
        .imageExtent = { img->width, img->height, 1 },
    };
    vkCmdCopyBufferToImage(cb, staging.buf, img->img,
                           VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &copy);
    /* Mip chain by successive blits: mip i-1 -> mip i. */
    int32_t w = (int32_t)img->width, h = (int32_t)img->height;
    for (uint32_t m = 1; m < img->mips; m++) {
        rt_cmd_image_barrier(cb, img->img, m - 1, 1, img->layers, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_ACCESS_TRANSFER_WRITE_BIT,
                VK_ACCESS_TRANSFER_READ_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
                VK_PIPELINE_STAGE_TRANSFER_BIT);
        int32_t nw = w > 1 ? w / 2 : 1, nh = h > 1 ? h / 2 : 1;
        VkImageBlit blit = {
            .srcSubresource = { VK_IMAGE_ASPECT_COLOR_BIT, m - 1, 0, img->layers },
            .srcOffsets = { { 0, 0, 0 }, { w, h, 1 } },
            .dstSubresource = { VK_IMAGE_ASPECT_COLOR_BIT, m, 0, img->layers },
            .dstOffsets = { { 0, 0, 0 }, { nw, nh, 1 } },
        };
        vkCmdBlitImage(cb, img->img, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, img->img,
                       VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &blit, VK_FILTER_LINEAR);
        rt_cmd_image_barrier(cb, img->img, m - 1, 1, img->layers, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, VK_ACCESS_TRANSFER_READ_BIT,
                VK_ACCESS_SHADER_READ_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
                VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT);
        w = nw;
        h = nh;
    }
    rt_cmd_image_barrier(cb, img->img, img->mips - 1, 1, img->layers, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
            VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, VK_ACCESS_TRANSFER_WRITE_BIT,
            VK_ACCESS_SHADER_READ_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
            VK_PIPELINE_STAGE_VERTEX_SHADER_BIT | VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT);
    bool ok = rt_oneshot_end(d, cb, e);
    rt_buffer_destroy(d, &staging);
    return ok;
}

bool rt_image_upload_levels(rt_device *d, rt_image *img, const uint8_t *const *levels,
                            rt_error *e)
{
    /* one staging buffer holding every level of every layer, one copy
     * region per level and layer */
    size_t total = 0;
    for (uint32_t m = 0; m < img->mips; m++) {
        size_t w = img->width >> m ? img->width >> m : 1;
        size_t h = img->height >> m ? img->height >> m : 1;
        total += w * h * 4 * img->layers;
    }
    uint32_t nregions = img->mips * img->layers;
    VkBufferImageCopy *regions = calloc(nregions, sizeof *regions);
    if (!regions)
        return rt_fail(e, RT_E_VULKAN, "mip upload", "out of memory");
    rt_buffer staging;
    if (!rt_buffer_create(d, total, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, true, &staging, e)) {
        free(regions);
        return false;
    }
    size_t off = 0;
    for (uint32_t l = 0; l < img->layers; l++)
        for (uint32_t m = 0; m < img->mips; m++) {
            uint32_t w = img->width >> m ? img->width >> m : 1;
            uint32_t h = img->height >> m ? img->height >> m : 1;
            memcpy((uint8_t *)staging.map + off, levels[l * img->mips + m], (size_t)w * h * 4);
            regions[l * img->mips + m] = (VkBufferImageCopy){
                .bufferOffset = off,
                .imageSubresource = { VK_IMAGE_ASPECT_COLOR_BIT, m, l, 1 },
                .imageExtent = { w, h, 1 },
            };
            off += (size_t)w * h * 4;
        }
    VkCommandBuffer cb;
    bool ok = rt_oneshot_begin(d, &cb, e);
    if (ok) {
        rt_cmd_image_barrier(cb, img->img, 0, img->mips, img->layers, VK_IMAGE_LAYOUT_UNDEFINED,
                VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 0, VK_ACCESS_TRANSFER_WRITE_BIT,
                VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT);
        vkCmdCopyBufferToImage(cb, staging.buf, img->img, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                               nregions, regions);
        rt_cmd_image_barrier(cb, img->img, 0, img->mips, img->layers, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, VK_ACCESS_TRANSFER_WRITE_BIT,
                VK_ACCESS_SHADER_READ_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
                VK_PIPELINE_STAGE_VERTEX_SHADER_BIT | VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT);
        ok = rt_oneshot_end(d, cb, e);
    }
    rt_buffer_destroy(d, &staging);
    free(regions);
    return ok;
}
