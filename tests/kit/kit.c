/* kit.c — the C test kit (kit.h). */
#include "kit.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>

static int failures;

void kit_fail(const char *file, int line, const char *cond, const char *fmt, ...)
{
    failures++;
    fprintf(stderr, "FAIL %s:%d: %s: ", file, line, cond);
    va_list ap;
    va_start(ap, fmt);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fputc('\n', stderr);
}

int kit_failures(void) { return failures; }

int kit_finish(const char *name)
{
    if (failures) {
        fprintf(stderr, "%s: %d failure%s\n", name, failures, failures == 1 ? "" : "s");
        return 1;
    }
    printf("%s: all checks passed\n", name);
    return 0;
}

char *kit_join(const char *dir, const char *name)
{
    size_t n = strlen(dir) + strlen(name) + 2;
    char *p = malloc(n);
    if (p) snprintf(p, n, "%s/%s", dir, name);
    return p;
}

char *kit_read_file(const char *path, size_t *n)
{
    FILE *f = fopen(path, "rb");
    char *buf = NULL;
    size_t len = 0, cap = 0;
    if (f) {
        for (;;) {
            if (len + 4097 > cap) {
                cap = cap ? 2 * cap : 65536;
                char *nb = realloc(buf, cap);
                if (!nb) break;
                buf = nb;
            }
            size_t got = fread(buf + len, 1, cap - len - 1, f);
            len += got;
            if (got == 0) break;
        }
    }
    bool ok = f && buf && !ferror(f) && feof(f);
    int err = errno;
    if (f) fclose(f);
    if (!ok) {
        CHECK(ok, "cannot read '%s': %s", path, f ? "read error" : strerror(err));
        free(buf);
        return NULL;
    }
    buf[len] = 0;
    if (n) *n = len;
    return buf;
}

bool kit_build_pack(const char *sg, const char *pack, splat_painted_format painted,
                    sg_diags *d)
{
    char rm[1200];
    snprintf(rm, sizeof rm, "rm -rf '%s'", pack);
    static const char *const search[] = { ".", NULL };
    splat_build_desc bd = { .scene = sg, .out = pack, .search_paths = search,
                            .jobs = 2, .no_cache = true, .painted = painted };
    splat_build_stats st;
    sg_diags_init(d);
    return system(rm) == 0 && splat_build(&bd, &st, d);
}

bool kit_build_pack_ok(const char *sg, const char *pack)
{
    sg_diags d;
    bool ok = kit_build_pack(sg, pack, SPLAT_PAINTED_BC4, &d);
    if (!ok) sg_diags_print(&d, stderr);
    sg_diags_free(&d);
    CHECK(ok, "%s does not build into %s", sg, pack);
    return ok;
}

rt_device *kit_device(void)
{
    rt_error e = { 0 };
    rt_device *d = NULL;
    CHECK(rt_device_open(NULL, &d, &e), "device: %s", e.msg ? e.msg : "?");
    rt_error_clear(&e);
    return d;
}

void kit_device_close(rt_device *d)
{
    if (!d) return;
    int messages = rt_device_close(d);
    CHECK(messages == 0, "%d validation message(s)", messages);
}

rt_pack *kit_pack(const char *dir)
{
    rt_error e = { 0 };
    rt_pack *p = NULL;
    CHECK(rt_pack_open(dir, &p, &e), "pack: %s", e.msg ? e.msg : "?");
    rt_error_clear(&e);
    return p;
}

rt_pack_info kit_pack_info(const rt_pack *p)
{
    rt_pack_info pi;
    rt_pack_info_get(p, &pi);
    return pi;
}

float *kit_frame(rt_renderer *r, const rt_camera *cam, int w, int h)
{
    rt_error e = { 0 };
    float *rgba = malloc((size_t)w * (size_t)h * 16);
    bool ok = rgba && rt_renderer_frame(r, cam, NULL, &e) && rt_renderer_read(r, rgba, &e);
    CHECK(ok, "frame: %s", e.msg ? e.msg : "?");
    rt_error_clear(&e);
    if (!ok) {
        free(rgba);
        return NULL;
    }
    return rgba;
}

float *kit_render(rt_device *dev, const rt_pack *p, const rt_render_desc *rd,
                  splat_view view, int material, const rt_camera *cam)
{
    rt_error e = { 0 };
    rt_renderer *r = NULL;
    bool ok = rt_renderer_create(dev, p, rd, &r, &e);
    CHECK(ok, "renderer: %s", e.msg ? e.msg : "?");
    rt_error_clear(&e);
    if (!ok)
        return NULL;
    rt_renderer_set_view(r, view, material);
    float *rgba = kit_frame(r, cam, rd->width, rd->height);
    rt_renderer_destroy(r);
    return rgba;
}

void kit_write_picture(const char *dir, const char *name, const float *rgba, int w, int h,
                       splat_view view)
{
    rt_error e = { 0 };
    uint8_t *px = malloc((size_t)w * (size_t)h * 4);
    char *png = kit_join(dir, name);
    if (px) rt_tonemap_rgba8(rgba, w, h, rt_view_tonemap(view), px);
    CHECK(px && png && rt_write_png(png, px, w, h, &e), "%s: %s", png ? png : name,
          e.msg ? e.msg : "");
    rt_error_clear(&e);
    free(png);
    free(px);
}

double kit_max_diff(const float *a, const float *b, size_t n)
{
    double m = 0;
    for (size_t i = 0; i < n; i++) {
        double d = fabs((double)a[i] - (double)b[i]);
        if (isnan(d) && !(isnan(a[i]) && isnan(b[i])))
            return NAN;   /* a NaN on one side only: as far apart as can be */
        if (d > m) m = d;
    }
    return m;
}

bool kit_image_near_at(const char *file, int line, const float *a, const float *b, int w,
                       int h, double tol, const char *what)
{
    if (!a || !b) {
        kit_fail(file, line, "a && b", "%s: a picture is missing", what);
        return false;
    }
    size_t n = (size_t)w * (size_t)h, off = 0, worst = 0;
    double max = 0;
    for (size_t i = 0; i < n; i++) {
        double d = kit_max_diff(a + 4 * i, b + 4 * i, 4);
        if (!(d <= tol)) off++;               /* NaN: off */
        if (!(d <= max) && !isnan(max)) max = d, worst = i;
    }
    if (off)
        kit_fail(file, line, "pictures near", "%s: %zu of %zu pixels differ by more than %g "
                 "(worst %g at %zu, %zu)", what, off, n, tol, max, worst % (size_t)w,
                 worst / (size_t)w);
    return off == 0;
}
