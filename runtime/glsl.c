/* glsl.c — GLSL to SPIR-V through glslang's C API, in process, for the
 * runtime's own shaders (the resolve pass of the multi-pass reference, the
 * viewer's tone map) and the test fixtures; and SPIRV-Tools validation of
 * the modules a pack brings, so a corrupt file is an error message and never
 * a validation error or a driver crash. */
#include "splatrt.h"

#include <stdlib.h>
#include <string.h>

#include <glslang/Include/glslang_c_interface.h>
#include <glslang/Public/resource_limits_c.h>
#include <spirv-tools/libspirv.h>

bool rt_glsl_compile(const char *glsl, VkShaderStageFlagBits stage,
                     const char *name, uint32_t **words, size_t *nwords,
                     rt_error *e)
{
    static bool initialised;
    if (!initialised) {
        glslang_initialize_process();   /* reference counted; never finalised */
        initialised = true;
    }
    glslang_input_t in = {
        .language = GLSLANG_SOURCE_GLSL,
        .stage = stage == VK_SHADER_STAGE_VERTEX_BIT ? GLSLANG_STAGE_VERTEX
                                                     : GLSLANG_STAGE_FRAGMENT,
        .client = GLSLANG_CLIENT_VULKAN,
        .client_version = GLSLANG_TARGET_VULKAN_1_2,
        .target_language = GLSLANG_TARGET_SPV,
        .target_language_version = GLSLANG_TARGET_SPV_1_5,
        .code = glsl,
        .default_version = 450,
        .default_profile = GLSLANG_NO_PROFILE,
        .messages = GLSLANG_MSG_SPV_RULES_BIT | GLSLANG_MSG_VULKAN_RULES_BIT,
        .resource = glslang_default_resource(),
    };
    glslang_shader_t *sh = glslang_shader_create(&in);
    if (!sh)
        return rt_fail(e, RT_E_SHADER, name, "glslang_shader_create failed");
    if (!glslang_shader_preprocess(sh, &in) || !glslang_shader_parse(sh, &in)) {
        rt_fail(e, RT_E_SHADER, name, glslang_shader_get_info_log(sh));
        glslang_shader_delete(sh);
        return false;
    }
    glslang_program_t *prog = glslang_program_create();
    glslang_program_add_shader(prog, sh);
    bool ok = glslang_program_link(prog, GLSLANG_MSG_SPV_RULES_BIT | GLSLANG_MSG_VULKAN_RULES_BIT);
    if (!ok) {
        rt_fail(e, RT_E_SHADER, name, glslang_program_get_info_log(prog));
    } else {
        glslang_program_SPIRV_generate(prog, in.stage);
        size_t n = glslang_program_SPIRV_get_size(prog);
        *words = malloc(n * sizeof **words);
        if (!*words) {
            ok = rt_fail(e, RT_E_SHADER, name, "out of memory");
        } else {
            glslang_program_SPIRV_get(prog, *words);
            *nwords = n;
        }
    }
    glslang_program_delete(prog);
    glslang_shader_delete(sh);
    return ok;
}

bool rt_spirv_validate(const uint32_t *words, size_t nwords, const char *name,
                       rt_error *e)
{
    if (nwords < 5 || words[0] != 0x07230203u)
        return rt_fail(e, RT_E_PACK_SPIRV, name, "no SPIR-V header (magic 0x07230203)");
    spv_context ctx = spvContextCreate(SPV_ENV_VULKAN_1_2);
    spv_diagnostic diag = NULL;
    spv_const_binary_t bin = { words, nwords };
    spv_result_t r = spvValidate(ctx, &bin, &diag);
    bool ok = r == SPV_SUCCESS;
    if (!ok)
        rt_fail(e, RT_E_PACK_SPIRV, name,
                diag && diag->error ? diag->error : "spirv-val rejects it");
    spvDiagnosticDestroy(diag);
    spvContextDestroy(ctx);
    return ok;
}
