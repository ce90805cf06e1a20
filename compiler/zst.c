/* zst.c — the pack's compressed files (zst.h). */
#include "zst.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <zstd.h>

bool splat_zst_name(const char *rel)
{
    size_t n = strlen(rel), k = sizeof SPLAT_ZST_SUFFIX - 1;
    return n > k && strcmp(rel + n - k, SPLAT_ZST_SUFFIX) == 0;
}

size_t splat_zst_bound(size_t n)
{
    return ZSTD_compressBound(n);
}

bool splat_zst_compress(const void *src, size_t n, uint8_t **out, size_t *out_n)
{
    *out = NULL;
    *out_n = 0;
    ZSTD_CCtx *c = ZSTD_createCCtx();
    size_t cap = ZSTD_compressBound(n);
    uint8_t *buf = malloc(cap ? cap : 1);
    bool ok = c && buf &&
              !ZSTD_isError(ZSTD_CCtx_setParameter(c, ZSTD_c_compressionLevel, SPLAT_ZST_LEVEL)) &&
              !ZSTD_isError(ZSTD_CCtx_setParameter(c, ZSTD_c_checksumFlag, 1)) &&
              !ZSTD_isError(ZSTD_CCtx_setParameter(c, ZSTD_c_contentSizeFlag, 1));
    size_t r = ok ? ZSTD_compress2(c, buf, cap, src, n) : 0;
    ok = ok && !ZSTD_isError(r);
    ZSTD_freeCCtx(c);
    if (!ok) {
        free(buf);
        return false;
    }
    *out = buf;
    *out_n = r;
    return true;
}

bool splat_zst_stated(const uint8_t *src, size_t n, size_t max, size_t *out, char *why,
                      size_t nwhy)
{
    unsigned long long size = ZSTD_getFrameContentSize(src, n);
    if (size == ZSTD_CONTENTSIZE_ERROR) {
        snprintf(why, nwhy, "is not a zstd frame");
        return false;
    }
    if (size == ZSTD_CONTENTSIZE_UNKNOWN) {
        snprintf(why, nwhy, "is a zstd frame without its content size");
        return false;
    }
    if (size > max) {
        snprintf(why, nwhy, "states %llu bytes of content, more than the limit of %zu", size,
                 max);
        return false;
    }
    *out = (size_t)size;
    return true;
}

uint8_t *splat_zst_decompress(const uint8_t *src, size_t n, size_t max, size_t *out_n,
                              char *why, size_t nwhy)
{
    *out_n = 0;
    size_t size;
    if (!splat_zst_stated(src, n, max, &size, why, nwhy))
        return NULL;
    size_t frame = ZSTD_findFrameCompressedSize(src, n);
    if (ZSTD_isError(frame) || frame != n) {
        snprintf(why, nwhy, "is not exactly one zstd frame (%s)",
                 ZSTD_isError(frame) ? "the frame is cut short" : "bytes after it");
        return NULL;
    }
    uint8_t *buf = malloc((size_t)size + 1);
    ZSTD_DCtx *d = ZSTD_createDCtx();
    if (!buf || !d) {
        free(buf);
        ZSTD_freeDCtx(d);
        snprintf(why, nwhy, "out of memory");
        return NULL;
    }
    /* the output holds exactly the stated size: zstd writes no further */
    size_t r = ZSTD_decompressDCtx(d, buf, (size_t)size, src, n);
    ZSTD_freeDCtx(d);
    if (ZSTD_isError(r) || r != size) {
        snprintf(why, nwhy, "does not decompress (%s)",
                 ZSTD_isError(r) ? ZSTD_getErrorName(r) : "shorter than its stated size");
        free(buf);
        return NULL;
    }
    buf[size] = 0;
    *out_n = (size_t)size;
    return buf;
}

bool splat_zst_holds(const uint8_t *frame, size_t fn, const void *data, size_t n)
{
    unsigned long long size = ZSTD_getFrameContentSize(frame, fn);
    if (size == ZSTD_CONTENTSIZE_ERROR || size == ZSTD_CONTENTSIZE_UNKNOWN || size != n)
        return false;   /* the cheap test first: most changed files differ in size */
    char why[64];
    size_t got;
    uint8_t *buf = splat_zst_decompress(frame, fn, n, &got, why, sizeof why);
    bool same = buf && got == n && memcmp(buf, data, n) == 0;
    free(buf);
    return same;
}
