/* imgcheck — small picture checks for the render tests.
 *
 *   imgcheck nonuniform IMG.png          exit 1 if 99 % of the pixels equal
 *                                        the first (IMG.f32: RGB floats)
 *   imgcheck colors IMG.png [r,g,b]      print the distinct colours
 *                                        (without the given background)
 *   imgcheck count IMG.png r,g,b         print pixels of exactly that colour
 *   imgcheck diff A.f32 B.f32 TOL        max |A - B| over RGB; exit 1 if > TOL
 *   imgcheck finite A.f32                exit 1 on any NaN or Inf
 *   imgcheck close A.f32 B.f32 TOL FRAC PSNR   PSNR (dB, peak 1) and the
 *                                        share of pixels within TOL; exit 1
 *                                        below PSNR or under FRAC (0..1)
 *   imgcheck near A.f32 r,g,b TOL MAX    the share of pixels whose RGB is
 *                                        within TOL of (r, g, b) (floats);
 *                                        exit 1 if it is over MAX (0..1)
 *   imgcheck contrast IMG.png MIN        the spread of luma (Rec. 709, 0..1)
 *                                        between its 5th and 95th percentile;
 *                                        exit 1 if under MIN (a picture that
 *                                        is mostly fog or sky has little)
 *   imgcheck overlay A.png B.png BW BH MIN   B is A with the help overlay
 *                                        (splatview --overlay): identical
 *                                        outside the top-left BW x BH box,
 *                                        and inside it at least MIN more
 *                                        near-white (text) pixels than A
 *   imgcheck white IMG.png BW BH         print the near-white pixels (all
 *                                        channels >= 230) in the top-left
 *                                        BW x BH box
 */
#include "splatrt.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <stb_image.h>

static uint8_t *load(const char *path, int *w, int *h)
{
    int ch;
    uint8_t *px = stbi_load(path, w, h, &ch, 4);
    if (!px)
        fprintf(stderr, "imgcheck: cannot read %s\n", path);
    return px;
}

static int cmp_u32(const void *a, const void *b)
{
    uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return (x > y) - (x < y);
}

static bool parse_rgb(const char *s, uint32_t *rgb)
{
    int r, g, b;
    if (sscanf(s, "%d,%d,%d", &r, &g, &b) != 3)
        return false;
    *rgb = (uint32_t)r | (uint32_t)g << 8 | (uint32_t)b << 16;
    return true;
}

int main(int argc, char **argv)
{
    if (argc < 3) {
        fprintf(stderr, "usage: see imgcheck.c\n");
        return 2;
    }
    const char *cmd = argv[1];
    if (!strcmp(cmd, "white") && argc == 5) {
        int w, h, boxw = atoi(argv[3]), boxh = atoi(argv[4]);
        uint8_t *a = load(argv[2], &w, &h);
        if (!a)
            return 1;
        long n = 0;
        for (int y = 0; y < h && y < boxh; y++)
            for (int x = 0; x < w && x < boxw; x++) {
                const uint8_t *p = a + 4 * ((size_t)y * w + x);
                n += p[0] >= 230 && p[1] >= 230 && p[2] >= 230;
            }
        printf("%ld\n", n);
        stbi_image_free(a);
        return 0;
    }
    if (!strcmp(cmd, "overlay") && argc == 7) {
        int aw, ah, bw, bh, boxw = atoi(argv[4]), boxh = atoi(argv[5]), min = atoi(argv[6]);
        uint8_t *a = load(argv[2], &aw, &ah), *b = load(argv[3], &bw, &bh);
        if (!a || !b || aw != bw || ah != bh) {
            fprintf(stderr, "imgcheck: overlay: unreadable pictures or sizes differ\n");
            return 1;
        }
        long outside = 0, white_a = 0, white_b = 0, changed = 0;
        for (int y = 0; y < ah; y++)
            for (int x = 0; x < aw; x++) {
                const uint8_t *pa = a + 4 * ((size_t)y * aw + x), *pb = b + 4 * ((size_t)y * aw + x);
                bool same = !memcmp(pa, pb, 3);
                if (x >= boxw || y >= boxh) {
                    outside += !same;
                    continue;
                }
                changed += !same;
                white_a += pa[0] >= 230 && pa[1] >= 230 && pa[2] >= 230;
                white_b += pb[0] >= 230 && pb[1] >= 230 && pb[2] >= 230;
            }
        printf("overlay: %ld pixels changed in the %dx%d box, near-white %ld -> %ld, "
               "%ld changed outside\n", changed, boxw, boxh, white_a, white_b, outside);
        stbi_image_free(a);
        stbi_image_free(b);
        return outside == 0 && white_b - white_a >= min ? 0 : 1;
    }
    if (!strcmp(cmd, "contrast")) {
        int w, h;
        double min;
        if (argc != 4 || sscanf(argv[3], "%lf", &min) != 1) {
            fprintf(stderr, "usage: imgcheck contrast IMG.png MIN\n");
            return 2;
        }
        uint8_t *px = load(argv[2], &w, &h);
        if (!px)
            return 2;
        size_t n = (size_t)w * (size_t)h, hist[256] = { 0 };
        for (size_t i = 0; i < n; i++) {
            double y = 0.2126 * px[4 * i] + 0.7152 * px[4 * i + 1] + 0.0722 * px[4 * i + 2];
            hist[(int)(y + 0.5) > 255 ? 255 : (int)(y + 0.5)]++;
        }
        stbi_image_free(px);
        int p5 = -1, p95 = -1;
        size_t acc = 0;
        for (int v = 0; v < 256; v++) {
            acc += hist[v];
            if (p5 < 0 && acc * 20 >= n)
                p5 = v;
            if (p95 < 0 && acc * 20 >= n * 19)
                p95 = v;
        }
        double spread = (p95 - p5) / 255.0;
        printf("luma p5 %.3f p95 %.3f spread %.3f\n", p5 / 255.0, p95 / 255.0, spread);
        return spread >= min ? 0 : 1;
    }
    if (!strcmp(cmd, "near")) {
        rt_error e = { 0 };
        float *a = NULL;
        int w, h;
        double ref[3], tol, max;
        if (argc != 6 || sscanf(argv[3], "%lf,%lf,%lf", &ref[0], &ref[1], &ref[2]) != 3) {
            fprintf(stderr, "imgcheck: near A.f32 r,g,b TOL MAX\n");
            return 2;
        }
        tol = atof(argv[4]);
        max = atof(argv[5]);
        if (!rt_read_float(argv[2], &a, &w, &h, &e)) {
            fprintf(stderr, "imgcheck: %s\n", e.msg);
            return 2;
        }
        size_t n = (size_t)w * h, k = 0;
        for (size_t i = 0; i < n; i++) {
            bool close = true;
            for (int c = 0; c < 3; c++)
                close = close && fabs((double)a[i * 4 + c] - ref[c]) <= tol;
            k += close;
        }
        double share = n ? (double)k / (double)n : 0;
        printf("pixels within %g of (%g, %g, %g): %zu of %zu (%.1f %%)\n", tol, ref[0], ref[1],
               ref[2], k, n, 100 * share);
        free(a);
        return share <= max ? 0 : 1;
    }
    if (!strcmp(cmd, "close")) {
        /* PSNR over RGB (peak 1) and the share of pixels whose largest
         * channel difference is over TOL; fails below PSNR or when more
         * than 1 - FRAC of the pixels are over TOL.  The pixels over TOL
         * are told by how many have a sky (clear-colour) neighbour in
         * either image: silhouettes. */
        rt_error e = { 0 };
        float *a = NULL, *b = NULL;
        int w, h, w2, h2;
        if (argc != 7 || !rt_read_float(argv[2], &a, &w, &h, &e) ||
            !rt_read_float(argv[3], &b, &w2, &h2, &e) || w != w2 || h != h2) {
            fprintf(stderr, "imgcheck: close A.f32 B.f32 TOL FRAC PSNR (one size)%s%s\n",
                    e.msg ? ": " : "", e.msg ? e.msg : "");
            free(a);
            free(b);
            return 2;
        }
        double tol = atof(argv[4]), frac = atof(argv[5]), min_psnr = atof(argv[6]), se = 0;
        size_t n = (size_t)w * h, over = 0, edge = 0;
        for (size_t i = 0; i < n; i++) {
            double m = 0;
            for (int c = 0; c < 3; c++) {
                double d = (double)a[i * 4 + c] - (double)b[i * 4 + c];
                se += d * d;
                m = fmax(m, fabs(d));
            }
            if (m > tol) {
                over++;
                /* a neighbour that is background in one image only */
                int x = (int)(i % (size_t)w), y = (int)(i / (size_t)w);
                bool sil = false;
                for (int dy = -1; dy <= 1 && !sil; dy++)
                    for (int dx = -1; dx <= 1 && !sil; dx++) {
                        int X = x + dx, Y = y + dy;
                        if (X < 0 || Y < 0 || X >= w || Y >= h)
                            continue;
                        size_t j = (size_t)Y * (size_t)w + (size_t)X;
                        sil = fabs(a[j * 4] - b[j * 4]) > 0.05 && (dx || dy);
                    }
                edge += sil;
            }
        }
        double mse = se / (double)(n * 3);
        double psnr = mse > 0 ? 10 * log10(1.0 / mse) : INFINITY;
        double share = (double)(n - over) / (double)n;
        printf("psnr %.2f dB, %.4f %% of pixels within %.4g (%zu over, %zu of them next to a "
               "silhouette)\n", psnr, 100 * share, tol, over, edge);
        free(a);
        free(b);
        return psnr >= min_psnr && share >= frac ? 0 : 1;
    }
    if (!strcmp(cmd, "diff") || !strcmp(cmd, "finite")) {
        rt_error e = { 0 };
        float *a = NULL, *b = NULL;
        int w, h, w2, h2;
        if (!rt_read_float(argv[2], &a, &w, &h, &e) ||
            (argc > 3 && !rt_read_float(argv[3], &b, &w2, &h2, &e))) {
            fprintf(stderr, "imgcheck: %s\n", e.msg);
            return 2;
        }
        size_t n = (size_t)w * h, bad = 0;
        if (!strcmp(cmd, "finite")) {
            for (size_t i = 0; i < n * 4; i++)
                bad += !isfinite(a[i]);
            printf("non-finite values: %zu\n", bad);
            free(a);
            free(b);
            return bad ? 1 : 0;
        }
        if (argc != 5 || w != w2 || h != h2) {
            fprintf(stderr, "imgcheck: diff needs two images of one size and a tolerance\n");
            free(a);
            free(b);
            return 2;
        }
        double tol = atof(argv[4]), worst = 0, sum = 0;
        size_t at = 0;
        for (size_t i = 0; i < n; i++)
            for (int c = 0; c < 3; c++) {
                double d = fabs((double)a[i * 4 + c] - (double)b[i * 4 + c]);
                if (!(d <= worst)) {
                    worst = d;
                    at = i;
                }
                sum += d;
                bad += d > tol;
            }
        printf("max abs diff %.3g at (%zu, %zu), mean %.3g, %zu values over %.3g\n", worst,
               at % (size_t)w, at / (size_t)w, sum / (double)(n * 3), bad, tol);
        free(a);
        free(b);
        return worst <= tol ? 0 : 1;
    }
    size_t len = strlen(argv[2]);
    if (!strcmp(cmd, "nonuniform") && len > 4 && !strcmp(argv[2] + len - 4, ".f32")) {
        rt_error e = { 0 };
        float *a = NULL;
        int w, h;
        if (!rt_read_float(argv[2], &a, &w, &h, &e)) {
            fprintf(stderr, "imgcheck: %s\n", e.msg);
            rt_error_clear(&e);
            return 2;
        }
        size_t n = (size_t)w * h, differ = 0;
        for (size_t i = 0; i < n; i++)
            differ += memcmp(&a[i * 4], &a[0], 3 * sizeof *a) != 0;
        printf("pixels unlike the first: %zu of %zu\n", differ, n);
        free(a);
        return n && differ > n / 100 ? 0 : 1;
    }
    int w, h;
    uint8_t *px = load(argv[2], &w, &h);
    if (!px)
        return 2;
    size_t n = (size_t)w * h;
    uint32_t *c = malloc(n * sizeof *c);
    if (!c)
        return 2;
    for (size_t i = 0; i < n; i++)
        c[i] = (uint32_t)px[4 * i] | (uint32_t)px[4 * i + 1] << 8 | (uint32_t)px[4 * i + 2] << 16;
    int rc = 0;
    if (!strcmp(cmd, "nonuniform")) {
        size_t differ = 0;
        for (size_t i = 0; i < n; i++)
            differ += c[i] != c[0];
        printf("pixels unlike the first: %zu of %zu\n", differ, n);
        rc = differ > n / 100 ? 0 : 1;
    } else if (!strcmp(cmd, "colors")) {
        uint32_t bg = 0xffffffffu;
        if (argc > 3 && !parse_rgb(argv[3], &bg))
            return 2;
        qsort(c, n, sizeof *c, cmp_u32);
        size_t distinct = 0;
        for (size_t i = 0; i < n; i++)
            if ((i == 0 || c[i] != c[i - 1]) && c[i] != bg)
                distinct++;
        printf("%zu\n", distinct);
    } else if (!strcmp(cmd, "count") && argc > 3) {
        uint32_t want;
        if (!parse_rgb(argv[3], &want))
            return 2;
        size_t k = 0;
        for (size_t i = 0; i < n; i++)
            k += c[i] == want;
        printf("%zu\n", k);
    } else {
        fprintf(stderr, "imgcheck: unknown command '%s'\n", cmd);
        rc = 2;
    }
    free(c);
    stbi_image_free(px);
    return rc;
}
