/* test_gdal.c — heightfields and painted masks through GDAL
 * (compiler/raster.c) and terrain holes on the CPU (terrain.c, scene.c).
 * The GeoTIFFs are written here with GDAL's C API into a fresh temporary
 * folder, with a scene file next to them; run from the repository root
 * (the scenes import graphs/ and nodes/ from there). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <gdal.h>
#include <ogr_srs_api.h>

#include "scene.h"

static char tmpdir[] = "/tmp/splat_gdal_XXXXXX";

static char *path_in(const char *name)
{
    static char buf[8][512];
    static int k;
    char *p = buf[k++ & 7];
    snprintf(p, sizeof buf[0], "%s/%s", tmpdir, name);
    return p;
}

/* A one-band GeoTIFF; `epsg` 0: no CRS; gt NULL: no geotransform. */
static void write_tif(const char *name, int w, int h, GDALDataType type,
                      const double *values, int epsg, const double *gt,
                      const double *nodata)
{
    GDALDatasetH ds = GDALCreate(GDALGetDriverByName("GTiff"), path_in(name),
                                 w, h, 1, type, NULL);
    assert_non_null(ds);
    if (gt) GDALSetGeoTransform(ds, (double *)gt);
    if (epsg) {
        OGRSpatialReferenceH srs = OSRNewSpatialReference(NULL);
        assert_int_equal(OSRImportFromEPSG(srs, epsg), OGRERR_NONE);
        GDALSetSpatialRef(ds, srs);
        OSRDestroySpatialReference(srs);
    }
    GDALRasterBandH b = GDALGetRasterBand(ds, 1);
    if (nodata) GDALSetRasterNoDataValue(b, *nodata);
    assert_int_equal(GDALRasterIO(b, GF_Write, 0, 0, w, h, (void *)values, w, h,
                                  GDT_Float64, 0, 0), CE_None);
    GDALClose(ds);
}

static void write_text(const char *name, const char *text)
{
    FILE *f = fopen(path_in(name), "w");
    assert_non_null(f);
    fputs(text, f);
    fclose(f);
}

/* A scene over `hf` with two materials; `extra` lines go inside. */
static void write_scene(const char *name, const char *hf, const char *extra)
{
    char text[2048];
    snprintf(text, sizeof text,
             "import \"nodes/compositors.sg\"\nimport \"graphs/grass.sg\"\nimport \"graphs/rock.sg\"\n"
             "scene t {\n    heightfield = \"%s\"\n    materials = [grass, rock]\n"
             "    cell = 8\n%s}\n", hf, extra);
    write_text(name, text);
}

static const char *const search[] = { ".", NULL };

static bool load(splat_scene *s, const char *scene, sg_diags *d)
{
    sg_diags_init(d);
    bool ok = splat_scene_load(s, path_in(scene), search, d);
    if (!ok) sg_diags_print(d, stderr);
    return ok;
}

static bool has_diag(const sg_diags *d, sg_severity sev, const char *text)
{
    for (int i = 0; i < d->n; i++)
        if (d->items[i].severity == sev && strstr(d->items[i].msg, text))
            return true;
    return false;
}

/* Float32 heights 1000 .. 1630 m in UTM 13N, 30 m texels, one nodata texel
 * and a NaN one: size from the geotransform, origin, heights mapped onto
 * 16 bits, the holes recorded and filled from their neighbours. */
static void test_projected_float(void **state)
{
    (void)state;
    enum { W = 64, H = 32 };
    static double v[W * H];
    for (int z = 0; z < H; z++)
        for (int x = 0; x < W; x++)
            v[z * W + x] = 1000.0 + 10.0 * x - 3.0 * z + (x == 63 ? 0 : 0);
    v[5 * W + 7] = -9999.0;
    v[6 * W + 7] = NAN;
    double nd = -9999.0;
    double gt[6] = { 500000.0, 30.0, 0.0, 4300000.0, 0.0, -30.0 };
    write_tif("proj.tif", W, H, GDT_Float32, v, 26913, gt, &nd);
    write_scene("proj.sg", "proj.tif", "");
    splat_scene s;
    sg_diags d;
    assert_true(load(&s, "proj.sg", &d));
    const splat_terrain *t = &s.terrain;
    assert_int_equal(t->width, W);
    assert_int_equal(t->height, H);
    assert_true(t->size[0] == 30.0 * W && t->size[1] == 30.0 * H);
    assert_true(t->origin[0] == 500000.0 && t->origin[1] == 4300000.0);
    double lo = 1000.0 - 3.0 * (H - 1), hi = 1000.0 + 10.0 * (W - 1);
    assert_true(fabs(t->height_offset - lo) < 1e-9);
    assert_true(fabs(t->max_height - (hi - lo)) < 1e-9);
    assert_true(has_diag(&d, SG_NOTE, "stored in 16 bits"));
    assert_true(has_diag(&d, SG_NOTE, "2 nodata texels"));
    /* every valid texel within half a 16-bit step of the stored height */
    double step = (hi - lo) / 65535.0;
    for (int z = 0; z < H; z++)
        for (int x = 0; x < W; x++) {
            int hole = splat_terrain_hole(t, x, z);
            assert_int_equal(hole, (x == 7 && (z == 5 || z == 6)));
            if (hole) continue;
            double got = splat_terrain_texel(t, x, z) * t->max_height + t->height_offset;
            assert_true(fabs(got - v[z * W + x]) <= 0.5 * step + 1e-9);
        }
    /* holes filled from their neighbours: within their range, not -9999 */
    for (int z = 5; z <= 6; z++) {
        double got = splat_terrain_texel(t, 7, z) * t->max_height + t->height_offset;
        assert_true(got > 1000.0 + 10.0 * 6 - 3.0 * 7 - 1 && got < 1000.0 + 10.0 * 8 + 1);
    }
    splat_scene_free(&s);
    sg_diags_free(&d);
}

/* Int16 heights in WGS 84 degrees around 45 N: metres at the centre
 * latitude (reported), heights exact (the integer range fits 16 bits). */
static void test_geographic_int(void **state)
{
    (void)state;
    enum { W = 40, H = 20 };
    static double v[W * H];
    for (int i = 0; i < W * H; i++)
        v[i] = -50 + (i * 37) % 400;
    double deg = 1.0 / 1200.0;            /* 3 arc seconds */
    double gt[6] = { -105.0, deg, 0.0, 45.0 + H * deg / 2, 0.0, -deg };
    write_tif("geo.tif", W, H, GDT_Int16, v, 4326, gt, NULL);
    write_scene("geo.sg", "geo.tif", "");
    splat_scene s;
    sg_diags d;
    assert_true(load(&s, "geo.sg", &d));
    const splat_terrain *t = &s.terrain;
    /* WGS 84 at 45 deg: 1 deg = 78846.8 m east, 111131.8 m north */
    assert_true(fabs(t->size[0] / (W * deg) - 78846.81) < 0.05);
    assert_true(fabs(t->size[1] / (H * deg) - 111131.75) < 0.05);
    assert_true(has_diag(&d, SG_NOTE, "geographic coordinates"));
    assert_true(t->height_offset == -50.0 && t->max_height == 65535.0);
    assert_false(has_diag(&d, SG_NOTE, "stored in 16 bits"));
    for (int z = 0; z < H; z++)
        for (int x = 0; x < W; x++) {
            double got = splat_terrain_texel(t, x, z) * t->max_height + t->height_offset;
            assert_true(got == v[z * W + x]);
        }
    assert_null(t->holes);
    splat_scene_free(&s);
    sg_diags_free(&d);
}

/* UInt16 with scale and offset: texels kept exactly; a scene size
 * overrides a file without geotransform; a GeoTIFF painted mask and a
 * holes mask. */
static void test_uint16_masks_holes(void **state)
{
    (void)state;
    enum { W = 16, H = 16 };
    static double v[W * H], m[W * H], hm[W * H];
    for (int i = 0; i < W * H; i++) {
        v[i] = (i * 4099) % 65536;
        m[i] = (i * 7) % 256;
        hm[i] = (i % W >= 4 && i % W < 8 && i / W >= 4 && i / W < 10) ? 255 : 0;
    }
    v[0] = 65535;  /* a spike under the hole's neighbours does not matter */
    write_tif("u16.tif", W, H, GDT_UInt16, v, 0, NULL, NULL);
    write_tif("mask.tif", W, H, GDT_Byte, m, 0, NULL, NULL);
    write_tif("holes.tif", W, H, GDT_Byte, hm, 0, NULL, NULL);
    write_scene("u16.sg", "u16.tif", "    size = 160 320\n"
                "    painted fields = \"mask.tif\"\n"
                "    painted holes = \"holes.tif\"\n");
    splat_scene s;
    sg_diags d;
    assert_true(load(&s, "u16.sg", &d));
    const splat_terrain *t = &s.terrain;
    assert_true(t->size[0] == 160 && t->size[1] == 320);
    assert_true(t->max_height == 65535.0 && t->height_offset == 0.0);
    for (int i = 0; i < W * H; i++) {
        if (hm[i] == 0)
            assert_int_equal(t->texels[i], (int)v[i]);
        assert_int_equal(t->holes[i], hm[i] != 0);
        assert_int_equal(s.painted[0][i], (int)m[i]);
    }
    assert_int_equal(s.desc->npainted, 1);   /* holes is not a layer */
    splat_scene_free(&s);
    sg_diags_free(&d);
}

static void expect_error(const char *scene, sg_error_id id, const char *text)
{
    splat_scene s;
    sg_diags d;
    sg_diags_init(&d);
    assert_false(splat_scene_load(&s, path_in(scene), search, &d));
    bool found = false;
    for (int i = 0; i < d.n; i++)
        if (d.items[i].severity == SG_ERROR && d.items[i].id == id &&
            strstr(d.items[i].msg, text) && d.items[i].loc.line > 0)
            found = true;
    if (!found) {
        sg_diags_print(&d, stderr);
        fail_msg("%s: no error containing '%s'", scene, text);
    }
    assert_null(s.terrain.texels);
    sg_diags_free(&d);
}

static void test_errors(void **state)
{
    (void)state;
    double v[4] = { 1, 2, 3, 4 }, nd = 5.0, all[4] = { 5, 5, 5, 5 }, m[9] = { 0 };
    double rot[6] = { 0, 1, 0.1, 0, 0, -1 }, gt[6] = { 0, 1, 0, 0, 0, -1 };
    write_tif("rot.tif", 2, 2, GDT_Float32, v, 26913, rot, NULL);
    write_tif("nogt.tif", 2, 2, GDT_Float32, v, 0, NULL, NULL);
    write_tif("allnd.tif", 2, 2, GDT_Float32, all, 26913, gt, &nd);
    write_tif("m3.tif", 3, 3, GDT_Byte, m, 0, NULL, NULL);
    write_tif("m16.tif", 2, 2, GDT_UInt16, v, 0, NULL, NULL);
    /* values at their ends: Float64 heights at +-1.7e308 (a span no float
     * holds) and 1e9 m texels; both would leave the manifest non-finite or
     * out of the runtime's range (abi.h SPLAT_MAX_EXTENT) */
    double ends[4] = { -1.7e308, 1.7e308, 0, 1 }, wide[6] = { 0, 1e9, 0, 0, 0, -1e9 };
    write_tif("ends.tif", 2, 2, GDT_Float64, ends, 0, gt, NULL);
    write_tif("wide.tif", 2, 2, GDT_Float32, v, 0, wide, NULL);
    write_text("junk.tif", "this is not a raster\n");
    /* a VRT (which could name any file) is not opened */
    write_text("x.vrt", "<VRTDataset rasterXSize=\"2\" rasterYSize=\"2\">"
               "<VRTRasterBand dataType=\"Byte\" band=\"1\"><SimpleSource>"
               "<SourceFilename>nogt.tif</SourceFilename></SimpleSource>"
               "</VRTRasterBand></VRTDataset>\n");
    static const struct {
        const char *hf, *extra;
        sg_error_id id;
        const char *text;
    } cases[] = {
        { "rot.tif", "", SG_E_RASTER, "rotated" },
        { "ends.tif", "", SG_E_OVER_LIMIT, "the pack limit is finite heights" },
        { "wide.tif", "", SG_E_OVER_LIMIT, "gives a world size of 2e+09 x 2e+09 m" },
        { "nogt.tif", "", SG_E_RASTER, "no geotransform" },
        { "allnd.tif", "", SG_E_RASTER, "no valid height" },
        { "junk.tif", "", SG_E_IO, "not a raster GDAL reads" },
        { "missing.tif", "", SG_E_IO, "No such file" },
        { "nogt.tif", "    size = 2 2\n    max_height = 10\n", SG_E_SETTING,
          "max_height comes from the heights" },
        { "x.vrt", "    size = 2 2\n", SG_E_IO, "not a raster GDAL reads" },
        { "nogt.tif", "    size = 2 2\n    painted fields = \"m3.tif\"\n", SG_E_RASTER,
          "is 3 x 3 texels; the heightfield is 2 x 2" },
        { "nogt.tif", "    size = 2 2\n    painted holes = \"m16.tif\"\n", SG_E_RASTER,
          "holds UInt16 values" },
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        char name[32];
        snprintf(name, sizeof name, "err%zu.sg", i);
        write_scene(name, cases[i].hf, cases[i].extra);
        expect_error(name, cases[i].id, cases[i].text);
    }
}

/* Filling: every hole takes a height between its known neighbours'. */
static void test_fill(void **state)
{
    (void)state;
    enum { W = 9, H = 7 };
    uint16_t tex[W * H];
    uint8_t holes[W * H];
    for (int i = 0; i < W * H; i++) {
        tex[i] = (uint16_t)(1000 + 100 * (i % W));
        holes[i] = (i % W >= 2 && i % W <= 6);
    }
    for (int i = 0; i < W * H; i++)
        if (holes[i]) tex[i] = 60000;          /* garbage under the hole */
    splat_terrain t = { .width = W, .height = H, .texels = tex, .holes = holes };
    assert_true(splat_terrain_fill_holes(&t));
    for (int z = 0; z < H; z++) {
        assert_int_equal(tex[z * W + 2], 1100);   /* from x = 1 */
        assert_int_equal(tex[z * W + 6], 1700);   /* from x = 7 */
        assert_int_equal(tex[z * W + 4], (1100 + 1700 + 1) / 2);
        for (int x = 2; x <= 6; x++)
            assert_true(tex[z * W + x] >= 1100 && tex[z * W + x] <= 1700);
    }
}

int main(void)
{
    if (!mkdtemp(tmpdir)) return 1;
    GDALAllRegister();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_projected_float),
        cmocka_unit_test(test_geographic_int),
        cmocka_unit_test(test_uint16_masks_holes),
        cmocka_unit_test(test_errors),
        cmocka_unit_test(test_fill),
    };
    int rc = cmocka_run_group_tests(tests, NULL, NULL);
    char cmd[600];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", tmpdir);
    if (system(cmd) != 0) rc = 1;
    GDALDestroyDriverManager();
    return rc;
}
