/* fuzz_spirv.c — libFuzzer target for the shader checks of the pack
 * loader: spirv-val (rt_spirv_validate), then, for a module it accepts,
 * SPIRV-Cross reflection against a role's interface (rt_spirv_check).  The
 * first byte picks the role and the painted format; the rest is the module.
 * The pack behind the interface has three textures and a 64-byte params
 * block. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "rt_internal.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 1 || (size - 1) % 4 || size > (1 << 20))
        return 0;
    rt_pack p;
    memset(&p, 0, sizeof p);
    p.ntextures = 3;
    p.params_size = 64;
    sparse_masks sparse;
    if (data[0] & 4)
        p.sparse = &sparse;
    size_t n = (size - 1) / 4;
    uint32_t *words = malloc(n ? n * 4 : 4);
    if (!words)
        return 0;
    memcpy(words, data + 1, n * 4);
    rt_error e = { 0 };
    rt_interface in;
    if (rt_spirv_validate(words, n, "fuzz.spv", &e) &&
        rt_interface_for(&p, (rt_shader_role)(data[0] % RT_ROLE_COUNT), &in)) {
        rt_spirv_check(words, n, "fuzz.spv", &in, &e);
        rt_interface_free(&in);
    }
    rt_error_clear(&e);
    free(words);
    return 0;
}
