/* gen_geotiff.c — write a GeoTIFF twin of a greyscale PNG through GDAL's C
 * API (for the colorado twin test, tests/world/suite.cmake):
 *
 *   gen_geotiff IN.png OUT.tif SIZE_X SIZE_Z [MAX_HEIGHT OFFSET]
 *
 * A 16-bit PNG becomes a UInt16 band with scale MAX_HEIGHT/65535 and offset
 * OFFSET (so splatc reads back exactly the PNG's texels and heights), an
 * 8-bit one a Byte band (a painted mask).  Georeferenced north-up in UTM
 * zone 13N (EPSG:26913, metres), texels SIZE_X/W by SIZE_Z/H metres, the
 * corner at 400000 E 4200000 N.  The texel spacing and the scale are nudged
 * by ulps until splatc's products (spacing * count, 65535 * scale) give back
 * the exact decimal sizes, so both scenes build the same pack. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cpl_conv.h>
#include <gdal.h>
#include <ogr_srs_api.h>
#include <stb_image.h>

/* x such that x * n == want (in double), found from want / n by ulps. */
static double exact_factor(double want, double n)
{
    double x = want / n;
    for (int i = 0; i < 64 && x * n != want; i++)
        x = nextafter(x, x * n < want ? INFINITY : -INFINITY);
    if (x * n != want) {
        fprintf(stderr, "gen_geotiff: no double x with x * %g == %.17g\n", n, want);
        exit(1);
    }
    return x;
}

int main(int argc, char **argv)
{
    if (argc != 5 && argc != 7) {
        fprintf(stderr, "usage: gen_geotiff IN.png OUT.tif SIZE_X SIZE_Z "
                "[MAX_HEIGHT OFFSET]\n");
        return 2;
    }
    int w, h, comp;
    bool is16 = stbi_is_16_bit(argv[1]);
    void *px = is16 ? (void *)stbi_load_16(argv[1], &w, &h, &comp, 1)
                    : (void *)stbi_load(argv[1], &w, &h, &comp, 1);
    if (!px) {
        fprintf(stderr, "gen_geotiff: cannot read '%s'\n", argv[1]);
        return 1;
    }
    double sx = exact_factor(atof(argv[3]), w), sz = exact_factor(atof(argv[4]), h);
    GDALAllRegister();
    GDALDriverH drv = GDALGetDriverByName("GTiff");
    char *opts[] = { "COMPRESS=DEFLATE", NULL };
    GDALDatasetH ds = GDALCreate(drv, argv[2], w, h, 1, is16 ? GDT_UInt16 : GDT_Byte, opts);
    if (!ds) {
        fprintf(stderr, "gen_geotiff: cannot create '%s'\n", argv[2]);
        return 1;
    }
    double gt[6] = { 400000.0, sx, 0.0, 4200000.0, 0.0, -sz };
    GDALSetGeoTransform(ds, gt);
    OGRSpatialReferenceH srs = OSRNewSpatialReference(NULL);
    OSRImportFromEPSG(srs, 26913);
    GDALSetSpatialRef(ds, srs);
    OSRDestroySpatialReference(srs);
    GDALRasterBandH band = GDALGetRasterBand(ds, 1);
    if (is16 && argc == 7) {
        GDALSetRasterScale(band, exact_factor(atof(argv[5]), 65535.0));
        GDALSetRasterOffset(band, atof(argv[6]));
    }
    CPLErr e = GDALRasterIO(band, GF_Write, 0, 0, w, h, px, w, h,
                            is16 ? GDT_UInt16 : GDT_Byte, 0, 0);
    GDALClose(ds);
    stbi_image_free(px);
    if (e != CE_None) {
        fprintf(stderr, "gen_geotiff: cannot write '%s'\n", argv[2]);
        return 1;
    }
    return 0;
}
