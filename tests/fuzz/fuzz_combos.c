/* fuzz_combos.c — libFuzzer target for the combos.bin reader
 * (rt_combos_parse).  Input: u8 cells_x - 1, u8 cells_z - 1, u16 ncombos
 * (little-endian), one little-endian i32 offset per level, then the file's
 * bytes. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "rt_internal.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 4)
        return 0;
    int cx = data[0] + 1, cz = data[1] + 1, ncombos = data[2] | data[3] << 8;
    int nlevels = rt_level_count(cx, cz);
    size_t head = 4 + 4 * (size_t)nlevels;
    if (size < head)
        return 0;
    int64_t offsets[32];
    for (int L = 0; L < nlevels && L < 32; L++) {
        const uint8_t *o = data + 4 + 4 * L;
        offsets[L] = (int32_t)((uint32_t)o[0] | (uint32_t)o[1] << 8 | (uint32_t)o[2] << 16 |
                               (uint32_t)o[3] << 24);
    }
    rt_pack_level levels[32];
    memset(levels, 0, sizeof levels);
    rt_error e = { 0 };
    rt_combos_parse(data + head, size - head, cx, cz, offsets, ncombos, false, levels, "combos.bin", &e);
    for (int L = 0; L < nlevels && L < 32; L++)
        free(levels[L].ids);
    rt_error_clear(&e);
    return 0;
}
