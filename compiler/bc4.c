/* bc4.c — BC4 (DXT5A / RGTC1 unorm) blocks for the sparse mask atlas.
 *
 * Encoding is stb_dxt's stb_compress_bc4_block (libstb already carries the
 * implementation, so no STB_DXT_IMPLEMENTATION here).  Decoding follows the
 * BC4_UNORM palette of the Vulkan / D3D specification, in float, without
 * rounding the interpolated values to 8 bits:
 *   r0 >  r1: p[2..7] = ((8 - i) r0 + (i - 1) r1) / 7
 *   r0 <= r1: p[2..5] = ((6 - i) r0 + (i - 1) r1) / 5, p6 = 0, p7 = 255
 * Indices: 16 x 3 bits, little-endian in bytes 2..7, texel order row-major.
 */
#include "sparse.h"

#include <stb_dxt.h>

void sparse_bc4_encode(uint8_t out[8], const uint8_t in[16])
{
    stb_compress_bc4_block(out, in);
}

void sparse_bc4_decode(const uint8_t in[8], float out[16])
{
    float r0 = in[0], r1 = in[1], p[8];
    p[0] = r0;
    p[1] = r1;
    if (in[0] > in[1]) {
        for (int i = 2; i < 8; i++)
            p[i] = ((float)(8 - i) * r0 + (float)(i - 1) * r1) / 7.0f;
    } else {
        for (int i = 2; i < 6; i++)
            p[i] = ((float)(6 - i) * r0 + (float)(i - 1) * r1) / 5.0f;
        p[6] = 0.0f;
        p[7] = 255.0f;
    }
    uint64_t bits = 0;
    for (int i = 0; i < 6; i++)
        bits |= (uint64_t)in[2 + i] << (8 * i);
    for (int k = 0; k < 16; k++)
        out[k] = p[(bits >> (3 * k)) & 7] / 255.0f;
}
