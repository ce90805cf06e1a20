/* pack_files.c — the pack loader's way into the pack folder (untrusted
 * input: rt_pack_open_file, rt_pack_read_file, rt_pack_read_content for
 * the compressed shaders) and its typed access to the manifest's fields,
 * each failure a message naming the field (pack_internal.h). */
#include "pack_internal.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

char *rt_pk_strdup(const char *s)
{
    size_t n = strlen(s) + 1;
    char *d = malloc(n);
    if (d)
        memcpy(d, s, n);
    return d;
}

char *rt_pk_join(const char *dir, const char *rel)
{
    size_t n = strlen(dir) + strlen(rel) + 2;
    char *s = malloc(n);
    if (s)
        snprintf(s, n, "%s/%s", dir, rel);
    return s;
}

/* ---- pack files: untrusted input ----------------------------------------
 * Every file of a pack is opened here, relative to the pack folder, one
 * path component at a time with O_NOFOLLOW: no absolute path, no "..", no
 * symbolic link anywhere on the way (a link out of the pack, or to
 * /dev/zero, is never followed), and only a regular file at the end (a
 * FIFO would block a reader forever, a device never ends).  The size comes
 * from fstat before a byte is read, and reads stop at that size. */

int rt_pack_open_file(int dirfd, const char *rel, char *why, size_t nwhy)
{
    if (!rel[0] || rel[0] == '/') {
        snprintf(why, nwhy, "is outside the pack (an absolute or empty path)");
        return -1;
    }
    size_t len = strlen(rel);
    char *path = malloc(len + 1);
    if (!path) {
        snprintf(why, nwhy, "cannot be opened (out of memory)");
        return -1;
    }
    memcpy(path, rel, len + 1);
    int cur = dirfd, fd = -1;
    char *save = NULL;
    for (char *c = strtok_r(path, "/", &save); c; c = strtok_r(NULL, "/", &save)) {
        bool last = save == NULL || *save == '\0';
        if (!strcmp(c, "..")) {
            snprintf(why, nwhy, "is outside the pack (\"..\")");
            break;
        }
        struct stat st;
        if (fstatat(cur, c, &st, AT_SYMLINK_NOFOLLOW) != 0) {
            snprintf(why, nwhy, "cannot be read (%s)", strerror(errno));
            break;
        }
        if (S_ISLNK(st.st_mode)) {
            snprintf(why, nwhy, "is%s a symbolic link (a pack holds only regular files)",
                     last ? "" : " inside");
            break;
        }
        if (!last && !S_ISDIR(st.st_mode)) {
            snprintf(why, nwhy, "cannot be read ('%s' is not a folder)", c);
            break;
        }
        if (last && !S_ISREG(st.st_mode)) {
            snprintf(why, nwhy, "is not a regular file (%s)",
                     S_ISFIFO(st.st_mode) ? "a FIFO" : S_ISDIR(st.st_mode) ? "a folder"
                     : S_ISCHR(st.st_mode) || S_ISBLK(st.st_mode) ? "a device" : "a socket");
            break;
        }
        int next = openat(cur, c, O_RDONLY | O_NOFOLLOW | O_CLOEXEC | O_NOCTTY |
                                      (last ? O_NONBLOCK : O_DIRECTORY));
        struct stat st2;
        if (next >= 0 && (fstat(next, &st2) != 0 || st2.st_dev != st.st_dev ||
                          st2.st_ino != st.st_ino)) {
            close(next);   /* replaced between the look and the open */
            next = -1;
            errno = ESTALE;
        }
        if (next < 0) {
            snprintf(why, nwhy, "cannot be read (%s)", strerror(errno));
            break;
        }
        if (cur != dirfd)
            close(cur);
        cur = next;
        if (last) {
            fd = cur;
            cur = dirfd;
        }
    }
    if (cur != dirfd)
        close(cur);
    free(path);
    if (fd >= 0)
        fcntl(fd, F_SETFL, 0);   /* a regular file: blocking reads again */
    return fd;
}

uint8_t *rt_pack_read_file(int dirfd, const char *rel, size_t max, size_t *n, char *why,
                           size_t nwhy)
{
    int fd = rt_pack_open_file(dirfd, rel, why, nwhy);
    if (fd < 0)
        return NULL;
    struct stat st;
    uint8_t *buf = NULL;
    if (fstat(fd, &st) != 0) {
        snprintf(why, nwhy, "cannot be read (%s)", strerror(errno));
    } else if ((uint64_t)st.st_size > max) {
        snprintf(why, nwhy, "has %llu bytes, more than the %zu it may have",
                 (unsigned long long)st.st_size, max);
    } else if (!(buf = malloc((size_t)st.st_size + 1))) {
        snprintf(why, nwhy, "does not fit in memory (%llu bytes)",
                 (unsigned long long)st.st_size);
    } else {
        size_t size = (size_t)st.st_size, got = 0;
        while (got < size) {
            ssize_t r = read(fd, buf + got, size - got);
            if (r < 0 && errno == EINTR)
                continue;
            if (r <= 0) {
                snprintf(why, nwhy, "cannot be read (%s)",
                         r < 0 ? strerror(errno) : "it shrank while being read");
                free(buf);
                buf = NULL;
                break;
            }
            got += (size_t)r;
        }
        if (buf) {
            buf[size] = 0;   /* text files end in a NUL */
            *n = size;
        }
    }
    close(fd);
    return buf;
}

uint8_t *rt_pack_read_content(int dirfd, const char *rel, size_t max, size_t *n, char *why,
                              size_t nwhy)
{
    if (!splat_zst_name(rel))
        return rt_pack_read_file(dirfd, rel, max, n, why, nwhy);
    /* the file within the largest frame of `max` bytes; the frame's stated
     * content size within `max` before its buffer is allocated (zst.h) */
    size_t zn = 0;
    uint8_t *z = rt_pack_read_file(dirfd, rel, splat_zst_bound(max), &zn, why, nwhy);
    if (!z)
        return NULL;
    uint8_t *d = splat_zst_decompress(z, zn, max, n, why, nwhy);
    free(z);
    return d;
}

bool rt_pack_stat_content(int dirfd, const char *rel, size_t max, size_t *n, char *why,
                          size_t nwhy)
{
    int fd = rt_pack_open_file(dirfd, rel, why, nwhy);
    if (fd < 0)
        return false;
    struct stat st;
    bool zst = splat_zst_name(rel), ok = false;
    if (fstat(fd, &st) != 0) {
        snprintf(why, nwhy, "cannot be read (%s)", strerror(errno));
    } else if ((uint64_t)st.st_size > (zst ? splat_zst_bound(max) : max)) {
        snprintf(why, nwhy, "has %llu bytes, more than the %zu it may have",
                 (unsigned long long)st.st_size, zst ? splat_zst_bound(max) : max);
    } else if (!zst) {
        *n = (size_t)st.st_size;
        ok = true;
    } else {
        uint8_t head[SPLAT_ZST_HEAD];
        size_t want = (size_t)st.st_size < sizeof head ? (size_t)st.st_size : sizeof head;
        ssize_t got;
        do
            got = pread(fd, head, want, 0);
        while (got < 0 && errno == EINTR);
        if (got != (ssize_t)want)
            snprintf(why, nwhy, "cannot be read (%s)", got < 0 ? strerror(errno) : "short read");
        else
            ok = splat_zst_stated(head, want, max, n, why, nwhy);
    }
    close(fd);
    return ok;
}

/* ---- typed field access with messages naming the field ------------------ */

bool rt_pk_field_fail(rt_pk_reader *r, const char *where, const char *what)
{
    char msg[512];
    snprintf(msg, sizeof msg, "%s %s", where, what);
    return rt_fail(r->e, RT_E_PACK_FIELD, r->manifest, msg);
}

json_t *rt_pk_get(rt_pk_reader *r, json_t *obj, const char *key, const char *where,
                   bool required)
{
    json_t *v = json_is_object(obj) ? json_object_get(obj, key) : NULL;
    if (!v && required) {
        char w[256];
        snprintf(w, sizeof w, "%s: missing field", where);
        rt_pk_field_fail(r, w, key);
    }
    return v;
}

bool rt_pk_get_number(rt_pk_reader *r, json_t *obj, const char *key, const char *where,
                       double *out)
{
    json_t *v = rt_pk_get(r, obj, key, where, true);
    if (!v)
        return false;
    if (!json_is_number(v)) {
        char w[256];
        snprintf(w, sizeof w, "%s.%s:", where, key);
        return rt_pk_field_fail(r, w, "must be a number");
    }
    *out = json_number_value(v);
    return true;
}

bool rt_pk_get_int(rt_pk_reader *r, json_t *obj, const char *key, const char *where,
                    int lo, int hi, int *out)
{
    json_t *v = rt_pk_get(r, obj, key, where, true);
    if (!v)
        return false;
    if (!json_is_integer(v) || json_integer_value(v) < lo || json_integer_value(v) > hi) {
        char w[256], what[96];
        snprintf(w, sizeof w, "%s.%s:", where, key);
        snprintf(what, sizeof what, "must be an integer in [%d, %d]", lo, hi);
        return rt_pk_field_fail(r, w, what);
    }
    *out = (int)json_integer_value(v);
    return true;
}

bool rt_pk_get_string(rt_pk_reader *r, json_t *obj, const char *key, const char *where,
                       const char **out)
{
    json_t *v = rt_pk_get(r, obj, key, where, true);
    if (!v)
        return false;
    if (!json_is_string(v)) {
        char w[256];
        snprintf(w, sizeof w, "%s.%s:", where, key);
        return rt_pk_field_fail(r, w, "must be a string");
    }
    *out = json_string_value(v);
    return true;
}

json_t *rt_pk_get_array(rt_pk_reader *r, json_t *obj, const char *key, const char *where,
                         bool required)
{
    json_t *v = rt_pk_get(r, obj, key, where, required);
    if (v && !json_is_array(v)) {
        char w[256];
        snprintf(w, sizeof w, "%s.%s:", where, key);
        rt_pk_field_fail(r, w, "must be an array");
        return NULL;
    }
    return v;
}

bool rt_pk_get_vec(rt_pk_reader *r, json_t *obj, const char *key, const char *where,
                    int n, double *out)
{
    json_t *a = rt_pk_get_array(r, obj, key, where, true);
    if (!a)
        return false;
    if ((int)json_array_size(a) != n) {
        char w[256], what[64];
        snprintf(w, sizeof w, "%s.%s:", where, key);
        snprintf(what, sizeof what, "must have %d numbers", n);
        return rt_pk_field_fail(r, w, what);
    }
    for (int i = 0; i < n; i++) {
        json_t *v = json_array_get(a, (size_t)i);
        if (!json_is_number(v)) {
            char w[256];
            snprintf(w, sizeof w, "%s.%s[%d]:", where, key, i);
            return rt_pk_field_fail(r, w, "must be a number");
        }
        out[i] = json_number_value(v);
    }
    return true;
}

/* A file of the pack (rt_pack_read_file): of exactly `want` bytes if want
 * > 0, else at most `max`. */
uint8_t *rt_pk_pack_file(rt_pk_reader *r, const char *field, const char *rel,
                          size_t want, size_t max, size_t *got)
{
    char why[256];
    size_t n = 0;
    uint8_t *data = rt_pack_read_content(r->dirfd, rel, want ? want : max, &n, why, sizeof why);
    if (!data) {
        rt_fail(r->e, RT_E_PACK_FILE, r->manifest, field, rel, why);
        return NULL;
    }
    if (want && n != want) {
        snprintf(why, sizeof why, "has %zu bytes, expected %zu", n, want);
        rt_fail(r->e, RT_E_PACK_FILE, r->manifest, field, rel, why);
        free(data);
        return NULL;
    }
    if (got)
        *got = n;
    return data;
}

/* ---- sections ------------------------------------------------------------ */

uint32_t rt_pk_le32(const uint8_t *b)
{
    return (uint32_t)b[0] | (uint32_t)b[1] << 8 | (uint32_t)b[2] << 16 | (uint32_t)b[3] << 24;
}
