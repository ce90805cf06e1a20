/* stairs — a stair-step measure of a rendered mask edge (issue 31: masks
 * without stair steps).
 *
 *   stairs measure MASK.f32 KNOT MAXRMS MAXDEV [X0 Y0 X1 Y1]
 *       the mask view's float image (splatview --view mask:M --float-out):
 *       the 0.5 contour of the mask (marching squares, sub-pixel vertices
 *       by linear interpolation between pixel centres) inside the
 *       rectangle (default: the whole image), over pixels that are terrain
 *       (grey: the mask view writes vec3(mask); the sky is not grey) and
 *       where the mask changes by at most STEEP between neighbouring
 *       pixels.  Its chains of at least 4 KNOT pixels of arc length are
 *       each fitted, x and y apart as functions of arc length, by a
 *       least-squares cubic B-spline with knots every KNOT pixels: a smooth
 *       curve at the scale of a few texels, which a staircase of texels
 *       smaller than KNOT on screen departs from.  Prints the chains,
 *       points, the RMS and the largest deviation (pixels) of the contour
 *       from its spline; exit 1 if the RMS is over MAXRMS, the largest
 *       over MAXDEV, or fewer than MIN_POINTS points were measured.
 *       $STAIRS_DEBUG=OUT.png: the mask, darkened, with the measured
 *       points from green (on the spline) to red (1 px or more off it).
 *   stairs crop IMG.f32|IMG.png X Y W H ZOOM OUT.png
 *       the rectangle, enlarged ZOOM times (nearest), clamped to [0, 1]
 *       and written as an 8-bit PNG (to look at the edge).
 */
#include "splatrt.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <stb_image.h>

/* A larger jump between neighbouring pixels is not measured: a silhouette
 * (a near ridge hiding the masked ground behind it) or an edge sharper
 * than a pixel, whose sampled position snaps to the pixel grid; either
 * would measure the pixels' staircase, not the mask's. */
#define STEEP 0.3
#define MIN_POINTS 40   /* fewer: no edge to measure, a failure */

typedef struct { float *px; int w, h; } image;

static float mask_at(const image *im, int x, int y) { return im->px[((size_t)y * im->w + x) * 4]; }

static bool terrain(const image *im, int x, int y)
{
    const float *p = im->px + ((size_t)y * im->w + x) * 4;
    return fabsf(p[0] - p[1]) < 1e-4f && fabsf(p[1] - p[2]) < 1e-4f;
}

/* ---- the contour ---------------------------------------------------------- */

/* Crossing points live on pixel-centre edges: edge 2k is between pixel k =
 * y*w + x and its right neighbour, 2k + 1 between it and the one below. */
typedef struct {
    int    *link;     /* per edge: up to 2 neighbouring edges, -1 none    */
    double *pos;      /* per edge: x, y of the crossing                   */
    char   *has;      /* per edge: crossed                                */
} contour;

static void add_link(contour *c, int a, int b)
{
    for (int i = 0; i < 2; i++)
        if (c->link[2 * a + i] < 0) { c->link[2 * a + i] = b; return; }
}

static int crossing(contour *c, const image *im, int x0, int y0, int x1, int y1, int e)
{
    if (!c->has[e]) {
        double a = mask_at(im, x0, y0), b = mask_at(im, x1, y1);
        double t = (0.5 - a) / (b - a);
        c->pos[2 * e] = x0 + (x1 - x0) * t + 0.5;   /* pixel centres at +0.5 */
        c->pos[2 * e + 1] = y0 + (y1 - y0) * t + 0.5;
        c->has[e] = 1;
    }
    return e;
}

static bool build(contour *c, const image *im, int rx0, int ry0, int rx1, int ry1)
{
    size_t n = (size_t)im->w * im->h * 2;
    c->link = malloc(n * 2 * sizeof *c->link);
    c->pos = malloc(n * 2 * sizeof *c->pos);
    c->has = calloc(n, 1);
    if (!c->link || !c->pos || !c->has) return false;
    for (size_t i = 0; i < n * 2; i++) c->link[i] = -1;
    for (int y = ry0; y + 1 < ry1; y++)
        for (int x = rx0; x + 1 < rx1; x++) {
            if (!terrain(im, x, y) || !terrain(im, x + 1, y) || !terrain(im, x, y + 1) ||
                !terrain(im, x + 1, y + 1))
                continue;
            double v[4] = { mask_at(im, x, y), mask_at(im, x + 1, y), mask_at(im, x + 1, y + 1),
                            mask_at(im, x, y + 1) };
            bool steep = false;
            for (int i = 0; i < 4; i++)
                steep = steep || fabs(v[i] - v[(i + 1) % 4]) > STEEP;
            if (steep) continue;
            int code = 0;
            for (int i = 0; i < 4; i++)
                code |= (v[i] >= 0.5) << i;
            if (code == 0 || code == 15) continue;
            int k = y * im->w + x;
            /* the square's sides: top, right, bottom, left, and their ends */
            int side[4] = { 2 * k, 2 * (k + 1) + 1, 2 * (k + im->w), 2 * k + 1 };
            int ends[4][4] = { { x, y, x + 1, y }, { x + 1, y, x + 1, y + 1 },
                               { x, y + 1, x + 1, y + 1 }, { x, y, x, y + 1 } };
            int cut[4], nc = 0;
            for (int s = 0; s < 4; s++)
                if (((code >> s) & 1) != ((code >> ((s + 1) % 4)) & 1))
                    cut[nc++] = crossing(c, im, ends[s][0], ends[s][1], ends[s][2], ends[s][3],
                                         side[s]);
            if (nc == 2) {
                add_link(c, cut[0], cut[1]);
                add_link(c, cut[1], cut[0]);
            } else if (nc == 4) {   /* a saddle: pair by the centre's side */
                bool centre = (v[0] + v[1] + v[2] + v[3]) / 4 >= 0.5;
                bool c0 = (code & 1) != 0;
                int p = centre == c0 ? 0 : 1;   /* pair sides (0,1)(2,3) or (0,3)(1,2) */
                int a0 = 0, a1 = p ? 3 : 1, b0 = p ? 1 : 2, b1 = p ? 2 : 3;
                add_link(c, cut[a0], cut[a1]); add_link(c, cut[a1], cut[a0]);
                add_link(c, cut[b0], cut[b1]); add_link(c, cut[b1], cut[b0]);
            }
        }
    return true;
}

/* ---- the least-squares cubic B-spline ------------------------------------- */

static void bspline_w(double t, double w[4])
{
    double s = 1 - t, t2 = t * t, t3 = t2 * t;
    w[0] = s * s * s / 6;
    w[1] = (3 * t3 - 6 * t2 + 4) / 6;
    w[2] = (-3 * t3 + 3 * t2 + 3 * t + 1) / 6;
    w[3] = t3 / 6;
}

/* Fit y(s) at n points with knots every `knot`; residuals into r. */
static bool fit(const double *s, const double *y, int n, double knot, double *r)
{
    int nk = (int)ceil(s[n - 1] / knot) + 3;   /* basis functions */
    double *A = calloc((size_t)nk * nk, sizeof *A), *b = calloc((size_t)nk, sizeof *b);
    if (!A || !b) { free(A); free(b); return false; }
    for (int i = 0; i < n; i++) {
        double u = s[i] / knot, w[4];
        int k = (int)floor(u);
        if (k > nk - 4) k = nk - 4;
        bspline_w(u - k, w);
        for (int a = 0; a < 4; a++) {
            b[k + a] += w[a] * y[i];
            for (int c = 0; c < 4; c++)
                A[(size_t)(k + a) * nk + k + c] += w[a] * w[c];
        }
    }
    for (int i = 0; i < nk; i++)
        A[(size_t)i * nk + i] += 1e-9;   /* knots no point reaches */
    for (int i = 0; i < nk; i++)   /* Gaussian elimination, SPD: no pivoting */
        for (int j = i + 1; j < nk && j < i + 4; j++) {
            double f = A[(size_t)j * nk + i] / A[(size_t)i * nk + i];
            for (int c = i; c < nk && c < i + 4; c++)
                A[(size_t)j * nk + c] -= f * A[(size_t)i * nk + c];
            b[j] -= f * b[i];
        }
    for (int i = nk - 1; i >= 0; i--) {
        for (int c = i + 1; c < nk && c < i + 4; c++)
            b[i] -= A[(size_t)i * nk + c] * b[c];
        b[i] /= A[(size_t)i * nk + i];
    }
    for (int i = 0; i < n; i++) {
        double u = s[i] / knot, w[4], v = 0;
        int k = (int)floor(u);
        if (k > nk - 4) k = nk - 4;
        bspline_w(u - k, w);
        for (int a = 0; a < 4; a++)
            v += w[a] * b[k + a];
        r[i] = y[i] - v;
    }
    free(A);
    free(b);
    return true;
}

static int measure(int argc, char **argv)
{
    image im;
    rt_error e = {0};
    if (!rt_read_float(argv[2], &im.px, &im.w, &im.h, &e)) {
        fprintf(stderr, "stairs: %s\n", e.msg ? e.msg : argv[2]);
        return 2;
    }
    double knot = atof(argv[3]), maxrms = atof(argv[4]), maxdev = atof(argv[5]);
    int r[4] = { 0, 0, im.w, im.h };
    if (argc == 10)
        for (int i = 0; i < 4; i++) r[i] = atoi(argv[6 + i]);
    if (r[0] < 0) r[0] = 0;
    if (r[1] < 0) r[1] = 0;
    if (r[2] > im.w) r[2] = im.w;
    if (r[3] > im.h) r[3] = im.h;
    contour c;
    if (!(knot > 0) || !build(&c, &im, r[0], r[1], r[2], r[3])) {
        fprintf(stderr, "stairs: bad knot spacing or out of memory\n");
        return 2;
    }
    size_t ne = (size_t)im.w * im.h * 2;
    char *seen = calloc(ne, 1);
    int *chain = malloc(ne * sizeof *chain);
    double *s = malloc(ne * sizeof *s), *xs = malloc(ne * sizeof *xs), *ys = malloc(ne * sizeof *ys);
    double *rx = malloc(ne * sizeof *rx), *ry = malloc(ne * sizeof *ry);
    double sum2 = 0, worst = 0;
    /* $STAIRS_DEBUG=FILE.png: the mask with the measured contour points,
     * green on the spline to red 1 px or more off it */
    const char *dbg_path = getenv("STAIRS_DEBUG");
    uint8_t *dbg = dbg_path ? malloc((size_t)im.w * im.h * 4) : NULL;
    for (size_t i = 0; dbg && i < (size_t)im.w * im.h; i++) {
        for (int k = 0; k < 3; k++) {
            float v = im.px[i * 4 + k] * 0.5f;
            dbg[i * 4 + k] = (uint8_t)(255 * (v < 0 ? 0 : v > 1 ? 1 : v));
        }
        dbg[i * 4 + 3] = 255;
    }
    long points = 0;
    int chains = 0;
    /* open chains from their ends first, then closed loops */
    for (int pass = 0; pass < 2; pass++)
        for (size_t e0 = 0; e0 < ne; e0++) {
            if (!c.has[e0] || seen[e0]) continue;
            int deg = (c.link[2 * e0] >= 0) + (c.link[2 * e0 + 1] >= 0);
            if (pass == 0 && deg != 1) continue;
            int n = 0, cur = (int)e0, prev = -1;
            while (cur >= 0 && !seen[cur]) {
                seen[cur] = 1;
                chain[n++] = cur;
                int nx = c.link[2 * cur] != prev ? c.link[2 * cur] : c.link[2 * cur + 1];
                if (nx == prev) nx = -1;
                prev = cur;
                cur = nx;
            }
            s[0] = 0;
            for (int i = 0; i < n; i++) {
                xs[i] = c.pos[2 * chain[i]];
                ys[i] = c.pos[2 * chain[i] + 1];
                if (i) s[i] = s[i - 1] + hypot(xs[i] - xs[i - 1], ys[i] - ys[i - 1]);
            }
            if (n < 8 || s[n - 1] < 4 * knot) continue;
            if (!fit(s, xs, n, knot, rx) || !fit(s, ys, n, knot, ry)) return 2;
            chains++;
            for (int i = 0; i < n; i++) {
                double d2 = rx[i] * rx[i] + ry[i] * ry[i];
                if (dbg) {   /* red: off the spline by 1 px or more */
                    int px = (int)xs[i], py = (int)ys[i];
                    uint8_t *o = dbg + ((size_t)py * im.w + px) * 4;
                    double q = fmin(sqrt(d2), 1.0);
                    o[0] = (uint8_t)(255 * q);
                    o[1] = (uint8_t)(255 * (1 - q));
                    o[2] = 0;
                }
                sum2 += d2;
                worst = fmax(worst, sqrt(d2));
                points++;
            }
        }
    double rms = points ? sqrt(sum2 / points) : 0;
    if (dbg) {
        rt_write_png(dbg_path, dbg, im.w, im.h, &e);
        free(dbg);
    }
    printf("stairs: %d chains, %ld points, deviation from the spline (knots every %g px): "
           "RMS %.3f px, max %.3f px\n", chains, points, knot, rms, worst);
    free(seen); free(chain); free(s); free(xs); free(ys); free(rx); free(ry);
    free(c.link); free(c.pos); free(c.has); free(im.px);
    if (points < MIN_POINTS) {
        fprintf(stderr, "stairs: only %ld contour points: no mask edge to measure\n", points);
        return 1;
    }
    if (rms > maxrms || worst > maxdev) {
        fprintf(stderr, "stairs: deviation RMS %.3f px (at most %g), max %.3f px (at most %g): "
                "the edge steps\n", rms, maxrms, worst, maxdev);
        return 1;
    }
    return 0;
}

static int crop(char **argv)
{
    image im;
    rt_error e = {0};
    size_t len = strlen(argv[2]);
    if (len > 4 && !strcmp(argv[2] + len - 4, ".png")) {   /* an 8-bit picture */
        int ch;
        uint8_t *p8 = stbi_load(argv[2], &im.w, &im.h, &ch, 4);
        if (!p8) {
            fprintf(stderr, "stairs: cannot read %s\n", argv[2]);
            return 2;
        }
        im.px = malloc(sizeof *im.px * 4 * (size_t)im.w * im.h);
        for (size_t i = 0; i < 4 * (size_t)im.w * im.h; i++) im.px[i] = p8[i] / 255.0f;
        stbi_image_free(p8);
    } else if (!rt_read_float(argv[2], &im.px, &im.w, &im.h, &e)) {
        fprintf(stderr, "stairs: %s\n", e.msg ? e.msg : argv[2]);
        return 2;
    }
    int X = atoi(argv[3]), Y = atoi(argv[4]), W = atoi(argv[5]), H = atoi(argv[6]);
    int z = atoi(argv[7]);
    if (W <= 0 || H <= 0 || z <= 0 || z > 64) return 2;
    uint8_t *out = malloc((size_t)W * z * H * z * 4);
    for (int y = 0; y < H * z; y++)
        for (int x = 0; x < W * z; x++) {
            int sx = X + x / z, sy = Y + y / z;
            uint8_t *o = out + ((size_t)y * W * z + x) * 4;
            for (int k = 0; k < 3; k++) {
                float v = sx >= 0 && sy >= 0 && sx < im.w && sy < im.h
                              ? im.px[((size_t)sy * im.w + sx) * 4 + k] : 0.0f;
                v = v < 0 ? 0 : v > 1 ? 1 : v;
                o[k] = (uint8_t)(v * 255 + 0.5f);
            }
            o[3] = 255;
        }
    bool ok = rt_write_png(argv[8], out, W * z, H * z, &e);
    free(out);
    free(im.px);
    return ok ? 0 : 2;
}

int main(int argc, char **argv)
{
    if (argc >= 6 && !strcmp(argv[1], "measure") && (argc == 6 || argc == 10))
        return measure(argc, argv);
    if (argc == 9 && !strcmp(argv[1], "crop"))
        return crop(argv);
    fprintf(stderr, "usage: stairs measure MASK.f32 KNOT MAXRMS MAXDEV [X0 Y0 X1 Y1]\n"
                    "       stairs crop IMG.f32|IMG.png X Y W H ZOOM OUT.png\n");
    return 2;
}
