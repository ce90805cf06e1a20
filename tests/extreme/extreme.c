/* extreme.c — numerical stability at the extremes (extreme-value stability).
 *
 *   extreme nodes      mask nodes at extreme inputs: ramp with lo == hi,
 *                      overlay and scale_contrast at 0, 1 and outside
 *                      [0, 1], contrast 0 and 1e6, a texture holding NaN
 *                      and Inf; each value by the CPU double reference
 *                      (ir_eval) and on the Vulkan device through the
 *                      compute harness (the project's GLSL emitter, fp32)
 *   extreme normals    Listing 1's normal filter (abi.h) at heights 0 and
 *                      65535 with max height 0 m, 1 m, 10 km, flat ground,
 *                      vertical cliffs, 1x1/2x2 heightfields (texel = the
 *                      whole terrain), 100 km terrains with 1 cm..40 km
 *                      texels: double reference vs the same formula in
 *                      float (what the shader computes)
 *   extreme gen DIR    heightfields, masks and scenes for run.sh's renders
 *   extreme check F.f32 [--mask] [--expect r,g,b TOL --clear r,g,b]
 *                      a splatview --float-out image: no NaN/Inf; --mask:
 *                      every value in [0, 1]; --expect: every pixel that
 *                      is not the clear colour within TOL of r,g,b
 *
 * Each prints a table (case, inputs, CPU value, GPU value, |error|, bound)
 * and exits 1 when a value is NaN/Inf where the case requires finite, a
 * mask leaves [0, 1], or an error exceeds its stated bound. */
#include "harness.h"
#include "sg.h"
#include "splatrt.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include <stb/stb_image_write.h>

static int failures;

static void fail(const char *fmt, const char *what)
{
    fprintf(stderr, fmt, what);
    failures++;
}

/* ---- nodes ------------------------------------------------------------------ */

static const char materials[] =
    "import \"nodes/masks.sg\"\n"
    "material ramp_eq {\n"
    "    node r : height_ramp { lo = 100.0, hi = 100.0 }\n"
    "    out mask = r.out\n"
    "}\n"
    "material overlay_x {\n"
    "    param float base = 0.5\n"
    "    param float blend = 0.5\n"
    "    param float opacity = 1.0\n"
    "    node o : overlay { base = base, blend = blend, opacity = opacity }\n"
    "    out mask = o.out\n"
    "}\n"
    "material contrast_x {\n"
    "    param float value = 0.5\n"
    "    param float contrast = 1.0\n"
    "    node c : scale_contrast { value = value, contrast = contrast }\n"
    "    out mask = c.out\n"
    "}\n"
    "material tex_x {\n"
    "    node s : sample { tex = \"graphs/textures/rock.png\", uv = terrain.uv }\n"
    "    node o : overlay { base = 0.7, blend = s.r, opacity = 0.7 }\n"
    "    out mask = o.out\n"
    "}\n";

enum { NROOTS = 4 };
static const char *const root_names[NROOTS] = {"ramp_eq.mask", "overlay_x.mask",
                                                "contrast_x.mask", "tex_x.mask"};

typedef struct pcase {
    const char *what;
    int         root;
    double      height, p[5];      /* base blend opacity value contrast */
    double      uv[2];
    bool        may_be_nonfinite;  /* NaN/Inf texel input               */
    bool        clamp_only;        /* raw value may leave [0,1]: check the
                                      clamped mask the composite uses   */
} pcase;

static int param_index(const ir *ir, const char *name)
{
    for (int i = 0; i < ir->nparams; i++)
        if (!strcmp(ir->params[i].name, name))
            return i;
    return -1;
}

/* the 2x2 texture: NaN, +Inf / -Inf, 0.5 (nearest, so each is read alone) */
static float tex_rgba[16];

static void sample_tex(void *user, int texture, double u, double v, double rgba[4])
{
    harness_image im = {.width = 2, .height = 2, .rgba = tex_rgba,
                        .filter = IR_FILTER_NEAREST, .wrap = IR_WRAP_CLAMP};
    harness_image_sample(&im, u, v, rgba);
}

static int cmd_nodes(void)
{
    float nan = NAN, inf = INFINITY;
    float t[16] = {nan, nan, nan, 1, inf, inf, inf, 1, -inf, -inf, -inf, 1, 0.5f, 0.5f, 0.5f, 1};
    memcpy(tex_rgba, t, sizeof t);

    static const char *const search[] = {".", NULL};
    sg_diags d;
    sg_diags_init(&d);
    sg_program *p = sg_load_string("extreme.sg", materials, search, &d);
    ir ir;
    ir_init(&ir);
    bool ok = p && d.nerrors == 0;
    for (int i = 0; ok && i < sg_material_count(p); i++)
        ok = sg_lower_material(p, sg_material_name(p, i), &ir, &d);
    if (!ok) {
        sg_diags_print(&d, stderr);
        return 1;
    }
    ir_ref roots[NROOTS];
    for (int r = 0; r < NROOTS; r++)
        roots[r] = ir_find_root(&ir, root_names[r]);
    const char *pn[5] = {"overlay_x.base", "overlay_x.blend", "overlay_x.opacity",
                         "contrast_x.value", "contrast_x.contrast"};
    int pi[5];
    for (int k = 0; k < 5; k++) {
        pi[k] = param_index(&ir, pn[k]);
        if (pi[k] < 0) {
            fprintf(stderr, "extreme: no param %s\n", pn[k]);
            return 1;
        }
    }

    /* the cases */
    pcase cs[256];
    int n = 0;
    static const double heights[] = {-1e4, 0, 99.999, 100, 100.001, 1e4, 1e6};
    for (size_t i = 0; i < sizeof heights / sizeof *heights; i++)
        cs[n++] = (pcase){"ramp lo == hi == 100 m", 0, heights[i], {0.5, 0.5, 1, 0.5, 1}};
    static const double ov[] = {0, 1, -0.5, 1.5, 0.5};
    static const double op[] = {0, 1, 0.7};
    for (int a = 0; a < 5; a++)
        for (int b = 0; b < 5; b++)
            for (int o = 0; o < 3; o++)
                cs[n++] = (pcase){"overlay base blend opacity", 1, 0, {ov[a], ov[b], op[o], 0.5, 1},
                                  .clamp_only = ov[a] < 0 || ov[a] > 1 || ov[b] < 0 || ov[b] > 1};
    static const double cv[] = {0, 1, -1, 2, 0.5, 0.25};
    static const double cc[] = {0, 1, 1e6};
    for (int a = 0; a < 6; a++)
        for (int c = 0; c < 3; c++)
            cs[n++] = (pcase){"scale_contrast value contrast", 2, 0, {0.5, 0.5, 1, cv[a], cc[c]}};
    static const char *const tnames[] = {"texel NaN", "texel +Inf", "texel -Inf", "texel 0.5"};
    for (int k = 0; k < 4; k++)
        cs[n] = (pcase){tnames[k], 3, 0, {0.5, 0.5, 1, 0.5, 1},
                        {(k % 2 + 0.5) / 2, (k / 2 + 0.5) / 2}, k < 3},
        n++;

    /* points: one per case (every root evaluated, only the case's root read) */
    ir_env *pts = calloc((size_t)n, sizeof *pts);
    double *params = calloc((size_t)n * (size_t)ir.nparams * 4, sizeof *params);
    for (int i = 0; i < n; i++) {
        double *pp = params + (size_t)i * (size_t)ir.nparams * 4;
        for (int q = 0; q < ir.nparams; q++)
            memcpy(pp + 4 * q, ir.params[q].def, sizeof ir.params[q].def);
        for (int k = 0; k < 5; k++)
            pp[4 * pi[k]] = (double)(float)cs[i].p[k];
        pts[i] = (ir_env){.height = cs[i].height, .slope = 0, .normal = {0, 1, 0},
                          .uv = {cs[i].uv[0], cs[i].uv[1]}, .params = pp,
                          .sample = sample_tex};
    }
    harness_image img = {.width = 2, .height = 2, .rgba = tex_rgba,
                         .filter = IR_FILTER_NEAREST, .wrap = IR_WRAP_CLAMP};
    harness_image *imgs = calloc((size_t)(ir.ntextures ? ir.ntextures : 1), sizeof *imgs);
    for (int k = 0; k < ir.ntextures; k++)
        imgs[k] = img;
    float *gpu = calloc((size_t)n * NROOTS * 4, sizeof *gpu);
    char *err = NULL;
    harness *h = harness_create(&(harness_desc){0}, &err);
    bool have_gpu = h != NULL;
    if (h) {
        harness_ir_desc hd = {.ir = &ir, .roots = roots, .nroots = NROOTS, .points = pts,
                              .npoints = n, .images = imgs};
        if (!harness_eval_ir(h, &hd, gpu, NULL, &err)) {
            fprintf(stderr, "extreme: harness: %s\n", err ? err : "?");
            failures++;
            have_gpu = false;
        }
    } else {
        fprintf(stderr, "extreme: no Vulkan device (%s): CPU reference only\n", err ? err : "?");
        failures++;
    }
    free(err);

    /* bound: a few fp32 ulps of the inputs' scale; contrast 1e6 multiplies
     * the rounding of (value - 0.5) by 1e6, but the inputs here are exact
     * in float so the saturated result is exact too */
    const double tol = 1e-6;
    printf("%-32s %-30s %12s %12s %10s %8s\n", "case", "inputs", "cpu (double)", "gpu (fp32)",
           "|error|", "bound");
    double maxerr[NROOTS] = {0};
    for (int i = 0; i < n; i++) {
        double ref[4];
        ir_eval(&ir, roots[cs[i].root], &pts[i], ref);
        double g = have_gpu ? gpu[((size_t)i * NROOTS + (size_t)cs[i].root) * 4] : NAN;
        char in[64];
        if (cs[i].root == 0)
            snprintf(in, sizeof in, "height %g", cs[i].height);
        else if (cs[i].root == 1)
            snprintf(in, sizeof in, "%g %g %g", cs[i].p[0], cs[i].p[1], cs[i].p[2]);
        else if (cs[i].root == 2)
            snprintf(in, sizeof in, "%g %g", cs[i].p[3], cs[i].p[4]);
        else
            snprintf(in, sizeof in, "uv %g,%g", cs[i].uv[0], cs[i].uv[1]);
        double e = fabs(g - ref[0]);
        /* the mask the composite uses: clamped to 0..1 (PACK.md) */
        double cm = fmin(fmax(ref[0], 0), 1), gm = fminf(fmaxf((float)g, 0), 1);
        if (cs[i].clamp_only)
            e = fabs(gm - cm);
        bool finite = isfinite(ref[0]) && isfinite(g);
        printf("%-32s %-30s %12.7g %12.7g %10.3g %8.0e%s\n", cs[i].what, in, ref[0], g,
               finite ? e : NAN, tol,
               !finite ? (cs[i].may_be_nonfinite ? "  NaN/Inf (texture input; see below)" : "  FAIL: NaN/Inf")
               : cs[i].clamp_only ? "  (raw value outside 0..1: clamped compared)" : "");
        if (!finite && !cs[i].may_be_nonfinite && (have_gpu || !isfinite(ref[0])))
            fail("extreme: %s: NaN/Inf\n", cs[i].what);
        if (finite && e > tol)
            fail("extreme: %s: error above the bound\n", cs[i].what);
        if (finite && !cs[i].clamp_only && cs[i].root != 3 && (ref[0] < 0 || ref[0] > 1))
            fail("extreme: %s: mask outside [0, 1]\n", cs[i].what);
        /* Listing 2: overlay leaves base 0 and 1 alone for blend, opacity in 0..1 */
        if (cs[i].root == 1 && (cs[i].p[0] == 0 || cs[i].p[0] == 1) && !cs[i].clamp_only &&
            cs[i].p[2] <= 1 && (ref[0] != cs[i].p[0] || (have_gpu && g != cs[i].p[0])))
            fail("extreme: %s: overlay moved base 0 or 1\n", in);
        if (finite && e > maxerr[cs[i].root])
            maxerr[cs[i].root] = e;
    }
    printf("\nmax |gpu - cpu|: ramp %.3g, overlay %.3g, scale_contrast %.3g, texture %.3g "
           "(bound %.0e; device %s)\n", maxerr[0], maxerr[1], maxerr[2], maxerr[3], tol,
           h ? harness_device_name(h) : "none");
    printf("NaN/Inf texels: a float texture holding NaN or Inf makes the mask NaN/Inf (both "
           "back ends); packs carry 8-bit PNG textures, so no pack can hold one.\n");
    if (h && harness_destroy(h) != 0)
        fail("extreme: %s\n", "validation messages");
    free(gpu);
    free(imgs);
    free(pts);
    free(params);
    ir_free(&ir);
    sg_free(p);
    sg_diags_free(&d);
    return failures ? 1 : 0;
}

/* ---- normals ---------------------------------------------------------------- */

/* Listing 1 in float, term for term as splat_normal_at() computes it. */
static void normal_f32(float hl, float hr, float hd, float hu, float maxh, float dx, float dz,
                       float n[3])
{
    n[0] = (hl - hr) * maxh / dx;
    n[1] = 2.0f;
    n[2] = (hd - hu) * maxh / dz;
    float len = sqrtf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    for (int i = 0; i < 3; i++)
        n[i] /= len;
}

static int cmd_normals(void)
{
    typedef struct { const char *what; double h[4]; } hcase;
    static const hcase hs[] = {
        {"all 0", {0, 0, 0, 0}},
        {"all 65535", {1, 1, 1, 1}},
        {"flat 32768", {32768 / 65535.0, 32768 / 65535.0, 32768 / 65535.0, 32768 / 65535.0}},
        {"cliff x (0 | 65535)", {0, 1, 0.5, 0.5}},
        {"cliff x+z", {1, 0, 1, 0}},
        {"1 step", {0, 1 / 65535.0, 0, 0}},
    };
    typedef struct { const char *what; double maxh, dx, dz; } scase;
    static const scase ss[] = {
        {"max 0 m, 1 m texels", 0, 1, 1},
        {"max 1 m, 1 m texels", 1, 1, 1},
        {"max 10 km, 1 m texels", 1e4, 1, 1},
        {"max 10 km, 1 cm texels", 1e4, 0.01, 0.01},
        {"max 10 km, 1x1 hf of 100 km", 1e4, 1e5, 1e5},
        {"max 10 km, 2x2 hf of 1 m", 1e4, 0.5, 0.5},
        {"100 km / 2401 x 1201 texels", 2962, 1e5 / 2401, 1e5 / 1201},
        {"max 1 m, 40 km texels", 1, 4e4, 4e4},
    };
    const double tol = 4e-7;   /* a few fp32 ulps of a unit vector */
    printf("%-22s %-30s %-28s %10s %8s %10s\n", "heights (l r d u)", "scale", "normal (double)",
           "slope", "|n32-n|", "bound");
    double worst = 0;
    for (size_t i = 0; i < sizeof hs / sizeof *hs; i++)
        for (size_t j = 0; j < sizeof ss / sizeof *ss; j++) {
            const double *h = hs[i].h;
            double n[3];
            float f[3];
            splat_normal_filter(h[0], h[1], h[2], h[3], ss[j].maxh, ss[j].dx, ss[j].dz, n);
            normal_f32((float)h[0], (float)h[1], (float)h[2], (float)h[3], (float)ss[j].maxh,
                       (float)ss[j].dx, (float)ss[j].dz, f);
            double e = 0;
            bool finite = true;
            for (int c = 0; c < 3; c++) {
                finite = finite && isfinite(n[c]) && isfinite(f[c]);
                e = fmax(e, fabs(f[c] - n[c]));
            }
            double slope = 1 - n[1];
            char nb[64];
            snprintf(nb, sizeof nb, "%.5f %.5f %.5f", n[0], n[1], n[2]);
            printf("%-22s %-30s %-28s %10.6f %8.2g %10.0e\n", hs[i].what, ss[j].what, nb, slope, e, tol);
            if (!finite)
                fail("extreme: normal of %s: NaN/Inf\n", hs[i].what);
            else if (e > tol)
                fail("extreme: normal of %s: fp32 error above the bound\n", hs[i].what);
            if (!(slope >= 0 && slope <= 1))
                fail("extreme: slope of %s outside [0, 1]\n", hs[i].what);
            worst = fmax(worst, e);
        }
    printf("\nmax |fp32 - double| over the normal components: %.3g (bound %.0e)\n", worst, tol);
    printf("vertical cliff: Listing 1 keeps n.y = 2 before normalising, so slope reaches 1 "
           "only in the limit (0.99980 at 10 km over 1 m texels), never exactly 1.\n");
    return failures ? 1 : 0;
}

/* ---- gen: rasters and scenes for the renders ---------------------------------- */

static bool write_r16(const char *path, int w, int h, uint16_t (*f)(int, int, int, int))
{
    FILE *fp = fopen(path, "wb");
    if (!fp)
        return false;
    bool ok = true;
    for (int j = 0; j < h; j++)
        for (int i = 0; i < w; i++) {
            uint16_t v = f(i, j, w, h);
            uint8_t b[2] = {(uint8_t)(v & 255), (uint8_t)(v >> 8)};
            ok = ok && fwrite(b, 1, 2, fp) == 2;
        }
    return fclose(fp) == 0 && ok;
}

static uint16_t hf_flat(int i, int j, int w, int h) { return 32768; }
/* two halves 0 | 65535: a vertical cliff between adjacent texels */
static uint16_t hf_cliff(int i, int j, int w, int h) { return i < w / 2 ? 0 : 65535; }
/* 0 and 65535 in a checkerboard of 8-texel squares */
static uint16_t hf_checker(int i, int j, int w, int h) { return ((i / 8 + j / 8) & 1) ? 65535 : 0; }
static uint16_t hf_hills(int i, int j, int w, int h)
{
    return (uint16_t)lround(32767.5 + 32767.5 * sin(i * 0.05) * cos(j * 0.07));
}

typedef struct gcase {
    const char *name;
    int         w, h;
    uint16_t  (*f)(int, int, int, int);
    double      size, maxh, offset;
    const char *mask;              /* "zero", "one" or NULL (half painted) */
} gcase;

static const gcase gcases[] = {
    {"max0", 64, 64, hf_cliff, 256, 0, 0, NULL},
    {"max1", 64, 64, hf_checker, 256, 1, 0, NULL},
    {"max10km", 64, 64, hf_cliff, 256, 1e4, 0, NULL},
    {"flat", 64, 64, hf_flat, 256, 100, 0, NULL},
    {"hf1x1", 1, 1, hf_flat, 256, 100, 0, NULL},
    {"hf2x2", 2, 2, hf_checker, 256, 100, 0, NULL},
    {"offset1e6", 64, 64, hf_hills, 256, 100, 1e6, NULL},
    {"world100km", 256, 256, hf_hills, 1e5, 2000, 0, NULL},
    {"masks0", 64, 64, hf_hills, 256, 50, 0, "zero"},
    {"masks1", 64, 64, hf_hills, 256, 50, 0, "one"},
};

static int cmd_gen(const char *dir)
{
    mkdir(dir, 0777);
    for (size_t c = 0; c < sizeof gcases / sizeof *gcases; c++) {
        const gcase *g = &gcases[c];
        char path[4096];
        snprintf(path, sizeof path, "%s/%s", dir, g->name);
        mkdir(path, 0777);
        snprintf(path, sizeof path, "%s/%s/hf.r16", dir, g->name);
        if (!write_r16(path, g->w, g->h, g->f)) {
            fprintf(stderr, "extreme: cannot write %s\n", path);
            return 1;
        }
        size_t npx = (size_t)(unsigned)g->w * (unsigned)g->h;
        uint8_t *m = calloc(npx, 1);
        if (!m)
            return 1;
        for (int i = 0; i < g->w * g->h; i++)
            m[i] = g->mask ? (!strcmp(g->mask, "one") ? 255 : 0) : (i % g->w < g->w / 2 ? 255 : 0);
        snprintf(path, sizeof path, "%s/%s/paint.png", dir, g->name);
        if (!stbi_write_png(path, g->w, g->h, 1, m, g->w)) {
            fprintf(stderr, "extreme: cannot write %s\n", path);
            return 1;
        }
        free(m);
        snprintf(path, sizeof path, "%s/%s/scene.sg", dir, g->name);
        FILE *f = fopen(path, "w");
        if (!f)
            return 1;
        fprintf(f,
                "# extreme case %s (written by tests/extreme/extreme gen)\n"
                "import \"nodes/compositors.sg\"\n"
                "import \"tests/extreme/materials.sg\"\n"
                "scene %s {\n"
                "    heightfield = \"hf.r16\"\n"
                "    heightfield_size = %d %d\n"
                "    size = %.17g %.17g\n"
                "    max_height = %.17g\n"
                "    height_offset = %.17g\n"
                "    materials = [x_base, x_painted, x_step, x_slope]\n"
                "    compositor = linear_alpha\n"
                "    painted paint = \"paint.png\"\n"
                "    cell = %d\n"
                "}\n",
                g->name, g->name, g->w, g->h, g->size, g->size, g->maxh, g->offset,
                g->w < 32 ? 1 : 32);
        fclose(f);
    }
    return 0;
}

/* ---- check: a rendered float image ---------------------------------------------- */

static int cmd_check(int argc, char **argv)
{
    float *img = NULL;
    int w, h;
    rt_error e = {0};
    if (!rt_read_float(argv[2], &img, &w, &h, &e)) {
        fprintf(stderr, "extreme: %s\n", e.msg);
        rt_error_clear(&e);
        return 1;
    }
    bool mask = false, expect = false;
    double ex[3] = {0}, clear[3] = {0}, tol = 0;
    for (int i = 3; i < argc; i++) {
        if (!strcmp(argv[i], "--mask"))
            mask = true;
        else if (!strcmp(argv[i], "--expect") && i + 2 < argc) {
            expect = sscanf(argv[i + 1], "%lf,%lf,%lf", &ex[0], &ex[1], &ex[2]) == 3;
            tol = atof(argv[i + 2]);
            i += 2;
        } else if (!strcmp(argv[i], "--clear") && i + 1 < argc) {
            if (sscanf(argv[++i], "%lf,%lf,%lf", &clear[0], &clear[1], &clear[2]) != 3)
                return 2;
        } else
            return 2;
    }
    long nonfinite = 0, outside = 0, terrain = 0;
    double lo = INFINITY, hi = -INFINITY, maxerr = 0;
    for (long p = 0; p < (long)w * h; p++) {
        const float *px = img + 4 * p;
        bool bg = true;
        for (int c = 0; c < 3; c++)
            bg = bg && fabs(px[c] - clear[c]) < 1e-6;
        for (int c = 0; c < 4; c++) {
            if (!isfinite(px[c])) {
                nonfinite++;
                continue;
            }
            if (c < 3) {
                lo = fmin(lo, px[c]);
                hi = fmax(hi, px[c]);
                if (mask && (px[c] < 0 || px[c] > 1))
                    outside++;
            }
        }
        if (expect && !bg) {
            terrain++;
            for (int c = 0; c < 3; c++)
                maxerr = fmax(maxerr, fabs(px[c] - ex[c]));
        }
    }
    printf("%-48s nonfinite %ld  range [%.6g, %.6g]", argv[2], nonfinite, lo, hi);
    if (mask)
        printf("  outside 0..1: %ld", outside);
    if (expect)
        printf("  max |v - exact| %.3g over %ld terrain pixels (bound %g)", maxerr, terrain, tol);
    printf("\n");
    free(img);
    return nonfinite || outside || (expect && (maxerr > tol || terrain == 0)) ? 1 : 0;
}

int main(int argc, char **argv)
{
    if (argc == 2 && !strcmp(argv[1], "nodes"))
        return cmd_nodes();
    if (argc == 2 && !strcmp(argv[1], "normals"))
        return cmd_normals();
    if (argc == 3 && !strcmp(argv[1], "gen"))
        return cmd_gen(argv[2]);
    if (argc >= 3 && !strcmp(argv[1], "check"))
        return cmd_check(argc, argv);
    fprintf(stderr, "usage: extreme nodes | normals | gen DIR | check F.f32 [--mask] "
            "[--expect r,g,b TOL --clear r,g,b]\n");
    return 2;
}
