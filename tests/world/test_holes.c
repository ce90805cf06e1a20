/* test_holes.c — terrain holes end to end on a Vulkan device (lavapipe
 * here; SPLAT_VALIDATE=1, and any validation message fails).
 *
 *   test_holes OUTDIR
 *
 * Writes a 257 x 257 Float32 GeoTIFF heightfield (4 m texels, gentle
 * relief 20..60 m) with a block of nodata texels (hole A) and a 900 m
 * spike of valid heights under a painted holes mask (hole B), a scene
 * over them, builds the pack with splatc's library and checks:
 *   - the analysis: cells whose texels and one-texel ring are all hole have
 *     no combination (combos.bin id 0xFFFF), other cells keep theirs;
 *   - the quadtree bounds ignore hole texels: no node's bound reaches the
 *     spike (its texels were filled from their neighbours);
 *   - from a camera straight above, in the lit, combos and über views,
 *     every pixel whose ground point lies 3 texels or more inside a hole is
 *     the background colour, every one 3 texels or more outside both holes
 *     is terrain;
 *   - no validation messages.
 * Pictures of the views go to OUTDIR. */
#include "rt_internal.h"
#include "kit.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <gdal.h>
#include <ogr_srs_api.h>
#include <stb_image_write.h>

enum { N = 257, W = 384, H = 384, CELL = 8 };
static const double TEXEL = 4.0, CAM[3] = { 514, 1400, 514 }, FOVY = M_PI / 3.0;
/* hole rectangles in texels [x0, x1) x [z0, z1) */
static const int HOLE_A[4] = { 40, 40, 90, 90 };      /* GDAL nodata     */
static const int HOLE_B[4] = { 150, 150, 210, 210 };  /* painted holes   */
static const float CLEAR[4] = { 1.0f, 0.0f, 1.0f, 1.0f };

static bool in_rect(const int r[4], double tx, double tz, double grow)
{
    return tx >= r[0] - grow && tx < r[2] + grow && tz >= r[1] - grow && tz < r[3] + grow;
}

static bool write_inputs(const char *dir)
{
    static float hf[N * N];
    static uint8_t mask[N * N];
    for (int z = 0; z < N; z++)
        for (int x = 0; x < N; x++) {
            hf[z * N + x] = (float)(20.0 + 0.08 * x + 0.04 * z + 8.0 * sin(x * 0.05) * cos(z * 0.07));
            mask[z * N + x] = in_rect(HOLE_B, x, z, 0) ? 255 : 0;
            if (in_rect(HOLE_A, x, z, 0)) hf[z * N + x] = -32768.0f;
            if (x >= 178 && x < 182 && z >= 178 && z < 182) hf[z * N + x] = 900.0f;
        }
    char *tif = kit_join(dir, "hf.tif"), *png = kit_join(dir, "holes.png"), *sg = kit_join(dir, "scene.sg");
    GDALAllRegister();
    GDALDatasetH ds = GDALCreate(GDALGetDriverByName("GTiff"), tif, N, N, 1, GDT_Float32, NULL);
    bool ok = ds != NULL;
    if (ok) {
        double gt[6] = { 300000.0, TEXEL, 0.0, 4100000.0, 0.0, -TEXEL };
        GDALSetGeoTransform(ds, gt);
        OGRSpatialReferenceH srs = OSRNewSpatialReference(NULL);
        OSRImportFromEPSG(srs, 26913);
        GDALSetSpatialRef(ds, srs);
        OSRDestroySpatialReference(srs);
        GDALRasterBandH b = GDALGetRasterBand(ds, 1);
        GDALSetRasterNoDataValue(b, -32768.0);
        ok = GDALRasterIO(b, GF_Write, 0, 0, N, N, hf, N, N, GDT_Float32, 0, 0) == CE_None;
        GDALClose(ds);
    }
    ok = ok && stbi_write_png(png, N, N, 1, mask, N);
    FILE *f = fopen(sg, "w");
    ok = ok && f;
    if (f) {
        fprintf(f, "import \"nodes/compositors.sg\"\nimport \"graphs/grass.sg\"\n"
                "import \"graphs/rock.sg\"\n"
                "scene holes {\n    heightfield = \"hf.tif\"\n"
                "    painted holes = \"holes.png\"\n"
                "    materials = [grass, rock]\n    cell = %d\n}\n", CELL);
        fclose(f);
    }
    free(tif); free(png); free(sg);
    return ok;
}

static bool build(const char *dir, char **pack)
{
    char *sg = kit_join(dir, "scene.sg");
    *pack = kit_join(dir, "pack");
    bool ok = kit_build_pack_ok(sg, *pack);
    free(sg);
    return ok;
}

/* Cells all hole (texels and ring) have 0xFFFF, the others a real id. */
static void check_analysis(const rt_pack *p)
{
    const rt_pack_level *l0 = &p->levels[0];
    int hole_cells = 0;
    for (int cz = 0; cz < l0->height; cz++)
        for (int cx = 0; cx < l0->width; cx++) {
            int x0 = cx * CELL - 1, z0 = cz * CELL - 1;
            int x1 = cx * CELL + CELL, z1 = cz * CELL + CELL;   /* ring, inclusive */
            bool all = false;
            for (int h = 0; h < 2 && !all; h++) {
                const int *r = h ? HOLE_B : HOLE_A;
                all = x0 >= r[0] && z0 >= r[1] && x1 < r[2] && z1 < r[3];
            }
            uint16_t id = l0->ids[(size_t)cz * l0->width + cx];
            CHECK((id == 0xFFFF) == all, "cell %d,%d: id %u, all hole %d", cx, cz, id, all);
            hole_cells += all;
        }
    CHECK(hole_cells >= 40, "only %d all-hole cells", hole_cells);
    printf("analysis: %d of %d cells all hole, no combination\n", hole_cells,
           l0->width * l0->height);
}

static void check_bounds(const rt_pack *p)
{
    rt_bounds b;
    CHECK(rt_bounds_build(&b, p->heights, p->hf_width, p->hf_height, p->cell_texels,
                          p->max_height, p->height_offset), "rt_bounds_build");
    float top = b.hmax[b.nlevels - 1][0];
    CHECK(top < 100.0f, "the root's bound %g m reaches the spike under hole B", top);
    printf("bounds: root max %.2f m (the spike under hole B: 900 m)\n", top);
    rt_bounds_free(&b);
}

/* Where the ray of pixel (px, py) meets the plane y (terrain metres). */
static void ground_at(int px, int py, double y, double *x, double *z)
{
    double t = 1.0 / tan(FOVY / 2.0), aspect = (double)W / H;
    double nx = (px + 0.5) / W * 2.0 - 1.0, ny = (py + 0.5) / H * 2.0 - 1.0;
    *x = CAM[0] + nx * aspect / t * (CAM[1] - y);
    *z = CAM[2] + ny / t * (CAM[1] - y);
}

static void check_view(const rt_pack *pack, rt_device *dev, rt_reference ref,
                       splat_view view, const char *dir, const char *name)
{
    rt_render_desc rd = { .width = W, .height = H, .reference = ref,
                          .clear = { CLEAR[0], CLEAR[1], CLEAR[2], CLEAR[3] } };
    rt_camera cam = { .position = { CAM[0], CAM[1], CAM[2] },
                      .look = { CAM[0], 0, CAM[2] }, .fovy = FOVY };
    float *rgba = kit_render(dev, pack, &rd, view, 0, &cam);
    bool ok = rgba != NULL;
    int hole = 0, ground = 0;
    for (int py = 0; ok && py < H; py++)
        for (int px = 0; px < W; px++) {
            /* the ground point at the lowest and highest valid height */
            double xa, za, xb, zb;
            ground_at(px, py, 0.0, &xa, &za);
            ground_at(px, py, 80.0, &xb, &zb);
            xa /= TEXEL; za /= TEXEL; xb /= TEXEL; zb /= TEXEL;
            const float *c = rgba + 4 * ((size_t)py * W + px);
            bool bg = fabsf(c[0] - CLEAR[0]) < 1e-6f && fabsf(c[1] - CLEAR[1]) < 1e-6f &&
                      fabsf(c[2] - CLEAR[2]) < 1e-6f;
            bool in = false, near = false;
            for (int h = 0; h < 2; h++) {
                const int *rc = h ? HOLE_B : HOLE_A;
                in |= in_rect(rc, xa, za, -3) && in_rect(rc, xb, zb, -3);
                near |= in_rect(rc, xa, za, 3) || in_rect(rc, xb, zb, 3);
            }
            bool on_terrain = xa > 3 && za > 3 && xa < N - 4 && za < N - 4 &&
                              xb > 3 && zb > 3 && xb < N - 4 && zb < N - 4;
            if (in) {
                hole++;
                if (!bg && kit_failures() < 20)
                    CHECK(bg, "%s: pixel %d,%d (texel %.1f,%.1f) inside a hole is "
                          "%g %g %g", name, px, py, xa, za, c[0], c[1], c[2]);
            } else if (!near && on_terrain) {
                ground++;
                if (bg && kit_failures() < 20)
                    CHECK(!bg, "%s: pixel %d,%d (texel %.1f,%.1f) outside the holes "
                          "is background", name, px, py, xa, za);
            }
        }
    CHECK(hole > 3000 && ground > 40000, "%s: %d hole and %d ground pixels checked",
          name, hole, ground);
    printf("%s: %d pixels inside holes are background, %d outside are terrain\n",
           name, hole, ground);
    if (ok)
        kit_write_picture(dir, name, rgba, W, H, view);
    free(rgba);
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: test_holes OUTDIR (run from the repository root)\n");
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
        return kit_finish("holes");
    check_analysis(pack);
    check_bounds(pack);
    check_view(pack, dev, RT_REF_NONE, SPLAT_VIEW_FINAL, dir, "final.png");
    check_view(pack, dev, RT_REF_NONE, SPLAT_VIEW_COMBOS, dir, "combos.png");
    check_view(pack, dev, RT_REF_UBER, SPLAT_VIEW_FINAL, dir, "uber.png");
    kit_device_close(dev);
    rt_pack_close(pack);
    free(packdir);
    GDALDestroyDriverManager();
    return kit_finish("holes");
}
