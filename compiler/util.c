/* util.c — allocation with one out-of-memory policy, one clock, path
 * helpers and one atomic write (util.h). */
#include "util.h"

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

void splat_oom(void)
{
    fputs("splatc: out of memory\n", stderr);
    abort();
}

void *xmalloc(size_t size)
{
    void *p = malloc(size ? size : 1);
    if (!p)
        splat_oom();
    return p;
}

void *xcalloc(size_t n, size_t size)
{
    void *p = calloc(n ? n : 1, size ? size : 1);
    if (!p)
        splat_oom();
    return p;
}

void *xrealloc(void *p, size_t size)
{
    p = realloc(p, size ? size : 1);
    if (!p)
        splat_oom();
    return p;
}

char *xstrdup(const char *s)
{
    return xstrndup(s, strlen(s));
}

char *xstrndup(const char *s, size_t n)
{
    size_t len = strnlen(s, n);
    char *d = xmalloc(len + 1);
    memcpy(d, s, len);
    d[len] = 0;
    return d;
}

char *xasprintf(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(NULL, 0, fmt, ap);
    va_end(ap);
    if (n < 0)
        splat_oom();
    char *s = xmalloc((size_t)n + 1);
    va_start(ap, fmt);
    vsnprintf(s, (size_t)n + 1, fmt, ap);
    va_end(ap);
    return s;
}

double splat_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

/* ---- paths ------------------------------------------------------------- */

/* Normalise in place: drop "." and empty components, fold "x/..". */
static char *normalise(char *path)
{
    bool abs = path[0] == '/';
    size_t n = strlen(path);
    char **comp = xmalloc((n / 2 + 2) * sizeof *comp);
    char *out = xmalloc(n + 3);
    int nc = 0, keep_up = 0;   /* leading ".." components we must keep */
    char *save = NULL;   /* strtok_r: loading may run on several threads */
    for (char *s = strtok_r(path, "/", &save); s; s = strtok_r(NULL, "/", &save)) {
        if (!strcmp(s, "."))
            continue;
        if (!strcmp(s, "..")) {
            if (nc > keep_up) {
                nc--;
                continue;
            }
            if (abs)
                continue;      /* "/.." is "/" */
            keep_up++;
        }
        comp[nc++] = s;
    }
    size_t o = 0;
    if (abs)
        out[o++] = '/';
    for (int i = 0; i < nc; i++) {
        size_t l = strlen(comp[i]);
        if (i)
            out[o++] = '/';
        memcpy(out + o, comp[i], l);
        o += l;
    }
    if (o == 0)
        out[o++] = '.';
    out[o] = 0;
    free(comp);
    free(path);
    return out;
}

char *splat_path_join(const char *dir, const char *rel)
{
    if (rel[0] == '/' || !*dir || !strcmp(dir, "."))
        return normalise(xstrdup(rel));
    return normalise(xasprintf("%s/%s", dir, rel));
}

char *splat_path_dir(const char *path)
{
    const char *slash = strrchr(path, '/');
    if (!slash)
        return xstrdup(".");
    return xstrndup(path, slash == path ? 1 : (size_t)(slash - path));
}

char *splat_path_parent(const char *dir)
{
    if (strcmp(dir, "/") == 0)
        return NULL;
    if (strcmp(dir, ".") == 0)
        return xstrdup("..");
    size_t n = strlen(dir);
    if (n >= 2 && strcmp(dir + n - 2, "..") == 0 && (n == 2 || dir[n - 3] == '/'))
        return xasprintf("%s/..", dir);
    return splat_path_dir(dir);
}

char *splat_path_absolute(const char *path)
{
    if (path[0] == '/')
        return normalise(xstrdup(path));
    char cwd[PATH_MAX];
    if (!getcwd(cwd, sizeof cwd))
        return xstrdup(path);
    return normalise(xasprintf("%s/%s", cwd, path));
}

char *splat_path_relative(const char *from, const char *to)
{
    size_t common = 0;
    for (size_t i = 0;; i++) {
        bool end_f = from[i] == 0 || from[i] == '/', end_t = to[i] == 0 || to[i] == '/';
        if (end_f && end_t)
            common = i;
        if (!from[i] || !to[i] || from[i] != to[i])
            break;
    }
    int ups = 0;
    for (const char *c = from + common; *c; c++)
        ups += *c == '/';
    if (!strcmp(from, "/"))
        ups = 0;
    const char *rest = to + common + (to[common] == '/');
    char *r = xmalloc((size_t)ups * 3 + strlen(rest) + 2);
    r[0] = 0;
    for (int i = 0; i < ups; i++)
        strcat(r, "../");
    strcat(r, *rest ? rest : ".");
    return r;
}

char *splat_path_relative_real(const char *base, const char *path)
{
    char rb[PATH_MAX], rp[PATH_MAX];
    if (!realpath(base, rb) || !realpath(path, rp))
        return xstrdup(path);
    return splat_path_relative(rb, rp);
}

bool splat_is_dir(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0 && S_ISDIR(st.st_mode);
}

/* ---- files ---------------------------------------------------------------- */

static mode_t file_mode;    /* 0666 & ~umask, read once: umask() is process-wide */
static pthread_once_t file_mode_once = PTHREAD_ONCE_INIT;

static void read_umask(void)
{
    mode_t mask = umask(0);
    umask(mask);
    file_mode = 0666 & ~mask;
}

bool splat_write_atomic(const char *path, const void *data, size_t n)
{
    pthread_once(&file_mode_once, read_umask);
    char *tmp = xasprintf("%s.tmp-XXXXXX", path);   /* "*.tmp-*": .gitignore */
    int fd = mkstemp(tmp);
    if (fd < 0) {
        free(tmp);
        return false;
    }
    const char *s = data;
    size_t done = 0;
    while (done < n) {
        ssize_t w = write(fd, s + done, n - done);
        if (w < 0 && errno == EINTR)
            continue;
        if (w <= 0)
            break;
        done += (size_t)w;
    }
    int err = done == n ? 0 : errno ? errno : EIO;
    if (fchmod(fd, file_mode) != 0 && !err)
        err = errno;
    if (close(fd) != 0 && !err)
        err = errno;
    if (!err && rename(tmp, path) != 0)
        err = errno;
    if (err)
        unlink(tmp);
    free(tmp);
    errno = err;
    return err == 0;
}

/* mkdir -p; true if the folder exists afterwards. */
bool splat_make_dirs(const char *path)
{
    char *p = strdup(path);
    if (!p)
        return false;
    for (char *s = p + 1; *s; s++) {
        if (*s != '/')
            continue;
        *s = 0;
        if (mkdir(p, 0777) != 0 && errno != EEXIST) {
            free(p);
            return false;
        }
        *s = '/';
    }
    bool ok = mkdir(p, 0777) == 0 || errno == EEXIST;
    struct stat sb;
    ok = ok && stat(p, &sb) == 0 && S_ISDIR(sb.st_mode);
    free(p);
    return ok;
}

/* ---- inputs ------------------------------------------------------------- */

static const char *file_kind(mode_t m)
{
    return S_ISFIFO(m) ? "a FIFO (named pipe)" : S_ISCHR(m) ? "a character device"
         : S_ISBLK(m) ? "a block device" : S_ISDIR(m) ? "a folder"
         : S_ISSOCK(m) ? "a socket" : "not a plain file";
}

int splat_input_open(const char *path, unsigned long long max_bytes,
                     unsigned long long *size, char *why, size_t nwhy)
{
    *size = 0;
    int fd;
    do
        fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
    while (fd < 0 && errno == EINTR);
    if (fd < 0) {
        snprintf(why, nwhy, "%s", strerror(errno));
        return -1;
    }
    struct stat st;
    if (fstat(fd, &st) != 0) {
        snprintf(why, nwhy, "%s", strerror(errno));
        close(fd);
        return -1;
    }
    if (!S_ISREG(st.st_mode)) {
        snprintf(why, nwhy, "not a regular file: it is %s", file_kind(st.st_mode));
        close(fd);
        return -1;
    }
    if (st.st_size < 0 || (unsigned long long)st.st_size > max_bytes) {
        snprintf(why, nwhy, "is %lld bytes, over the limit of %llu for this kind of input",
                 (long long)st.st_size, max_bytes);
        close(fd);
        return -1;
    }
    int fl = fcntl(fd, F_GETFL);
    if (fl < 0 || fcntl(fd, F_SETFL, fl & ~O_NONBLOCK) != 0) {
        snprintf(why, nwhy, "%s", strerror(errno));
        close(fd);
        return -1;
    }
    *size = (unsigned long long)st.st_size;
    return fd;
}

FILE *splat_input_fopen(const char *path, unsigned long long max_bytes,
                        char *why, size_t nwhy)
{
    unsigned long long size;
    int fd = splat_input_open(path, max_bytes, &size, why, nwhy);
    if (fd < 0)
        return NULL;
    FILE *f = fdopen(fd, "rb");
    if (!f) {
        snprintf(why, nwhy, "%s", strerror(errno));
        close(fd);
    }
    return f;
}

bool splat_input_check(const char *path, unsigned long long max_bytes,
                       char *why, size_t nwhy)
{
    unsigned long long size;
    int fd = splat_input_open(path, max_bytes, &size, why, nwhy);
    if (fd < 0)
        return false;
    close(fd);
    return true;
}

char *splat_input_read(const char *path, unsigned long long max_bytes, size_t *len,
                       char *why, size_t nwhy)
{
    *len = 0;
    unsigned long long size;
    int fd = splat_input_open(path, max_bytes, &size, why, nwhy);
    if (fd < 0)
        return NULL;
    char *buf = xmalloc((size_t)size + 1);
    size_t n = 0;
    while (n < size) {
        ssize_t got = read(fd, buf + n, (size_t)size - n);
        if (got < 0 && errno == EINTR)
            continue;
        if (got < 0) {
            snprintf(why, nwhy, "%s", strerror(errno));
            close(fd);
            free(buf);
            return NULL;
        }
        if (got == 0)
            break;              /* shrank meanwhile: what is there */
        n += (size_t)got;
    }
    close(fd);
    buf[n] = 0;
    *len = n;
    return buf;
}
