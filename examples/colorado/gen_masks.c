/* gen_masks.c — the painted masks of the colorado example, generated from
 * the DEM so they sit where fields and roads would be (deterministic: no
 * clock, no rand(); the same DEM gives the same files).
 *
 *   colorado_gen_masks trinidad.png OUTDIR
 *
 * writes four 8-bit greyscale masks of the DEM's size (2401 x 1201):
 *   field_wheat.png, field_plowed.png, field_fallow.png — fields on flat
 *       lowland, like Andersson 2007 Fig. 10's scattered painted fields: centre-
 *       pivot circles in the San Luis Valley (the west), rectangles on the
 *       plains (the east); each field gets one of the three crops;
 *   road.png — roads found as least-cost paths (Dijkstra; cost grows with
 *       slope) between fixed end points, so they follow valleys and passes
 *       as real ones do.  The fields keep clear of it.
 * With SPLINES.txt, the same roads as a scene `spline` block of one curve
 * each (smoothed, simplified to 40 m): what scene.sg's spline road was made
 * from (the road material reads it as a vector mask, compiler/vector.c).
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <stb_image.h>

#include "texgen.h"

/* World spacing of the DEM (examples/colorado/README.md). */
enum { NMASKS = 4 };
static const double DX = 73.5, DZ = 92.6;           /* metres per texel  */
static const double MAX_H = 4320.894 - 1358.652, OFFSET = 1358.652;
static const char *const names[NMASKS] = {"field_wheat", "field_plowed", "field_fallow", "road"};

typedef struct grid { int w, h; const uint16_t *hf; float *slope; } grid;

static double height_m(const grid *g, int x, int z)
{
    x = x < 0 ? 0 : x >= g->w ? g->w - 1 : x;
    z = z < 0 ? 0 : z >= g->h ? g->h - 1 : z;
    return g->hf[(size_t)z * g->w + x] / 65535.0 * MAX_H + OFFSET;
}

/* slope = 1 - normal.y from central differences in metres */
static void compute_slope(grid *g)
{
    for (int z = 0; z < g->h; z++)
        for (int x = 0; x < g->w; x++) {
            double gx = (height_m(g, x + 1, z) - height_m(g, x - 1, z)) / (2 * DX);
            double gz = (height_m(g, x, z + 1) - height_m(g, x, z - 1)) / (2 * DZ);
            g->slope[(size_t)z * g->w + x] = (float)(1.0 - 1.0 / sqrt(1 + gx * gx + gz * gz));
        }
}

/* ---- fields ------------------------------------------------------------ */

enum { CELL_X = 12, CELL_Z = 10 };   /* about 880 m x 930 m: a quarter section-ish */

static void paint_fields(const grid *g, uint8_t *masks[NMASKS])
{
    for (int cz = 0; cz + CELL_Z <= g->h; cz += CELL_Z)
        for (int cx = 0; cx + CELL_X <= g->w; cx += CELL_X) {
            double hmax = 0, smax = 0;
            for (int z = cz; z < cz + CELL_Z; z++)
                for (int x = cx; x < cx + CELL_X; x++) {
                    double hm = height_m(g, x, z), s = g->slope[(size_t)z * g->w + x];
                    hmax = hm > hmax ? hm : hmax;
                    smax = s > smax ? s : smax;
                }
            /* farmland: flat and below the foothills */
            if (hmax > 2500 || smax > 0.004)
                continue;
            /* farms cluster in districts (low-frequency noise), and inside
             * a district most cells are fields */
            double district = texgen_fbm((double)cx / g->w * 6, (double)cz / g->h * 3,
                                         6, 3, 3, 0.5, 77);
            uint32_t h = texgen_hash(cx, cz, 2024);
            if (district < 0.05 || (h & 255) < 40)
                continue;
            int crop = (int)((h >> 8) % 3);
            bool pivot = cx < g->w * 2 / 5;      /* San Luis Valley: centre pivots */
            uint8_t *m = masks[crop];
            for (int z = cz; z < cz + CELL_Z; z++)
                for (int x = cx; x < cx + CELL_X; x++) {
                    double v;
                    if (pivot) {
                        /* circle in metres, anti-aliased over about one texel */
                        double ex = (x + 0.5 - cx - CELL_X / 2.0) * DX;
                        double ez = (z + 0.5 - cz - CELL_Z / 2.0) * DZ;
                        double r = 0.5 * CELL_X * DX * 0.92, d = sqrt(ex * ex + ez * ez);
                        v = (r - d) / DX + 0.5;
                    } else {
                        /* rectangle with a one-texel margin (field edges) */
                        v = (x > cx && x < cx + CELL_X - 1 && z > cz && z < cz + CELL_Z - 1) ? 1 : 0;
                    }
                    v = v < 0 ? 0 : v > 1 ? 1 : v;
                    m[(size_t)z * g->w + x] = (uint8_t)floor(v * 255 + 0.5);
                }
        }
}

/* ---- roads ------------------------------------------------------------- */

typedef struct heap { int32_t *node; double *key; int n; } heap;

static void heap_push(heap *hp, int32_t node, double key)
{
    int i = hp->n++;
    while (i > 0) {
        int p = (i - 1) / 2;
        if (hp->key[p] <= key)
            break;
        hp->node[i] = hp->node[p];
        hp->key[i] = hp->key[p];
        i = p;
    }
    hp->node[i] = node;
    hp->key[i] = key;
}

static int32_t heap_pop(heap *hp)
{
    int32_t top = hp->node[0];
    int32_t last = hp->node[--hp->n];
    double lk = hp->key[hp->n];
    int i = 0;
    for (;;) {
        int c = 2 * i + 1;
        if (c >= hp->n)
            break;
        if (c + 1 < hp->n && hp->key[c + 1] < hp->key[c])
            c++;
        if (hp->key[c] >= lk)
            break;
        hp->node[i] = hp->node[c];
        hp->key[i] = hp->key[c];
        i = c;
    }
    hp->node[i] = last;
    hp->key[i] = lk;
    return top;
}

/* Douglas-Peucker: keep[i] set for the points of p[lo..hi] (x, z pairs)
 * that the polyline needs to stay within `tol` metres. */
static void simplify(const double *p, int lo, int hi, double tol, uint8_t *keep)
{
    double ax = p[2 * lo], az = p[2 * lo + 1], bx = p[2 * hi], bz = p[2 * hi + 1];
    double len = hypot(bx - ax, bz - az), worst = 0;
    int at = -1;
    for (int i = lo + 1; i < hi; i++) {
        double d = len > 0 ? fabs((bx - ax) * (az - p[2 * i + 1]) - (ax - p[2 * i]) * (bz - az)) / len
                           : hypot(p[2 * i] - ax, p[2 * i + 1] - az);
        if (d > worst) worst = d, at = i;
    }
    if (at < 0 || worst <= tol)
        return;
    keep[at] = 1;
    simplify(p, lo, at, tol, keep);
    simplify(p, at, hi, tol, keep);
}

/* The road's path as a `points` curve of the spline (terrain-local metres at
 * texel centres): smoothed along the path (a 9-texel moving average takes
 * out the 8-connected stair steps), then Douglas-Peucker to 40 m. */
static void print_spline(FILE *out, int r, const int32_t *path, int n, int w)
{
    double *p = malloc(2 * (size_t)n * sizeof *p);
    uint8_t *keep = calloc((size_t)n, 1);
    if (!p || !keep) {
        free(p); free(keep);
        return;
    }
    for (int i = 0; i < n; i++) {
        double sx = 0, sz = 0;
        int k = 0;
        for (int j = i - 4; j <= i + 4; j++) {
            int q = j < 0 ? 0 : j >= n ? n - 1 : j;
            sx += (path[q] % w + 0.5) * DX;
            sz += (path[q] / w + 0.5) * DZ;
            k++;
        }
        p[2 * i] = sx / k;
        p[2 * i + 1] = sz / k;
    }
    keep[0] = keep[n - 1] = 1;
    simplify(p, 0, n - 1, 40.0, keep);
    fprintf(out, "        # road %d\n        points = [", r);
    int col = 0;
    for (int i = 0; i < n; i++)
        if (keep[i])
            fprintf(out, "%s%.0f %.0f", col == 0 ? "" : col % 7 ? ", " : ",\n                  ",
                    p[2 * i], p[2 * i + 1]), col++;
    fprintf(out, "]\n");
    free(p);
    free(keep);
}

/* Least-cost 8-connected path from a to b; cost per step = metres x
 * (1 + 400 slope^2 x ...), so steep ground is avoided.  Paints the path;
 * with `splines`, prints it there as a curve of spline `road`. */
static bool paint_road(const grid *g, int ax, int az, int bx, int bz, uint8_t *m,
                       FILE *splines, int r)
{
    size_t n = (size_t)g->w * g->h;
    double *dist = malloc(n * sizeof *dist);
    int32_t *from = malloc(n * sizeof *from);
    /* each node is pushed at most 8 times (once per relaxation) */
    heap hp = {malloc(n * 8 * sizeof(int32_t)), malloc(n * 8 * sizeof(double)), 0};
    if (!dist || !from || !hp.node || !hp.key) {
        free(dist); free(from); free(hp.node); free(hp.key);
        return false;
    }
    for (size_t i = 0; i < n; i++) {
        dist[i] = INFINITY;
        from[i] = -1;
    }
    int32_t src = az * g->w + ax, dst = bz * g->w + bx;
    dist[src] = 0;
    heap_push(&hp, src, 0);
    static const int dxs[8] = {1, -1, 0, 0, 1, 1, -1, -1}, dzs[8] = {0, 0, 1, -1, 1, -1, 1, -1};
    while (hp.n) {
        int32_t u = heap_pop(&hp);
        if (u == dst)
            break;
        int ux = u % g->w, uz = u / g->w;
        for (int k = 0; k < 8; k++) {
            int vx = ux + dxs[k], vz = uz + dzs[k];
            if (vx < 0 || vz < 0 || vx >= g->w || vz >= g->h)
                continue;
            int32_t v = vz * g->w + vx;
            double run = sqrt(dxs[k] * dxs[k] * DX * DX + dzs[k] * dzs[k] * DZ * DZ);
            double rise = fabs(height_m(g, vx, vz) - height_m(g, ux, uz));
            double grade = rise / run;
            double d = dist[u] + run * (1 + 400 * grade * grade);
            if (d < dist[v]) {
                dist[v] = d;
                from[v] = u;
                heap_push(&hp, v, d);
            }
        }
    }
    bool ok = from[dst] >= 0;
    if (ok && splines) {   /* the path, a to b */
        int np = 0;
        for (int32_t v = dst; v >= 0; v = from[v])
            np++;
        int32_t *path = malloc((size_t)np * sizeof *path);
        if (path) {
            int i = np;
            for (int32_t v = dst; v >= 0; v = from[v])
                path[--i] = v;
            print_spline(splines, r, path, np, g->w);
            free(path);
        }
    }
    for (int32_t v = dst; ok && v >= 0; v = from[v]) {
        int x = v % g->w, z = v / g->w;
        for (int dz = -1; dz <= 1; dz++)
            for (int dx = -1; dx <= 1; dx++) {
                int px = x + dx, pz = z + dz;
                if (px < 0 || pz < 0 || px >= g->w || pz >= g->h)
                    continue;
                uint8_t val = (dx == 0 && dz == 0) ? 255 : (dx == 0 || dz == 0) ? 110 : 40;
                uint8_t *p = &m[(size_t)pz * g->w + px];
                *p = val > *p ? val : *p;
            }
    }
    free(dist); free(from); free(hp.node); free(hp.key);
    return ok;
}

int main(int argc, char **argv)
{
    if (argc != 3 && argc != 4) {
        fprintf(stderr, "usage: %s DEM.png OUTDIR [SPLINES.txt]\n", argv[0]);
        return 2;
    }
    FILE *splines = NULL;
    if (argc == 4 && !(splines = fopen(argv[3], "w"))) {
        fprintf(stderr, "%s: cannot write\n", argv[3]);
        return 1;
    }
    grid g = {0};
    int ch;
    uint16_t *hf = stbi_load_16(argv[1], &g.w, &g.h, &ch, 1);
    if (!hf) {
        fprintf(stderr, "%s: cannot read 16-bit PNG: %s\n", argv[1], stbi_failure_reason());
        return 1;
    }
    g.hf = hf;
    size_t n = (size_t)g.w * g.h;
    g.slope = malloc(n * sizeof *g.slope);
    uint8_t *masks[NMASKS];
    for (int i = 0; i < NMASKS; i++)
        masks[i] = calloc(n, 1);
    compute_slope(&g);
    paint_fields(&g, masks);

    /* Road end points, as fractions of the map (x east, z south):
     * across the range from the San Luis Valley to the plains (the US-160
     * idea), north-south along the plains, and down the valley. */
    static const double roads[][4] = {
        {0.03, 0.55, 0.97, 0.60},
        {0.78, 0.02, 0.74, 0.98},
        {0.12, 0.02, 0.22, 0.98},
    };
    int status = 0;
    if (splines)   /* one spline of a curve per road (the material reads one shape) */
        fprintf(splines, "    spline road { width = 10, falloff = 32, profile = smoothstep\n");
    for (size_t r = 0; r < sizeof roads / sizeof roads[0]; r++)
        if (!paint_road(&g, (int)(roads[r][0] * (g.w - 1)), (int)(roads[r][1] * (g.h - 1)),
                        (int)(roads[r][2] * (g.w - 1)), (int)(roads[r][3] * (g.h - 1)), masks[3],
                        splines, (int)r)) {
            fprintf(stderr, "road %zu: no path (or out of memory)\n", r);
            status = 1;
        }
    if (splines)
        fprintf(splines, "    }\n");
    /* a road is not a field */
    for (size_t i = 0; i < n; i++)
        if (masks[3][i])
            for (int f = 0; f < 3; f++)
                masks[f][i] = (uint8_t)(masks[f][i] * (255 - masks[3][i]) / 255);

    for (int i = 0; i < NMASKS && !status; i++) {
        char path[4096];
        snprintf(path, sizeof path, "%s/%s.png", argv[2], names[i]);
        texgen_image img = {g.w, g.h, 1, masks[i]};
        char *err = NULL;
        if (!texgen_write_png(path, &img, &err)) {
            fprintf(stderr, "%s\n", err);
            free(err);
            status = 1;
        }
        size_t painted = 0;
        for (size_t k = 0; k < n; k++)
            painted += masks[i][k] != 0;
        printf("%s  %.1f %% of texels painted\n", path, 100.0 * painted / n);
    }
    for (int i = 0; i < NMASKS; i++)
        free(masks[i]);
    free(g.slope);
    stbi_image_free(hf);
    if (splines && fclose(splines) != 0)
        status = 1;
    return status;
}
