/* raster.c — heightfields and painted masks read through libgdal (any
 * raster GDAL reads: GeoTIFF, SRTM .hgt, ASCII grids, …).  PNG and raw R16
 * stay on the dependency-light path of terrain.c and scene.c.
 *
 * Heightfield (splat_raster_heightfield):
 *  - size: the geotransform's texel spacing times the texel count, in
 *    metres: a projected CRS's linear unit (metres, feet, …) is converted
 *    to metres; for a geographic CRS, degrees are converted at the centre
 *    latitude on the CRS's ellipsoid (meridian and prime-vertical radii)
 *    and the conversion is reported as a note; without a CRS the
 *    geotransform is taken as metres (also a note).  Rotated or sheared
 *    geotransforms are refused.  A scene `size` overrides the file's.
 *  - origin: the geotransform's corner (CRS units), kept in the terrain.
 *    Row 0 (north-up: the northern edge) is z = 0, as in a PNG.
 *  - heights as stored (band 1, times the band's scale, plus its offset):
 *    an unsigned 8- or 16-bit band with a positive scale is kept exactly
 *    (max_height = 65535 * scale or 255 * scale), and so is any other
 *    integer band whose values span at most 65535 (texel = value - lowest,
 *    SRTM's Int16 metres for one); the rest (floats, wider integer ranges)
 *    are mapped linearly onto 16 bits between the lowest and highest valid
 *    height (offset = lowest, max_height = the range), a note gives the
 *    step.
 *  - nodata texels (the band's nodata value, or NaN / inf) are holes
 *    (t->holes); splat_terrain_fill_holes (terrain.c) gives them heights.
 * Painted masks (splat_raster_mask): band 1; an 8-bit band as stored, a
 * floating-point band as 0..1 (times 255, rounded); nodata reads 0.
 *
 * Untrusted files: only the drivers below may open them (no VRT, whose
 * XML can name any file on the machine), the size is checked against the
 * limits (splat_raster_check_size) before anything is allocated, and the
 * data is read in strips of rows.  GDAL's own messages are kept off
 * stderr and folded into our diagnostics.
 */
#include "terrain.h"

#include "abi.h"
#include "util.h"

#include <errno.h>
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cpl_conv.h>
#include <cpl_error.h>
#include <gdal.h>
#include <ogr_srs_api.h>

/* Drivers allowed to open a scene's raster: self-contained formats or
 * ones whose side files sit next to the raster (.hdr, .aux.xml). */
static const char *const drivers[] = {
    "GTiff", "SRTMHGT", "AAIGrid", "GSAG", "GSBG", "GS7BG", "USGSDEM",
    "EHdr", "ENVI", "XYZ", "PNG", NULL
};

static pthread_once_t gdal_once = PTHREAD_ONCE_INIT;
static void gdal_init(void) { GDALAllRegister(); }

bool splat_raster_check_size(const char *what, const char *path, long long w,
                             long long h, sg_loc loc, sg_diags *d)
{
    if (w >= 1 && h >= 1 && w <= SPLAT_MAX_HEIGHTFIELD && h <= SPLAT_MAX_HEIGHTFIELD)
        return true;
    char msg[512];
    snprintf(msg, sizeof msg, "%s '%s' is %lld x %lld texels, over the pack limit "
             "of %d per side", what, path, w, h, SPLAT_MAX_HEIGHTFIELD);
    sg_error(d, loc, SG_E_OVER_LIMIT, msg);
    return false;
}

static void gdal_error(const char *path, const char *fallback, sg_loc loc,
                       sg_diags *d)
{
    const char *m = CPLGetLastErrorMsg();
    char why[400];
    snprintf(why, sizeof why, "%s%s%s", fallback, m && *m ? " (GDAL: " : "",
             m && *m ? m : "");
    if (m && *m) strncat(why, ")", sizeof why - strlen(why) - 1);
    sg_error(d, loc, SG_E_IO, path, why);
}

/* Open `path` with the allowed drivers, or NULL (error at loc). */
static GDALDatasetH open_raster(const char *path, sg_loc loc, sg_diags *d)
{
    /* a FIFO, a device or a folder never reaches GDAL (util.h) */
    char why[256];
    if (!splat_input_check(path, SPLAT_MAX_RASTER_BYTES, why, sizeof why)) {
        sg_error(d, loc, SG_E_IO, path, why);
        return NULL;
    }
    pthread_once(&gdal_once, gdal_init);
    CPLErrorReset();
    CPLPushErrorHandler(CPLQuietErrorHandler);
    GDALDatasetH ds = GDALOpenEx(path, GDAL_OF_RASTER | GDAL_OF_READONLY,
                                 drivers, NULL, NULL);
    CPLPopErrorHandler();
    if (!ds)
        gdal_error(path, "not a raster GDAL reads here (GeoTIFF, SRTM .hgt, "
                   "ASCII grid, Surfer, USGS DEM, EHdr/ENVI, XYZ)", loc, d);
    else if (GDALGetRasterCount(ds) < 1) {
        sg_error(d, loc, SG_E_IO, path, "the raster has no bands");
        GDALClose(ds);
        ds = NULL;
    }
    return ds;
}

/* Rows [y, y + n) of band 1 as doubles; false on a read error. */
static bool read_rows(GDALRasterBandH band, int w, int y, int n, double *buf)
{
    CPLErrorReset();
    CPLPushErrorHandler(CPLQuietErrorHandler);
    CPLErr e = GDALRasterIO(band, GF_Read, 0, y, w, n, buf, w, n, GDT_Float64, 0, 0);
    CPLPopErrorHandler();
    return e == CE_None;
}

/* Rows per strip: about a million texels at a time. */
static int strip_rows(int w, int h)
{
    int n = (1 << 20) / w;
    return n < 1 ? 1 : n > h ? h : n;
}

typedef struct nodata {
    bool   has;
    double value;
    bool   single;     /* the band is Float32: compare in float */
} nodata;

static nodata band_nodata(GDALRasterBandH band)
{
    int has = 0;
    nodata nd = { false, GDALGetRasterNoDataValue(band, &has), false };
    nd.has = has != 0;
    nd.single = GDALGetRasterDataType(band) == GDT_Float32;
    return nd;
}

static bool is_valid(const nodata *nd, double v)
{
    if (!isfinite(v)) return false;
    if (!nd->has) return true;
    if (v == nd->value) return false;
    return !(nd->single && (float)v == (float)nd->value);
}

/* ---- metres per CRS unit ------------------------------------------------ */

/* Metres per geotransform unit along x (east) and z (south); false with an
 * error if the CRS cannot be used. */
static bool metres_per_unit(GDALDatasetH ds, const double gt[6], int h,
                            const char *path, sg_loc loc, sg_diags *d,
                            double *fx, double *fz)
{
    *fx = *fz = 1.0;
    OGRSpatialReferenceH srs = GDALGetSpatialRef(ds);
    char msg[512];
    if (!srs) {
        snprintf(msg, sizeof msg, "heightfield '%s' has no coordinate system: "
                 "its geotransform is taken as metres (%g x %g m texels)",
                 path, fabs(gt[1]), fabs(gt[5]));
        sg_note(d, loc, "%s", msg);
        return true;
    }
    if (OSRIsGeographic(srs)) {
        double rad = OSRGetAngularUnits(srs, NULL);   /* radians per unit */
        OGRErr err = OGRERR_NONE;
        double a = OSRGetSemiMajor(srs, &err);
        double invf = OSRGetInvFlattening(srs, &err);
        double lat_units = gt[3] + gt[5] * h * 0.5;
        double phi = lat_units * rad;
        if (!(a > 0) || !(rad > 0) || !isfinite(phi) || fabs(phi) > M_PI / 2) {
            snprintf(msg, sizeof msg, "heightfield '%s': geographic coordinates "
                     "with centre latitude %g are out of range", path, lat_units);
            sg_error(d, loc, SG_E_RASTER, msg);
            return false;
        }
        double f = invf > 0 ? 1.0 / invf : 0.0;
        double e2 = f * (2.0 - f);
        double s = sin(phi), w = sqrt(1.0 - e2 * s * s);
        double N = a / w;                          /* prime vertical radius */
        double M = a * (1.0 - e2) / (w * w * w);   /* meridian radius       */
        *fx = N * cos(phi) * rad;
        *fz = M * rad;
        sg_note(d, loc, "heightfield '%s' is in geographic coordinates: at its "
                "centre latitude %.6f deg, 1 deg = %.3f m east and %.3f m north "
                "(texels %.3f x %.3f m)", path, phi * 180.0 / M_PI,
                *fx / rad * (M_PI / 180.0), *fz / rad * (M_PI / 180.0),
                fabs(gt[1]) * *fx, fabs(gt[5]) * *fz);
        return true;
    }
    double m = OSRGetLinearUnits(srs, NULL);   /* metres per unit */
    if (!(m > 0) || !isfinite(m)) {
        snprintf(msg, sizeof msg, "heightfield '%s': its coordinate system's "
                 "linear unit is not a length", path);
        sg_error(d, loc, SG_E_RASTER, msg);
        return false;
    }
    *fx = *fz = m;
    return true;
}

/* ---- heightfield -------------------------------------------------------- */

static const char *type_name(GDALDataType t)
{
    const char *n = GDALGetDataTypeName(t);
    return n ? n : "unknown";
}

/* The band's scale and offset (raw * scale + offset = metres); 1 and 0
 * where it gives none or a useless one. */
static void band_scale(GDALRasterBandH band, double *scale, double *offset)
{
    int has_scale = 0, has_off = 0;
    *scale = GDALGetRasterScale(band, &has_scale);
    *offset = GDALGetRasterOffset(band, &has_off);
    if (!has_scale || !isfinite(*scale) || *scale == 0) *scale = 1.0;
    if (!has_off || !isfinite(*offset)) *offset = 0.0;
}

/* Pass 1 over a heightfield band: the valid heights' range (raw and
 * scaled) and the nodata count.  False if a strip cannot be read. */
typedef struct height_scan {
    double lo, hi;      /* scaled heights (metres)                 */
    double rlo, rhi;    /* raw band values                         */
    size_t nholes;      /* nodata or non-finite texels             */
} height_scan;

static bool scan_heights(GDALRasterBandH band, const nodata *nd, int w, int h, int rows,
                         double *buf, double scale, double offset, height_scan *hs)
{
    for (int y = 0; y < h; y += rows) {
        int m = y + rows <= h ? rows : h - y;
        if (!read_rows(band, w, y, m, buf))
            return false;
        for (size_t i = 0; i < (size_t)w * (size_t)m; i++) {
            if (!is_valid(nd, buf[i])) {
                hs->nholes++;
                continue;
            }
            if (buf[i] < hs->rlo) hs->rlo = buf[i];
            if (buf[i] > hs->rhi) hs->rhi = buf[i];
            double v = buf[i] * scale + offset;
            if (v < hs->lo) hs->lo = v;
            if (v > hs->hi) hs->hi = v;
        }
    }
    return true;
}

/* Pass 2: the 16-bit texels, exact (a byte times 257, or the raw value
 * less base_raw) or the scaled height quantised over [lo, lo + 65535 / q];
 * nodata texels 0 and marked in `holes`. */
typedef struct texel_rule {
    bool   exact, byte;
    double base_raw, scale, offset, lo, q;
} texel_rule;

static bool store_texels(GDALRasterBandH band, const nodata *nd, int w, int h, int rows,
                         double *buf, const texel_rule *r, uint16_t *texels, uint8_t *holes)
{
    for (int y = 0; y < h; y += rows) {
        int m = y + rows <= h ? rows : h - y;
        if (!read_rows(band, w, y, m, buf))
            return false;
        size_t base = (size_t)y * (size_t)w;
        for (size_t i = 0; i < (size_t)w * (size_t)m; i++) {
            double v = buf[i];
            bool valid = is_valid(nd, v);
            if (!valid) holes[base + i] = 1;
            uint16_t texel = 0;
            if (valid && r->exact)
                texel = (uint16_t)(r->byte ? v * 257.0 : v - r->base_raw);
            else if (valid)
                texel = (uint16_t)fmin(65535.0, fmax(0.0, round(((v * r->scale + r->offset) -
                                                                 r->lo) * r->q)));
            texels[base + i] = texel;
        }
    }
    return true;
}

/* The world size (unless given) and origin from the geotransform: north
 * up, each axis's unit in metres (metres_per_unit); a raster without one
 * needs `size`. */
static bool world_size(GDALDatasetH ds, const char *path, bool size_given, int w, int h,
                       splat_terrain *t, sg_loc loc, sg_diags *d)
{
    char msg[512];
    double gt[6];
    if (GDALGetGeoTransform(ds, gt) == CE_None) {
        if (gt[2] != 0 || gt[4] != 0 || !(gt[1] != 0) || !(gt[5] != 0) ||
            !isfinite(gt[0]) || !isfinite(gt[1]) || !isfinite(gt[3]) || !isfinite(gt[5])) {
            sg_errorf(d, loc, SG_E_RASTER, "heightfield '%s' has a rotated, sheared or "
                      "degenerate geotransform (%g %g %g %g %g %g); warp it north-up "
                      "first (gdalwarp)", path, gt[0], gt[1], gt[2], gt[3], gt[4], gt[5]);
            return false;
        }
        double fx, fz;
        if (!metres_per_unit(ds, gt, h, path, loc, d, &fx, &fz))
            return false;
        t->origin[0] = gt[0];
        t->origin[1] = gt[3];
        if (!size_given) {
            t->size[0] = fabs(gt[1]) * fx * w;
            t->size[1] = fabs(gt[5]) * fz * h;
        }
    } else if (!size_given) {
        snprintf(msg, sizeof msg, "heightfield '%s' has no geotransform: give "
                 "the world size (size = X Z metres)", path);
        sg_error(d, loc, SG_E_RASTER, msg);
        return false;
    }
    if (!(t->size[0] > 0) || !(t->size[1] > 0) || !isfinite(t->size[0]) ||
        !isfinite(t->size[1])) {
        snprintf(msg, sizeof msg, "heightfield '%s' gives a world size of "
                 "%g x %g m", path, t->size[0], t->size[1]);
        sg_error(d, loc, SG_E_RASTER, msg);
        return false;
    }
    return true;
}

bool splat_raster_heightfield(splat_terrain *t, const char *path, bool size_given,
                              sg_loc loc, sg_diags *d)
{
    char msg[512];
    GDALDatasetH ds = open_raster(path, loc, d);
    if (!ds) return false;
    bool ok = false;
    double *buf = NULL;
    uint8_t *holes = NULL;
    int w = GDALGetRasterXSize(ds), h = GDALGetRasterYSize(ds);
    if (!splat_raster_check_size("heightfield", path, w, h, loc, d))
        goto done;
    GDALRasterBandH band = GDALGetRasterBand(ds, 1);
    GDALDataType type = GDALGetRasterDataType(band);
    if (GDALDataTypeIsComplex(type)) {
        snprintf(msg, sizeof msg, "heightfield '%s' holds complex numbers (%s)",
                 path, type_name(type));
        sg_error(d, loc, SG_E_RASTER, msg);
        goto done;
    }

    if (!world_size(ds, path, size_given, w, h, t, loc, d))
        goto done;

    /* heights: pass 1, the valid range and the holes */
    double scale, offset;
    band_scale(band, &scale, &offset);
    nodata nd = band_nodata(band);
    size_t n = (size_t)w * (size_t)h;
    int rows = strip_rows(w, h);
    buf = malloc((size_t)w * (size_t)rows * sizeof *buf);
    t->texels = malloc(n * sizeof *t->texels);
    if (!buf || !t->texels) {
        sg_error(d, loc, SG_E_OUT_OF_MEMORY, "heightfield does not fit in memory");
        goto done;
    }
    height_scan hs = {INFINITY, -INFINITY, INFINITY, -INFINITY, 0};
    if (!scan_heights(band, &nd, w, h, rows, buf, scale, offset, &hs)) {
        gdal_error(path, "truncated or corrupt raster", loc, d);
        goto done;
    }
    double lo = hs.lo, hi = hs.hi, rlo = hs.rlo, rhi = hs.rhi;
    size_t nholes = hs.nholes;
    if (nholes == n || !isfinite(lo) || !isfinite(hi)) {
        snprintf(msg, sizeof msg, "heightfield '%s' has no valid height (every "
                 "texel is nodata or not finite)", path);
        sg_error(d, loc, SG_E_RASTER, msg);
        goto done;
    }
    if (nholes > 0 && !(holes = calloc(n, 1))) {
        sg_error(d, loc, SG_E_OUT_OF_MEMORY, "heightfield does not fit in memory");
        goto done;
    }

    /* pass 2: 16-bit texels; exact for unsigned 8/16-bit bands (as a PNG)
     * and for other integer bands whose values span at most 65535 (shifted
     * by their lowest value) */
    bool u16 = (type == GDT_UInt16 || type == GDT_Byte) && scale > 0;
    bool shifted = !u16 && scale > 0 && !GDALDataTypeIsFloating(type) &&
                   rhi - rlo <= 65535.0;
    bool exact = u16 || shifted;
    double base_raw = shifted ? rlo : 0.0;
    double top = type == GDT_Byte ? 255.0 : 65535.0;
    texel_rule rule = {exact, type == GDT_Byte, base_raw, scale, offset, lo,
                       hi > lo ? 65535.0 / (hi - lo) : 0.0};
    if (!store_texels(band, &nd, w, h, rows, buf, &rule, t->texels, holes)) {
        gdal_error(path, "truncated or corrupt raster", loc, d);
        goto done;
    }
    if (u16) {
        t->max_height = top * scale;
        t->height_offset = offset;
    } else if (shifted) {
        t->max_height = 65535.0 * scale;
        t->height_offset = base_raw * scale + offset;
    } else {
        t->max_height = hi - lo;
        t->height_offset = lo;
        sg_note(d, loc, "heightfield '%s': %s heights %.6g .. %.6g m stored in "
                "16 bits (step %.3g m)", path, type_name(type), lo, hi, (hi - lo) / 65535.0);
    }
    if (nholes > 0)
        sg_note(d, loc, "heightfield '%s': %zu nodata texel%s cut the terrain "
                "(holes)", path, nholes, nholes == 1 ? "" : "s");
    t->width = w;
    t->height = h;
    t->holes = holes;
    holes = NULL;
    ok = true;
done:
    if (!ok) {
        free(t->texels);
        t->texels = NULL;
    }
    free(holes);
    free(buf);
    GDALClose(ds);
    return ok;
}

/* ---- painted masks ------------------------------------------------------ */

bool splat_raster_size(const char *what, const char *path, int *w, int *h,
                       sg_loc loc, sg_diags *d)
{
    GDALDatasetH ds = open_raster(path, loc, d);
    if (!ds) return false;
    *w = GDALGetRasterXSize(ds);
    *h = GDALGetRasterYSize(ds);
    GDALClose(ds);
    return splat_raster_check_size(what, path, *w, *h, loc, d);
}

uint8_t *splat_raster_mask(const char *what, const char *path, int *out_w,
                           int *out_h, sg_loc loc, sg_diags *d)
{
    char msg[512];
    GDALDatasetH ds = open_raster(path, loc, d);
    if (!ds) return NULL;
    uint8_t *out = NULL;
    double *buf = NULL;
    int w = GDALGetRasterXSize(ds), h = GDALGetRasterYSize(ds);
    if (!splat_raster_check_size(what, path, w, h, loc, d))
        goto done;
    GDALRasterBandH band = GDALGetRasterBand(ds, 1);
    GDALDataType type = GDALGetRasterDataType(band);
    bool fp = type == GDT_Float32 || type == GDT_Float64;
    if (type != GDT_Byte && !fp) {
        snprintf(msg, sizeof msg, "%s '%s' holds %s values; expected 8-bit "
                 "(0..255) or floating point (0..1)", what, path, type_name(type));
        sg_error(d, loc, SG_E_RASTER, msg);
        goto done;
    }
    nodata nd = band_nodata(band);
    int rows = strip_rows(w, h);
    buf = malloc((size_t)w * (size_t)rows * sizeof *buf);
    out = malloc((size_t)w * (size_t)h);
    if (!buf || !out) {
        sg_error(d, loc, SG_E_OUT_OF_MEMORY, "painted mask does not fit in memory");
        goto fail;
    }
    for (int y = 0; y < h; y += rows) {
        int m = y + rows <= h ? rows : h - y;
        if (!read_rows(band, w, y, m, buf)) {
            gdal_error(path, "truncated or corrupt raster", loc, d);
            goto fail;
        }
        uint8_t *dst = out + (size_t)y * (size_t)w;
        for (size_t i = 0; i < (size_t)w * (size_t)m; i++) {
            double v = buf[i];
            if (!is_valid(&nd, v)) v = 0;
            else if (fp) v = round(fmin(1.0, fmax(0.0, v)) * 255.0);
            dst[i] = (uint8_t)v;
        }
    }
    *out_w = w;
    *out_h = h;
    goto done;
fail:
    free(out);
    out = NULL;
done:
    free(buf);
    GDALClose(ds);
    return out;
}
