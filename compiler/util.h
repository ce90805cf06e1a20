/* util.h — the compiler's small utilities, one of each: allocation with
 * one out-of-memory policy, one clock, one set of path helpers, one atomic
 * file write.  libsplatrt links libsplatc and uses them too.
 *
 * Out of memory: the x* functions print "splatc: out of memory" and
 * abort().  The compiler's data is small next to any machine it runs on,
 * so running out is a bug or a runaway input that the limits
 * (diagnostics with an id) should have stopped first; there is nothing
 * sane to undo.  Library code otherwise never exits (STYLE). */
#ifndef SPLAT_UTIL_H
#define SPLAT_UTIL_H

#include <stdbool.h>
#include <stddef.h>
#include <stdio.h>

void *xmalloc(size_t size);
void *xcalloc(size_t n, size_t size);          /* n == 0 gives a valid block */
void *xrealloc(void *p, size_t size);
char *xstrdup(const char *s);
char *xstrndup(const char *s, size_t n);
char *xasprintf(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
void  splat_oom(void) __attribute__((noreturn)); /* the policy itself */

/* Seconds on a monotonic clock (phase timers, --stats, frame times). */
double splat_now(void);

/* ---- paths: lexical, malloc'd, relative paths stay relative ------------ */

/* dir/rel with "." and empty components dropped and "x/.." folded; rel
 * as given if absolute or dir is "" or ".". */
char *splat_path_join(const char *dir, const char *rel);
/* The folder part: "a/b" -> "a", "b" -> ".", "/b" -> "/". */
char *splat_path_dir(const char *path);
/* The parent of a folder, kept relative where it was: "a/b" -> "a" ->
 * "." -> ".." -> "../.."; NULL above "/". */
char *splat_path_parent(const char *dir);
/* Absolute (against the current folder), "." and ".." resolved lexically. */
char *splat_path_absolute(const char *path);
/* `to` relative to folder `from` (both absolute and normalised). */
char *splat_path_relative(const char *from, const char *to);
/* `path` relative to folder `base` after resolving both (symlinks too),
 * so the result does not depend on where the tree lives; `path` as given
 * when either does not resolve. */
char *splat_path_relative_real(const char *base, const char *path);
bool  splat_is_dir(const char *path);
/* mkdir -p; true if the folder exists afterwards. */
bool  splat_make_dirs(const char *path);

/* ---- files ---------------------------------------------------------------- */

/* Write `n` bytes to `path` atomically: a temporary file beside it
 * (PATH.tmp-XXXXXX, mode 0666 & ~umask), renamed over it; readers never
 * see half a file, and on failure nothing is left.  False with errno set. */
bool splat_write_atomic(const char *path, const void *data, size_t n);

/* ---- inputs: every file a scene names is untrusted ------------------------ */

/* Size bounds of the inputs, checked on the open descriptor before a byte
 * is read (and before GDAL, stb_image or tinyobjloader see the file).
 * They bound runaway files, not honest ones: a 16384^2 RGBA PNG stored
 * uncompressed is 1 GiB, a Float64 GeoTIFF of 16384^2 texels 2 GiB. */
#define SPLAT_MAX_GRAPH_BYTES  ((unsigned long long)16 << 20)   /* .sg files  */
#define SPLAT_MAX_MESH_BYTES   ((unsigned long long)64 << 20)   /* OBJ files  */
#define SPLAT_MAX_IMAGE_BYTES  ((unsigned long long)1 << 30)    /* PNG, …     */
#define SPLAT_MAX_RASTER_BYTES ((unsigned long long)4 << 30)    /* GDAL, R16  */
#define SPLAT_MAX_SPIRV_BYTES  ((unsigned long long)64 << 20)   /* the SPIR-V
                                  cache's entries, an existing pack's shaders */

/* Open `path` for reading as an untrusted input, the one way every input
 * is opened: open(2) with O_RDONLY | O_NONBLOCK | O_CLOEXEC (a FIFO's open
 * never waits for a writer), then fstat on that descriptor: anything but
 * a regular file (a FIFO, a character or block device, a folder, a
 * socket; a symbolic link counts as what it points to, so a link to
 * /dev/zero is a character device) or a file over `max_bytes` is refused.
 * O_NONBLOCK is then cleared.  The descriptor, its size in *size; -1 with
 * the reason in why[nwhy] ("No such file or directory", "not a regular
 * file: it is a FIFO (named pipe)", "is N bytes, over the limit of M"). */
int   splat_input_open(const char *path, unsigned long long max_bytes,
                       unsigned long long *size, char *why, size_t nwhy);
/* The same, as a FILE * ("rb"). */
FILE *splat_input_fopen(const char *path, unsigned long long max_bytes,
                        char *why, size_t nwhy);
/* Checked, then closed: for libraries that open the path themselves
 * (GDAL), after the check. */
bool  splat_input_check(const char *path, unsigned long long max_bytes,
                        char *why, size_t nwhy);
/* The whole file, at most its fstat size (a file that grows while read
 * is cut there), NUL-terminated, malloc'd, its length in *len; NULL with
 * the reason in why. */
char *splat_input_read(const char *path, unsigned long long max_bytes, size_t *len,
                       char *why, size_t nwhy);

#endif
