/* shader_compile.c — the runtime's shader compiler and SPIR-V checks, on top of
 * libsplatc's spv.h (glslang's C API in process, SPIRV-Tools validation):
 * the runtime's own shaders (the multi-pass resolve pass, the viewer's tone
 * map) and the test fixtures compile through it, and every module a pack
 * brings is validated before the driver sees it, so a corrupt file is an
 * error message, never a validation error or a driver crash. */
#include "rt_internal.h"

#include <stdlib.h>

#include "spv.h"

bool rt_glsl_compile(const char *glsl, VkShaderStageFlagBits stage,
                     const char *name, uint32_t **words, size_t *nwords,
                     rt_error *e)
{
    char *log = NULL;
    int st = stage == VK_SHADER_STAGE_VERTEX_BIT  ? SPV_STAGE_VERTEX :
             stage == VK_SHADER_STAGE_COMPUTE_BIT ? SPV_STAGE_COMPUTE : SPV_STAGE_FRAGMENT;
    if (!spv_compile(glsl, st, name, words, nwords, &log)) {
        rt_fail(e, RT_E_SHADER, name, log ? log : "glslang failed");
        free(log);
        return false;
    }
    free(log);
    return true;
}

bool rt_spirv_validate(const uint32_t *words, size_t nwords, const char *name,
                       rt_error *e)
{
    if (nwords < 5 || words[0] != 0x07230203u)
        return rt_fail(e, RT_E_PACK_SPIRV, name, "no SPIR-V header (magic 0x07230203)");
    char *log = NULL;
    if (!spv_validate(words, nwords, &log)) {
        rt_fail(e, RT_E_PACK_SPIRV, name, log ? log : "spirv-val rejects it");
        free(log);
        return false;
    }
    free(log);
    return true;
}

bool rt_glsl_module(rt_device *d, const char *glsl, VkShaderStageFlagBits stage,
                    const char *name, const rt_interface *check, VkShaderModule *out,
                    rt_error *e)
{
    uint32_t *w = NULL;
    size_t n = 0;
    bool ok = rt_glsl_compile(glsl, stage, name, &w, &n, e) && rt_spirv_validate(w, n, name, e) &&
              (!check || rt_spirv_check(w, n, name, check, e));
    if (ok) {
        VkShaderModuleCreateInfo ci = {
            .sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO,
            .codeSize = n * 4, .pCode = w,
        };
        VkResult r = vkCreateShaderModule(d->dev, &ci, NULL, out);
        if (r != VK_SUCCESS)
            ok = rt_fail(e, RT_E_VULKAN, "vkCreateShaderModule", rt_vk_result_name(r));
    }
    free(w);
    return ok;
}

static bool compute_pipeline(rt_device *d, VkPipelineCache cache, VkPipelineLayout layout,
                             VkShaderModule m, VkPipeline *out, rt_error *e);

bool rt_glsl_compute_pipeline(rt_device *d, VkPipelineCache cache, VkPipelineLayout layout,
                              const char *glsl, const char *name, const rt_interface *check,
                              VkPipeline *out, rt_error *e)
{
    VkShaderModule m;
    if (!rt_glsl_module(d, glsl, VK_SHADER_STAGE_COMPUTE_BIT, name, check, &m, e))
        return false;
    return compute_pipeline(d, cache, layout, m, out, e);
}

bool rt_spirv_compute_pipeline(rt_device *d, VkPipelineCache cache, VkPipelineLayout layout,
                               const rt_spirv *s, VkPipeline *out, rt_error *e)
{
    VkShaderModuleCreateInfo ci = {
        .sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO,
        .codeSize = s->nwords * 4, .pCode = s->words,
    };
    VkShaderModule m;
    VkResult r = vkCreateShaderModule(d->dev, &ci, NULL, &m);
    if (r != VK_SUCCESS)
        return rt_fail(e, RT_E_VULKAN, "vkCreateShaderModule", rt_vk_result_name(r));
    return compute_pipeline(d, cache, layout, m, out, e);
}

/* A compute pipeline of module `m`, which it destroys. */
static bool compute_pipeline(rt_device *d, VkPipelineCache cache, VkPipelineLayout layout,
                             VkShaderModule m, VkPipeline *out, rt_error *e)
{
    VkComputePipelineCreateInfo ci = {
        .sType = VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO,
        .stage = { .sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO,
                   .stage = VK_SHADER_STAGE_COMPUTE_BIT, .module = m, .pName = "main" },
        .layout = layout,
    };
    VkResult r = vkCreateComputePipelines(d->dev, cache, 1, &ci, NULL, out);
    vkDestroyShaderModule(d->dev, m, NULL);
    if (r != VK_SUCCESS)
        return rt_fail(e, RT_E_VULKAN, "vkCreateComputePipelines", rt_vk_result_name(r));
    return true;
}
