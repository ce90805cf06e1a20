/* bench_util.c — splatbench's shared helpers (bench.h): files, medians,
 * memory, the image error and the analytic heightfield. */
#include "bench.h"
#include "zst.h"

#include <math.h>
#include <stdlib.h>
#include <time.h>
#include <unistd.h>

/* A pack file's bytes (NUL after them), decompressed where its name ends
 * in ".zst" (compiler/PACK.md "Compressed shaders"). */
static uint8_t *read_pack_file(const char *path, size_t *n)
{
    *n = 0;
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    fseek(f, 0, SEEK_END);
    long bytes = ftell(f);
    fseek(f, 0, SEEK_SET);
    uint8_t *data = bytes >= 0 ? xcalloc((size_t)bytes + 1, 1) : NULL;
    if (data && bytes > 0 && fread(data, 1, (size_t)bytes, f) != (size_t)bytes) {
        free(data);
        data = NULL;
    }
    fclose(f);
    if (data && splat_zst_name(path)) {
        char why[256];
        size_t raw = 0;
        uint8_t *d = splat_zst_decompress(data, (size_t)bytes, (size_t)64 << 20, &raw, why,
                                          sizeof why);
        if (!d)
            fprintf(stderr, "splatbench: %s %s\n", path, why);
        free(data);
        *n = raw;
        return d;
    }
    *n = data ? (size_t)bytes : 0;
    return data;
}

char *read_text(const char *path)
{
    size_t n;
    return (char *)read_pack_file(path, &n);
}

bool read_words(const char *path, uint32_t **words, size_t *n)
{
    size_t bytes = 0;
    uint8_t *data = read_pack_file(path, &bytes);
    if (!data || bytes == 0 || bytes % 4) {
        free(data);
        return false;
    }
    *words = (uint32_t *)data;
    *n = bytes / 4;
    return true;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* median, 10th and 90th percentile of n samples (sorted in place) */
void percentiles(double *v, int n, double *med, double *p10, double *p90)
{
    qsort(v, (size_t)n, sizeof *v, cmp_double);
    *med = n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
    *p10 = v[(int)floor(0.1 * (n - 1))];
    *p90 = v[(int)ceil(0.9 * (n - 1))];
}

/* resident set size now, MB (lavapipe's "GPU" memory is host memory) */
double process_cpu_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec * 1e-6;
}

double rss_mb(void)
{
    FILE *f = fopen("/proc/self/statm", "r");
    long pages = 0, res = 0;
    if (f) {
        if (fscanf(f, "%ld %ld", &pages, &res) != 2)
            res = 0;
        fclose(f);
    }
    return (double)res * (double)sysconf(_SC_PAGESIZE) / (1024.0 * 1024.0);
}

/* ---- image error ---------------------------------------------------------- */


/* RGB of `img` against `ref` (w*h RGBA floats).  A NaN/Inf in img counts
 * as nonfinite and as an error of 1 (so it cannot hide in the mean). */
void err_add(err_acc *a, const float *img, const float *ref, size_t npx)
{
    for (size_t i = 0; i < npx; i++)
        for (int c = 0; c < 3; c++) {
            float v = img[4 * i + c], r = ref[4 * i + c];
            double d;
            if (!isfinite(v) || !isfinite(r)) {
                a->nonfinite++;
                d = 1.0;
            } else {
                d = fabs((double)v - (double)r);
            }
            a->max_abs = d > a->max_abs ? d : a->max_abs;
            a->sum_abs += d;
            a->sum_sq += d * d;
            a->n++;
        }
}

double err_psnr(const err_acc *a)
{
    double mse = a->n ? a->sum_sq / (double)a->n : 0;
    return mse > 0 ? 10.0 * log10(1.0 / mse) : 999.0;
}
/* The analytic heightfield: normalised height at heightfield uv (u, v),
 * within 0.1 .. 0.9, and its exact normal in GLSL (terrain.x, .y: size in
 * metres, .z: max height), written from the same formula. */
double analytic_height(double u, double v)
{
    const double tau = 6.283185307179586;
    return 0.5 + 0.25 * sin(tau * 3 * u) * cos(tau * 2 * v) + 0.15 * sin(tau * 7 * (u + v));
}
