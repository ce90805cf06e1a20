/* big_png OUT SIDE — write a SIDE x SIDE 8-bit greyscale PNG of zeros to
 * OUT, streamed row by row through zlib (a 16384^2 image is about 250 KB
 * and a fraction of a second): the "small PNG" of issue 34's placed-mask
 * cases, which decodes to SIDE^2 bytes. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <zlib.h>

static void put32(uint8_t *p, uint32_t v)
{
    p[0] = (uint8_t)(v >> 24), p[1] = (uint8_t)(v >> 16), p[2] = (uint8_t)(v >> 8), p[3] = (uint8_t)v;
}

static int chunk(FILE *f, const char *type, const uint8_t *data, uint32_t n)
{
    uint8_t head[8];
    put32(head, n);
    memcpy(head + 4, type, 4);
    uLong crc = crc32(crc32(0, (const Bytef *)type, 4), data, n);
    uint8_t tail[4];
    put32(tail, (uint32_t)crc);
    return fwrite(head, 1, 8, f) == 8 && (n == 0 || fwrite(data, 1, n, f) == n) &&
           fwrite(tail, 1, 4, f) == 4;
}

int main(int argc, char **argv)
{
    if (argc != 3) {
        fprintf(stderr, "usage: big_png OUT SIDE\n");
        return 2;
    }
    uint32_t side = (uint32_t)strtoul(argv[2], NULL, 10);
    FILE *f = fopen(argv[1], "wb");
    if (!f || side == 0)
        return 1;
    static const uint8_t sig[8] = { 0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n' };
    uint8_t ihdr[13] = { 0 };
    put32(ihdr, side);
    put32(ihdr + 4, side);
    ihdr[8] = 8;   /* bit depth; colour type 0 (grey), deflate, no filter, no interlace */
    int ok = fwrite(sig, 1, 8, f) == 8 && chunk(f, "IHDR", ihdr, 13);
    z_stream z = { 0 };
    ok = ok && deflateInit(&z, 1) == Z_OK;
    uint8_t *row = calloc(side + 1, 1), out[1 << 16];
    for (uint32_t y = 0; ok && y < side; y++) {
        z.next_in = row;
        z.avail_in = side + 1;    /* filter byte 0, then the row */
        int flush = y + 1 == side ? Z_FINISH : Z_NO_FLUSH;
        do {
            z.next_out = out;
            z.avail_out = sizeof out;
            deflate(&z, flush);
            uint32_t n = (uint32_t)(sizeof out - z.avail_out);
            if (n)
                ok = ok && chunk(f, "IDAT", out, n);
        } while (ok && (z.avail_out == 0 || (flush == Z_FINISH && z.avail_in > 0)));
    }
    deflateEnd(&z);
    free(row);
    static const uint8_t none[1];
    ok = ok && chunk(f, "IEND", none, 0);
    return fclose(f) == 0 && ok ? 0 : 1;
}
