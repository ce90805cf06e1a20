/* mesh.c — undergrowth meshes (mesh.h): the built-in procedural ones, and
 * an OBJ file's corners (mesh_obj.cpp) made into an indexed mesh.
 *
 * The built-ins are fixed: every variation between grass blades or stone
 * faces comes from constants (a golden-ratio sequence, small tables), so
 * a mesh is the same on every run and machine and a pack stays
 * byte-identical.  The instances vary them further at draw time (scale,
 * rotation), not here.
 */
#include "mesh.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <xxhash.h>

#include "abi.h"
#include "util.h"

const char *const splat_mesh_builtins[] = { "grass", "plant", "stone", NULL };

static const double PI = 3.14159265358979323846;

/* ---- building ------------------------------------------------------------ */

typedef struct builder {
    splat_mesh *m;
    uint32_t    capv, capi;
} builder;

static uint32_t vert(builder *b, const double p[3], const double n[3], double u, double v)
{
    splat_mesh *m = b->m;
    if (m->nv == b->capv) {
        b->capv = b->capv ? 2 * b->capv : 64;
        m->v = xrealloc(m->v, b->capv * sizeof *m->v);
    }
    double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    splat_mesh_vertex *x = &m->v[m->nv];
    for (int i = 0; i < 3; i++) {
        x->pos[i] = (float)p[i];
        x->nrm[i] = (float)(n[i] / len);
    }
    x->uv[0] = (float)u;
    x->uv[1] = (float)v;
    return m->nv++;
}

static void tri(builder *b, uint32_t i0, uint32_t i1, uint32_t i2)
{
    splat_mesh *m = b->m;
    if (m->nidx + 3 > b->capi) {
        b->capi = b->capi ? 2 * b->capi : 192;
        m->idx = xrealloc(m->idx, b->capi * sizeof *m->idx);
    }
    m->idx[m->nidx++] = i0;
    m->idx[m->nidx++] = i1;
    m->idx[m->nidx++] = i2;
}

static double frac(double x) { return x - floor(x); }

static void cross(const double a[3], const double b[3], double out[3])
{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

/* ---- built-ins ------------------------------------------------------------ */

/* grass: 12 blades round the root.  Blade k stands at angle k*30 degrees
 * (jittered), 2-8 cm out, is 0.35-0.5 m tall and leans 6-14 cm outward at
 * its tip (quadratically: it bends).  A blade is 3 rows of 2 vertices, 3 cm
 * wide at the root narrowing to 6 mm at the tip, 4 triangles; uv.x across,
 * uv.y up.  Normals lean 17 degrees outward from straight up, so the clump
 * shades like the ground it grows on. */
static void grass(builder *b)
{
    for (int k = 0; k < 12; k++) {
        double f = frac(k * 0.6180339887), g = frac(k * 0.7548776662 + 0.3);
        double ang = k * (2 * PI / 12) + (f - 0.5) * 0.4;
        double out[2] = { cos(ang), sin(ang) };
        double twist = ang + PI / 2 + (g - 0.5) * 0.8;     /* the blade's width axis */
        double side[2] = { cos(twist), sin(twist) };
        double r = 0.02 + 0.06 * g, h = 0.35 + 0.15 * f, lean = 0.06 + 0.08 * g;
        double n[3] = { 0.3 * out[0], 1, 0.3 * out[1] };
        uint32_t row[3][2];
        for (int i = 0; i < 3; i++) {
            double t = i / 2.0, w = 0.015 * (1 - 0.8 * t), o = r + lean * t * t;
            for (int j = 0; j < 2; j++) {
                double s = j ? w : -w;
                double p[3] = { out[0] * o + side[0] * s, h * t, out[1] * o + side[1] * s };
                row[i][j] = vert(b, p, n, j, t);
            }
        }
        for (int i = 0; i < 2; i++) {
            tri(b, row[i][0], row[i][1], row[i + 1][0]);
            tri(b, row[i + 1][0], row[i][1], row[i + 1][1]);
        }
    }
}

/* plant: two crossed vertical quads, 0.6 m wide and high, facing +z and
 * +x (drawn double-sided; the fragment shader cuts a leaf shape out of uv
 * with alpha test).  Normals halfway between the face and straight up. */
static void plant(builder *b)
{
    for (int q = 0; q < 2; q++) {
        /* along: the quad's width axis; face: its normal */
        double along[3] = { q ? 0 : 1, 0, q ? -1 : 0 };
        double face[3] = { q ? 1 : 0, 0, q ? 0 : 1 };
        double n[3] = { 0.5 * face[0], 1, 0.5 * face[2] };
        uint32_t c[4];
        for (int i = 0; i < 4; i++) {
            double u = (i == 1 || i == 2) ? 1 : 0, v = i >= 2 ? 1 : 0;
            double p[3] = { along[0] * (u - 0.5) * 0.6, v * 0.6, along[2] * (u - 0.5) * 0.6 };
            c[i] = vert(b, p, n, u, v);
        }
        tri(b, c[0], c[1], c[2]);
        tri(b, c[0], c[2], c[3]);
    }
}

/* stone: a low-poly rock about 0.4 m wide and 0.2 m high, its bottom 5 cm
 * in the ground: a bottom point, a ring of 6 points near the ground, a
 * smaller ring of 6 higher up (turned 30 degrees) and a top point, all
 * pushed about by fixed amounts; 24 faces with flat normals (3 vertices
 * each), wound counter-clockwise seen from outside.  uv = (0.5, height
 * over the stone's height), as an OBJ without uv gets. */
static void stone(builder *b)
{
    static const double ring[2][6][3] = {   /* angle offset (deg), radius, y */
        { { 0, 0.22, 0.05 }, { 8, 0.19, 0.07 }, { -6, 0.21, 0.04 },
          { 5, 0.18, 0.06 }, { -9, 0.22, 0.05 }, { 4, 0.20, 0.08 } },
        { { 33, 0.12, 0.16 }, { 25, 0.10, 0.17 }, { 36, 0.13, 0.15 },
          { 28, 0.11, 0.18 }, { 34, 0.10, 0.16 }, { 23, 0.12, 0.17 } },
    };
    double e[2][6][3];
    for (int r = 0; r < 2; r++)
        for (int i = 0; i < 6; i++) {
            double a = (i * 60 + 15 + ring[r][i][0]) * PI / 180;
            e[r][i][0] = ring[r][i][1] * cos(a);
            e[r][i][1] = ring[r][i][2];
            e[r][i][2] = ring[r][i][1] * sin(a);
        }
    static const double bottom[3] = { 0.0, -0.05, 0.01 }, top[3] = { 0.02, 0.20, -0.01 };
    static const double centre[3] = { 0, 0.07, 0 };
    const double *t[24][3];
    int nt = 0;
    for (int i = 0; i < 6; i++) {
        int j = (i + 1) % 6;
        t[nt][0] = bottom,  t[nt][1] = e[0][i], t[nt][2] = e[0][j], nt++;
        t[nt][0] = e[0][i], t[nt][1] = e[0][j], t[nt][2] = e[1][i], nt++;
        t[nt][0] = e[0][j], t[nt][1] = e[1][j], t[nt][2] = e[1][i], nt++;
        t[nt][0] = e[1][i], t[nt][1] = e[1][j], t[nt][2] = top,     nt++;
    }
    for (int k = 0; k < nt; k++) {
        double a[3], c[3], n[3], mid[3];
        for (int i = 0; i < 3; i++) {
            a[i] = t[k][1][i] - t[k][0][i];
            c[i] = t[k][2][i] - t[k][0][i];
            mid[i] = (t[k][0][i] + t[k][1][i] + t[k][2][i]) / 3 - centre[i];
        }
        cross(a, c, n);
        bool flip = n[0] * mid[0] + n[1] * mid[1] + n[2] * mid[2] < 0;
        if (flip)
            for (int i = 0; i < 3; i++)
                n[i] = -n[i];
        uint32_t v[3];
        for (int i = 0; i < 3; i++) {
            const double *p = t[k][i];
            v[i] = vert(b, p, n, 0.5, (p[1] - bottom[1]) / (top[1] - bottom[1]));
        }
        if (flip)
            tri(b, v[0], v[2], v[1]);
        else
            tri(b, v[0], v[1], v[2]);
    }
}

/* The far versions (mesh.h splat_mesh_builtin_far): what a distant clump
 * needs is its cover, not its shape; the undergrowth's draws cost per
 * triangle (each one shades at least a 2x2 quad), so they keep the cover
 * with a sixth of the triangles. */

/* grass far: 4 blades, 90 degrees apart (jittered as the near ones), each
 * one tapered quad from root to tip (2 triangles, no bend), three times
 * as wide: about the near clump's side area. */
static void grass_far(builder *b)
{
    for (int k = 0; k < 4; k++) {
        double f = frac(k * 0.6180339887), g = frac(k * 0.7548776662 + 0.3);
        double ang = k * (2 * PI / 4) + (f - 0.5) * 0.4;
        double out[2] = { cos(ang), sin(ang) };
        double twist = ang + PI / 2 + (g - 0.5) * 0.8;
        double side[2] = { cos(twist), sin(twist) };
        double r = 0.02 + 0.06 * g, h = 0.35 + 0.15 * f, lean = 0.06 + 0.08 * g;
        double n[3] = { 0.3 * out[0], 1, 0.3 * out[1] };
        uint32_t row[2][2];
        for (int i = 0; i < 2; i++) {
            double w = 0.045 * (1 - 0.8 * i), o = r + lean * i;
            for (int j = 0; j < 2; j++) {
                double s = j ? w : -w;
                double p[3] = { out[0] * o + side[0] * s, h * i, out[1] * o + side[1] * s };
                row[i][j] = vert(b, p, n, j, i);
            }
        }
        tri(b, row[0][0], row[0][1], row[1][0]);
        tri(b, row[1][0], row[0][1], row[1][1]);
    }
}

/* stone far: 5 faces from a ring of 5 points just under the ground to a
 * top point, flat normals. */
static void stone_far(builder *b)
{
    static const double top[3] = { 0.02, 0.18, -0.01 };
    double e[5][3];
    for (int i = 0; i < 5; i++) {
        double a = (i * 72 + 15) * PI / 180, r = i & 1 ? 0.19 : 0.22;
        e[i][0] = r * cos(a);
        e[i][1] = -0.02;   /* in the ground, as the near one's bottom */
        e[i][2] = r * sin(a);
    }
    for (int i = 0; i < 5; i++) {
        const double *p0 = e[i], *p1 = e[(i + 1) % 5];
        double a[3], c[3], n[3], mid[3];
        for (int k = 0; k < 3; k++) {
            a[k] = p1[k] - p0[k];
            c[k] = top[k] - p0[k];
            mid[k] = (p0[k] + p1[k] + top[k]) / 3 - (k == 1 ? 0.07 : 0);
        }
        cross(a, c, n);
        bool flip = n[0] * mid[0] + n[1] * mid[1] + n[2] * mid[2] < 0;
        if (flip)   /* outward normals, counter-clockwise seen from outside */
            for (int k = 0; k < 3; k++)
                n[k] = -n[k];
        /* uv.y as the near stone's: height over its 0.25 m */
        uint32_t v0 = vert(b, p0, n, 0.5, 0.12), v1 = vert(b, p1, n, 0.5, 0.12);
        uint32_t vt = vert(b, top, n, 0.5, (top[1] + 0.05) / 0.25);
        if (flip)
            tri(b, v0, vt, v1);
        else
            tri(b, v0, v1, vt);
    }
}

static bool build(const char *name, void (*const make[])(builder *), splat_mesh *m)
{
    memset(m, 0, sizeof *m);
    for (int i = 0; splat_mesh_builtins[i]; i++)
        if (!strcmp(name, splat_mesh_builtins[i]) && make[i]) {
            builder b = { m, 0, 0 };
            make[i](&b);
            return true;
        }
    return false;
}

bool splat_mesh_builtin(const char *name, splat_mesh *m)
{
    static void (*const make[])(builder *) = { grass, plant, stone };
    return build(name, make, m);
}

bool splat_mesh_builtin_far(const char *name, splat_mesh *m)
{
    static void (*const make[])(builder *) = { grass_far, NULL, stone_far };
    return build(name, make, m);
}

void splat_mesh_free(splat_mesh *m)
{
    free(m->v);
    free(m->idx);
    memset(m, 0, sizeof *m);
}

/* ---- OBJ files ---------------------------------------------------------------- */

/* Index of vertex x in m, appended if new (open addressing over the bytes
 * of the vertex; slots hold index + 1). */
static uint32_t merge(splat_mesh *m, uint32_t *slots, uint32_t mask, const splat_mesh_vertex *x)
{
    uint32_t h = (uint32_t)XXH3_64bits(x, sizeof *x) & mask;
    for (;; h = (h + 1) & mask) {
        uint32_t s = slots[h];
        if (!s) {
            m->v[m->nv] = *x;
            slots[h] = ++m->nv;
            return m->nv - 1;
        }
        if (!memcmp(&m->v[s - 1], x, sizeof *x))
            return s - 1;
    }
}

/* The next whitespace-separated word of line [*p, end), or NULL. */
static const char *word(const char **p, const char *end, size_t *n)
{
    const char *s = *p;
    while (s < end && (*s == ' ' || *s == '\t' || *s == '\r'))
        s++;
    const char *e = s;
    while (e < end && *e != ' ' && *e != '\t' && *e != '\r')
        e++;
    *p = e;
    *n = (size_t)(e - s);
    return e > s ? s : NULL;
}

static bool scan_fail(char **err, size_t line, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
static bool scan_fail(char **err, size_t line, const char *fmt, ...)
{
    char msg[256];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    *err = xasprintf("line %zu: %s", line, msg);
    return false;
}

bool splat_obj_scan(const char *text, size_t len, char **err)
{
    const char *end = text + len;
    size_t line = 0, count[3] = { 0 }, indices = 0;
    static const char *const kinds[3] = { "v", "vn", "vt" };
    for (const char *p = text; p < end; ) {
        const char *eol = memchr(p, '\n', (size_t)(end - p));
        if (!eol)
            eol = end;
        line++;
        const char *at = p;
        p = eol + 1;
        size_t n;
        const char *kw = word(&at, eol, &n);
        if (!kw || kw[0] == '#')
            continue;
        int kind = n == 1 && kw[0] == 'v' ? 0 : n == 2 && kw[0] == 'v' && kw[1] == 'n' ? 1
                 : n == 2 && kw[0] == 'v' && kw[1] == 't' ? 2 : -1;
        if (kind >= 0) {
            if (++count[kind] > SPLAT_MAX_MESH_INDICES)
                return scan_fail(err, line, "more than %d '%s' lines (no mesh within the "
                                 "limit of %d indices can use them)", SPLAT_MAX_MESH_INDICES,
                                 kinds[kind], SPLAT_MAX_MESH_INDICES);
            const char *w;
            for (int k = 0; (w = word(&at, eol, &n)) != NULL; k++) {
                char num[64];
                snprintf(num, sizeof num, "%.*s", (int)(n < 63 ? n : 63), w);
                double x = strtod(num, NULL);
                if (!isfinite(x))
                    return scan_fail(err, line, "'%s' value '%s' is not a finite number",
                                     kinds[kind], num);
                if (kind == 0 && k < 3 && !(fabs(x) <= SPLAT_MAX_MESH_VALUE))
                    return scan_fail(err, line, "vertex coordinate %s is beyond the pack "
                                     "limit of %g m either way", num, SPLAT_MAX_MESH_VALUE);
            }
        } else if (n == 1 && kw[0] == 'f') {
            size_t corners = 0;
            while (word(&at, eol, &n))
                if (++corners > SPLAT_OBJ_MAX_FACE_CORNERS)
                    return scan_fail(err, line, "a face of more than %d corners",
                                     SPLAT_OBJ_MAX_FACE_CORNERS);
            if (corners >= 3 && (indices += 3 * (corners - 2)) > SPLAT_MAX_MESH_INDICES)
                return scan_fail(err, line, "the faces so far make more than %d indices, "
                                 "the limit of an undergrowth mesh", SPLAT_MAX_MESH_INDICES);
        }
    }
    return true;
}

bool splat_mesh_obj(const char *path, splat_mesh *m, char **err)
{
    memset(m, 0, sizeof *m);
    *err = NULL;
    /* only regular files of bounded size (util.h): a FIFO or /dev/zero
     * must not hang the compiler */
    char why[256];
    size_t len = 0;
    char *text = splat_input_read(path, SPLAT_MAX_MESH_BYTES, &len, why, sizeof why);
    if (!text) {
        *err = xstrdup(why);
        return false;
    }
    splat_obj_corners c;
    bool ok = splat_obj_scan(text, len, err) && splat_obj_parse(text, len, &c, err);
    free(text);
    if (!ok)
        return false;
    float ylo = INFINITY, yhi = -INFINITY;
    for (uint32_t i = 0; i < c.n; i++) {
        ylo = fminf(ylo, c.pos[3 * i + 1]);
        yhi = fmaxf(yhi, c.pos[3 * i + 1]);
    }
    uint32_t cap = 16;
    while (cap < 2 * c.n)
        cap *= 2;
    uint32_t *slots = xcalloc(cap, sizeof *slots);
    m->v = xmalloc(c.n * sizeof *m->v);
    m->idx = xmalloc(c.n * sizeof *m->idx);
    m->nidx = c.n;
    for (uint32_t t = 0; t < c.n; t += 3) {
        const float *p = &c.pos[3 * t];
        double a[3], b[3], flat[3];
        for (int i = 0; i < 3; i++) {
            a[i] = (double)p[3 + i] - p[i];
            b[i] = (double)p[6 + i] - p[i];
        }
        cross(a, b, flat);
        double fl = sqrt(flat[0] * flat[0] + flat[1] * flat[1] + flat[2] * flat[2]);
        for (int k = 0; k < 3; k++) {
            uint32_t i = t + k;
            splat_mesh_vertex x;
            memset(&x, 0, sizeof x);   /* padding-free, but merge compares bytes */
            const float *n = &c.nrm[3 * i];
            double nl = sqrt((double)n[0] * n[0] + (double)n[1] * n[1] + (double)n[2] * n[2]);
            for (int j = 0; j < 3; j++) {
                x.pos[j] = c.pos[3 * i + j];
                if (nl > 1e-12 && isfinite(nl))
                    x.nrm[j] = (float)(n[j] / nl);
                else if (fl > 0)
                    x.nrm[j] = (float)(flat[j] / fl);
                else
                    x.nrm[j] = j == 1;             /* degenerate: up */
            }
            float u = c.uv[2 * i], v = c.uv[2 * i + 1];
            if (isnan(u)) {
                x.uv[0] = 0.5f;
                x.uv[1] = yhi > ylo ? (x.pos[1] - ylo) / (yhi - ylo) : 0;
            } else {
                x.uv[0] = isfinite(u) ? u : 0;
                x.uv[1] = isnan(v) ? 0 : fminf(fmaxf(v, 0), 1);
            }
            for (int j = 0; j < 3; j++) {   /* -0 and 0 merge */
                x.pos[j] += 0.0f;
                x.nrm[j] += 0.0f;
                x.uv[j % 2] += 0.0f;
            }
            m->idx[i] = merge(m, slots, cap - 1, &x);
        }
    }
    free(slots);
    free(c.pos);
    free(c.nrm);
    free(c.uv);
    m->v = xrealloc(m->v, (m->nv ? m->nv : 1) * sizeof *m->v);
    return true;
}
