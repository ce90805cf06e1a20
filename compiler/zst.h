/* zst.h — the pack's compressed files (compiler/PACK.md "Compressed
 * shaders"): one zstd frame each, with its content size and checksum in
 * the frame (libzstd, Debian's libzstd-dev).
 *
 * splat_zst_compress is deterministic (one thread, fixed level and
 * parameters): same bytes in, same frame out, as the pack's "same inputs,
 * byte-identical files" asks.  splat_zst_decompress reads untrusted
 * input: it checks the frame's stated size against `max` and the file's
 * own size before allocating (no decompression bomb), and that the input
 * is exactly one frame whose content is that size.
 */
#ifndef SPLAT_ZST_H
#define SPLAT_ZST_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#define SPLAT_ZST_SUFFIX ".zst"   /* a pack file name that ends so is compressed */
#define SPLAT_ZST_LEVEL  3        /* fast; level 9 gains 10 % for 5x the time */

/* Whether pack file name `rel` names a compressed file. */
bool     splat_zst_name(const char *rel);
/* The largest frame splat_zst_compress makes of `n` bytes. */
size_t   splat_zst_bound(size_t n);
/* `n` bytes as one frame (malloc'd, *out_n bytes); false: out of memory or
 * a libzstd error. */
bool     splat_zst_compress(const void *src, size_t n, uint8_t **out, size_t *out_n);
/* The content size that the frame starting `src` (its first `n` bytes:
 * SPLAT_ZST_HEAD or the whole file if shorter) states, checked against
 * `max`; false with `why` set if it states none or more. */
#define SPLAT_ZST_HEAD 18   /* ZSTD_FRAMEHEADERSIZE_MAX */
bool     splat_zst_stated(const uint8_t *src, size_t n, size_t max, size_t *size, char *why,
                          size_t nwhy);
/* The content of one frame of at most `max` bytes, with one spare byte
 * allocated after it (a NUL, so text can be used in place); NULL with
 * `why` set on any mismatch. */
uint8_t *splat_zst_decompress(const uint8_t *src, size_t n, size_t max, size_t *out_n,
                              char *why, size_t nwhy);
/* Whether the `fn` bytes at `frame` are exactly one frame whose content is
 * the `n` bytes at `data` (what a rebuild checks before it keeps a pack
 * file instead of compressing it again); any mismatch or error: false. */
bool     splat_zst_holds(const uint8_t *frame, size_t fn, const void *data, size_t n);

#endif
