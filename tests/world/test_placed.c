/* test_placed.c — a painted mask at its own resolution (issue: large worlds,
 * part 3) end to end on a Vulkan device (SPLAT_VALIDATE=1: any validation
 * message fails).
 *
 *   test_placed OUTDIR
 *   test_placed --inputs OUTDIR    (only write the inputs: make bench)
 *
 * Writes a 10,000 x 10,000 texel road mask (1 px/m over 10 x 10 km, 10^8
 * texels, all 0 but a 4 m road along x, an 8 m road along z and a 4 m ring)
 * as a deflate GeoTIFF, and a scene over colorado's heightfield (73.5 m x
 * 92.6 m texels) that places it with { origin, size }.  Builds the pack
 * with splatc's library and checks:
 *   - build time and peak memory (printed; the memory must stay under 1 GB);
 *   - the sparse store is under 5 % of the dense 10^8 bytes;
 *   - looking straight down from 60 m, the mask view shows the 4 m road
 *     4 m wide and the 8 m road 8 m wide (within 10 % + 2 px), where a
 *     heightfield-sized mask would be one 73 m texel wide;
 *   - the analysis stays sound: composites against the über-shader within
 *     1/255 at every pixel of close, overview and grazing views;
 *   - the screen-space path (compute shading) reads the placed mask too:
 *     the close view within 4/255 of forward on 99.5 % of pixels (mip
 *     selection from screen derivatives differs at the road's edges);
 *   - no validation messages.
 * Pictures of the views go to OUTDIR. */
#include "rt_internal.h"
#include "kit.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <time.h>

#include <gdal.h>

enum { N = 10000, W = 384, H = 384 };
/* the mask's square on colorado (terrain-local metres) */
static const double ORIGIN[2] = { 20000.0, 40000.0 };
/* roads in mask texels (= metres): [ROAD_Z, +4) along x, [ROAD_X, +8)
 * along z, a ring of radius [2500, 2504) about the centre */
enum { ROAD_Z = 5000, ROAD_X = 3000 };
static const double FOVY = M_PI / 3.0;

static bool write_text(const char *dir, const char *name, const char *text)
{
    char *path = kit_join(dir, name);
    FILE *f = fopen(path, "w");
    bool ok = f && fputs(text, f) >= 0;
    if (f) ok &= fclose(f) == 0;
    free(path);
    return ok;
}

static bool write_mask(const char *dir)
{
    uint8_t *m = calloc((size_t)N * N, 1);
    if (!m) return false;
    for (int z = 0; z < N; z++) {
        uint8_t *row = m + (size_t)z * N;
        if (z >= ROAD_Z && z < ROAD_Z + 4)
            memset(row, 255, N);
        memset(row + ROAD_X, 255, 8);
        double dz = z + 0.5 - N / 2.0;
        if (fabs(dz) < 2504.0)
            for (int x = 0; x < N; x++) {
                double dx = x + 0.5 - N / 2.0, r = sqrt(dx * dx + dz * dz);
                if (r >= 2500.0 && r < 2504.0) row[x] = 255;
            }
    }
    char *tif = kit_join(dir, "road.tif");
    char opt_c[] = "COMPRESS=DEFLATE", opt_t[] = "TILED=YES";
    char *opts[] = { opt_c, opt_t, NULL };
    GDALAllRegister();
    GDALDatasetH ds = GDALCreate(GDALGetDriverByName("GTiff"), tif, N, N, 1, GDT_Byte, opts);
    bool ok = ds != NULL;
    if (ok) {
        GDALRasterBandH b = GDALGetRasterBand(ds, 1);
        ok = GDALRasterIO(b, GF_Write, 0, 0, N, N, m, N, N, GDT_Byte, 0, 0) == CE_None;
        GDALClose(ds);
    }
    free(tif);
    free(m);
    return ok;
}

static bool write_inputs(const char *dir)
{
    char cmd[1200];
    snprintf(cmd, sizeof cmd, "cp examples/colorado/trinidad.png '%s/'", dir);
    char scene[512];
    snprintf(scene, sizeof scene,
             "import \"nodes/compositors.sg\"\nimport \"graphs/grass.sg\"\n"
             "import \"paint.sg\"\n"
             "scene placed {\n"
             "    heightfield = \"trinidad.png\"\n"
             "    size = 176473.5 111212.6\n"
             "    max_height = 2962.242\n"
             "    height_offset = 1358.652\n"
             "    materials = [grass, paint]\n"
             "    painted road = \"road.tif\" { origin = %g %g, size = %d %d }\n"
             "    cell = 32\n}\n", ORIGIN[0], ORIGIN[1], N, N);
    return system(cmd) == 0 && write_mask(dir) &&
           write_text(dir, "paint.sg",
                      "# the road mask as is, bright red\n"
                      "material paint {\n"
                      "    node p : painted { mask = \"road\" }\n"
                      "    out mask      = p.out\n"
                      "    out albedo    = vec3(0.8, 0.1, 0.1)\n"
                      "    out roughness = 0.5\n"
                      "    out height    = 0.5\n}\n") &&
           write_text(dir, "scene.sg", scene);
}

static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec + 1e-9 * t.tv_nsec;
}

static bool build(const char *dir, char **pack)
{
    char *sg = kit_join(dir, "scene.sg");
    *pack = kit_join(dir, "pack");
    double t0 = now();
    bool ok = kit_build_pack_ok(sg, *pack);
    double secs = now() - t0;
    free(sg);
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    double mb = ru.ru_maxrss / 1024.0;   /* the whole process so far */
    printf("build: %.2f s, peak resident memory %.0f MB (mask of %d x %d texels)\n",
           secs, mb, N, N);
    CHECK(mb < 1024.0, "peak memory %.0f MB", mb);
    return ok;
}

/* --painted dense cannot store a placed mask: a located error, no pack. */
static void check_dense_refused(const char *dir)
{
    char *sg = kit_join(dir, "scene.sg"), *out = kit_join(dir, "dense_pack");
    sg_diags d;
    CHECK(!kit_build_pack(sg, out, SPLAT_PAINTED_DENSE, &d), "--painted dense built a placed mask");
    char *text = NULL;
    size_t n = 0;
    FILE *f = open_memstream(&text, &n);
    sg_diags_print(&d, f);
    fclose(f);
    CHECK(strstr(text, "scene.sg:10:") && strstr(text, "error: painted mask 'road' is placed"),
          "diagnostic: %s", text);
    FILE *gone = fopen(out, "r");
    CHECK(!gone, "%s written", out);
    if (gone) fclose(gone);
    free(text);
    sg_diags_free(&d);
    free(sg);
    free(out);
}

static void check_store(const rt_pack *p)
{
    CHECK(p->sparse != NULL, "the pack stores the masks dense");
    if (!p->sparse) return;
    sparse_stats st;
    sparse_get_stats(p->sparse, &st);
    CHECK(st.dense_bytes == (size_t)N * N, "dense %zu B", st.dense_bytes);
    CHECK(st.fraction < 0.05, "sparse store %.2f %% of dense", 100.0 * st.fraction);
    printf("store: %zu B sparse = %.2f %% of %zu B dense (%d unique slots, %d stored "
           "cells)\n", st.total_bytes, 100.0 * st.fraction, st.dense_bytes, st.nslots,
           st.stored_cells);
}

/* The terrain's height at (x, z) metres, bilinear between texel centres. */
static double ground(const rt_pack *p, double x, double z)
{
    double tx = x / p->size[0] * p->hf_width - 0.5, tz = z / p->size[1] * p->hf_height - 0.5;
    int ix = (int)floor(tx), iz = (int)floor(tz);
    double fx = tx - ix, fz = tz - iz, h = 0.0;
    for (int j = 0; j < 2; j++)
        for (int i = 0; i < 2; i++) {
            double w = (i ? fx : 1 - fx) * (j ? fz : 1 - fz);
            h += w * p->heights[(size_t)(iz + j) * p->hf_width + (ix + i)];
        }
    return p->height_offset + h / 65535.0 * p->max_height;
}

/* A frame of the paint material's `view` (forward, or the screen path),
 * also written to DIR/NAME. */
static float *render(const rt_pack *pack, rt_device *dev, rt_reference ref, rt_shading shading,
                     splat_view view, const rt_camera *cam, const char *dir, const char *name)
{
    rt_render_desc rd = { .width = W, .height = H, .reference = ref, .shading = shading };
    float *rgba = kit_render(dev, pack, &rd, view, 1, cam);
    if (rgba) kit_write_picture(dir, name, rgba, W, H, view);
    return rgba;
}

/* Straight down from 60 m over mask texel (mx, mz): the road crossing the
 * centre row or column is `metres` wide in the mask view. */
static void check_width(const rt_pack *p, rt_device *dev, double mx, double mz,
                        double metres, const char *dir, const char *name)
{
    double x = ORIGIN[0] + mx, z = ORIGIN[1] + mz, y = ground(p, x, z);
    rt_camera cam = { .position = { x, y + 60.0, z + 1e-3 }, .look = { x, y, z },
                      .fovy = FOVY };
    float *m = render(p, dev, RT_REF_NONE, RT_SHADING_FORWARD, SPLAT_VIEW_MASK, &cam, dir, name);
    if (!m) return;
    int row = 0, col = 0;
    for (int i = 0; i < W; i++) {
        row += m[4 * ((size_t)(H / 2) * W + i)] > 0.5f;
        col += m[4 * ((size_t)i * W + W / 2)] > 0.5f;
    }
    int across = row < col ? row : col, along = row < col ? col : row;
    double per_px = 2.0 * 60.0 * tan(FOVY / 2.0) / H;   /* metres per pixel */
    double want = metres / per_px;
    printf("%s: road %.0f m wide: %d px across (%.2f m), %d px along (of %d)\n", name,
           metres, across, across * per_px, along, W);
    CHECK(fabs(across - want) <= 0.1 * want + 2.0, "%s: %d px, want %.1f", name, across, want);
    CHECK(along == W, "%s: the road does not cross the view (%d px)", name, along);
    free(m);
}

/* Composites against the über-shader, every pixel within 1/255. */
static void check_sound(const rt_pack *p, rt_device *dev, const rt_camera *cam,
                        const char *dir, const char *name)
{
    char a[64], b[64];
    snprintf(a, sizeof a, "%s_final.png", name);
    snprintf(b, sizeof b, "%s_uber.png", name);
    float *c = render(p, dev, RT_REF_NONE, RT_SHADING_FORWARD, SPLAT_VIEW_FINAL, cam, dir, a);
    float *u = render(p, dev, RT_REF_UBER, RT_SHADING_FORWARD, SPLAT_VIEW_FINAL, cam, dir, b);
    if (c && u) {
        double worst = 0.0;
        int red = 0;
        for (size_t i = 0; i < (size_t)W * H; i++) {
            for (int k = 0; k < 3; k++)
                worst = fmax(worst, fabs(c[4 * i + k] - u[4 * i + k]));
            red += c[4 * i] > 2.0f * c[4 * i + 1] && c[4 * i] > 0.1f;
        }
        printf("%s: composites vs über max difference %.2e, %d road pixels\n", name, worst,
               red);
        CHECK(worst <= 1.0 / 255.0, "%s: max difference %g", name, worst);
        CHECK(red > 0, "%s: no road in the view", name);
    }
    free(c);
    free(u);
}

static void check_screen(const rt_pack *p, rt_device *dev, const rt_camera *cam,
                         const char *dir)
{
    float *f = render(p, dev, RT_REF_NONE, RT_SHADING_FORWARD, SPLAT_VIEW_FINAL, cam, dir,
                      "close_final.png");
    float *s = render(p, dev, RT_REF_NONE, RT_SHADING_SCREEN, SPLAT_VIEW_FINAL, cam, dir,
                      "screen_close.png");
    if (f && s) {
        size_t close = 0, n = (size_t)W * H;
        for (size_t i = 0; i < n; i++) {
            double d = 0.0;
            for (int k = 0; k < 3; k++)
                d = fmax(d, fabs(f[4 * i + k] - s[4 * i + k]));
            close += d <= 4.0 / 255.0;
        }
        printf("screen path: %.3f %% of pixels within 4/255 of forward\n", 100.0 * close / n);
        CHECK(close >= 0.995 * n, "screen path: %zu of %zu pixels close", close, n);
    }
    free(f);
    free(s);
}

int main(int argc, char **argv)
{
    if (argc == 3 && strcmp(argv[1], "--inputs") == 0)
        return write_inputs(argv[2]) ? 0 : 1;
    if (argc != 2) {
        fprintf(stderr, "usage: test_placed [--inputs] OUTDIR (run from the repository root)\n");
        return 2;
    }
    const char *dir = argv[1];
    char *packdir = NULL;
    if (!write_inputs(dir) || !build(dir, &packdir)) {
        fprintf(stderr, "FAIL: the test scene does not build\n");
        free(packdir);
        return 1;
    }
    rt_pack *pack = kit_pack(packdir);
    rt_device *dev = pack ? kit_device() : NULL;
    if (!dev)
        return kit_finish("placed");
    check_dense_refused(dir);
    check_store(pack);
    check_width(pack, dev, 1500.0, ROAD_Z + 2.0, 4.0, dir, "road4.png");
    check_width(pack, dev, ROAD_X + 4.0, 8500.0, 8.0, dir, "road8.png");
    /* close over the crossing, the whole square, a grazing view along x */
    double cx = ORIGIN[0] + ROAD_X + 4, cz = ORIGIN[1] + ROAD_Z + 2;
    double gy = ground(pack, cx, cz);
    rt_camera close = { .position = { cx - 30, gy + 40, cz - 30 }, .look = { cx, gy, cz },
                        .fovy = FOVY };
    double mx = ORIGIN[0] + N / 2.0, mz = ORIGIN[1] + N / 2.0, my = ground(pack, mx, mz);
    rt_camera over = { .position = { mx, my + 9000, mz + 1 }, .look = { mx, my, mz },
                       .fovy = FOVY };
    rt_camera graze = { .position = { ORIGIN[0] - 200, my + 150, mz + 1200 },
                        .look = { mx, my, mz + 1200 }, .fovy = FOVY };
    check_sound(pack, dev, &close, dir, "close");
    check_sound(pack, dev, &over, dir, "over");
    check_sound(pack, dev, &graze, dir, "graze");
    check_screen(pack, dev, &close, dir);
    kit_device_close(dev);
    rt_pack_close(pack);
    free(packdir);
    GDALDestroyDriverManager();
    return kit_finish("placed");
}
