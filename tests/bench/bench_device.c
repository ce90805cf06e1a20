/* bench_device.c — splatbench's device benchmarks: far-bake (the far atlas
 * baked on the device) and shadow (the shadow map marched on the CPU and
 * on the device, side by side). */
#include "bench.h"

#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

typedef struct far_bake_opts {
    const char *pack_dir, *out;
    int n, runs;
} far_bake_opts;

#define F(field) offsetof(far_bake_opts, field)
static const splat_arg far_bake_rows[] = {
    { "--pack", SPLAT_ARG_STRING, "P", "the pack (built with its heightfield)", F(pack_dir) },
    { "--far-atlas", SPLAT_ARG_INT, "N", "one atlas texel per N x N heightfield texels "
      "(default 1)", F(n), .min = 1, .max = 64 },
    { "--runs", SPLAT_ARG_INT, "K", "bakes (default 1; the first with a cold pipeline cache)",
      F(runs), .min = 1, .max = 1000000 },
    { "--out", SPLAT_ARG_STRING, "PREFIX", "write the last run's level 0 as "
      "PREFIX.albedo.f32 and PREFIX.normal.f32", F(out) },
};
#undef F
static const splat_args_desc far_bake_args = {
    .prog = "splatbench far-bake", .usage = "usage: splatbench far-bake --pack P [options]\n",
    .args = far_bake_rows, .nargs = (int)(sizeof far_bake_rows / sizeof far_bake_rows[0]),
    .column = 20,
};

typedef struct shadow_opts {
    const char *pack_dir;
    int runs;
    double sun[2];
    bool sun_set;
} shadow_opts;

static bool parse_sun(const char *v, void *o, splat_arg_why *why)
{
    char tail;
    double *sun = ((shadow_opts *)o)->sun;
    (void)why;
    return sscanf(v, "%lf,%lf%c", &sun[0], &sun[1], &tail) == 2;
}

#define F(field) offsetof(shadow_opts, field)
static const splat_arg shadow_rows[] = {
    { "--pack", SPLAT_ARG_STRING, "P", "the pack", F(pack_dir) },
    { "--runs", SPLAT_ARG_INT, "K", "maps per path (default 5)", F(runs), .min = 1,
      .max = 1000000 },
    { "--sun", SPLAT_ARG_CUSTOM, "AZ,EL", "the sun (default the pack's light)",
      .parse = parse_sun, .given = SPLAT_ARG_GIVEN(shadow_opts, sun_set),
      .expects = "AZIMUTH,ELEVATION in degrees" },
};
#undef F
static const splat_args_desc shadow_args = {
    .prog = "splatbench shadow", .usage = "usage: splatbench shadow --pack P [options]\n",
    .args = shadow_rows, .nargs = (int)(sizeof shadow_rows / sizeof shadow_rows[0]),
    .column = 20,
};

/* splatbench far-bake --pack P [--far-atlas N] [--runs K] [--out PREFIX]:
 * the far atlas baked on the device (runtime/far_bake.c) from pack P, one
 * texel per N x N heightfield texels, K times (the first compiles with a
 * cold pipeline cache of its own, the later ones hit it): per run the
 * combinations compiled and the seconds of compiling and of shading.
 * --out writes the last run's level 0 for `splatbench compare`:
 * PREFIX.albedo.f32 (albedo rgb, roughness) and PREFIX.normal.f32 (xyz, 1). */
int bench_far_bake(int argc, char **argv)
{
    far_bake_opts o = { .n = 1, .runs = 1 };
    int rc = splat_args_parse(&far_bake_args, argc, argv, 2, &o);
    if (rc)
        return rc == SPLAT_ARGS_HELP ? 0 : rc;
    if (!o.pack_dir) {
        fprintf(stderr, "splatbench far-bake: --pack P is needed\n");
        return 2;
    }
    const char *pack_dir = o.pack_dir, *out = o.out;
    int n = o.n, runs = o.runs;
    rt_error e = {0};
    rt_pack p;
    rt_device dev;
    rt_renderer *r = NULL;
    bool have_pack = false, have_dev = false;
    int status = 1;
    float *al = NULL, *no = NULL, *ro = NULL, *img = NULL;
    char cache[64];
    snprintf(cache, sizeof cache, "/tmp/splatbench-farbake-%d.bin", (int)getpid());
    remove(cache);
    if (!(have_pack = rt_pack_load(&p, pack_dir, &e)) ||
        !(have_dev = rt_device_create(&dev, NULL, &e)))
        goto done;
    int w = (p.hf_width + n - 1) / n, h = (p.hf_height + n - 1) / n;
    size_t texels = (size_t)w * (size_t)h;
    al = xcalloc(texels * 3, sizeof *al);
    no = xcalloc(texels * 3, sizeof *no);
    ro = xcalloc(texels, sizeof *ro);
    printf("device %s, far atlas %d x %d texels (N = %d)\n", dev.props.deviceName, w, h, n);
    printf("run,combos,compile_s,shade_s,total_s\n");
    for (int k = 0; k < runs; k++) {
        /* the full shading, as splatc's device bake (far_bake_device.c) */
        rt_render_desc rd = { .width = 8, .height = 8, .no_undergrowth = true, .no_shadows = true,
                              .pipeline_cache = cache, .shading_lod = RT_SHADING_LOD_OFF };
        rt_far_bake_stats st;
        if (!rt_renderer_create(&dev, &p, &rd, &r, &e) ||
            !rt_renderer_bake_far(r, w, h, al, no, ro, &st, &e))
            goto done;
        rt_renderer_destroy(r);   /* saves the pipeline cache */
        r = NULL;
        printf("%d,%d,%.3f,%.3f,%.3f\n", k + 1, st.combos, st.compile_s, st.shade_s,
               st.compile_s + st.shade_s);
    }
    if (out) {
        img = xcalloc(texels * 4, sizeof *img);
        char path[4096];
        for (size_t i = 0; i < texels; i++) {
            memcpy(img + 4 * i, al + 3 * i, 3 * sizeof *img);
            img[4 * i + 3] = ro[i];
        }
        snprintf(path, sizeof path, "%s.albedo.f32", out);
        if (!rt_write_float(path, img, w, h, &e))
            goto done;
        for (size_t i = 0; i < texels; i++) {
            memcpy(img + 4 * i, no + 3 * i, 3 * sizeof *img);
            img[4 * i + 3] = 1.0f;
        }
        snprintf(path, sizeof path, "%s.normal.f32", out);
        if (!rt_write_float(path, img, w, h, &e))
            goto done;
    }
    status = 0;
done:
    if (e.msg)
        fprintf(stderr, "splatbench: %s\n", e.msg);
    rt_error_clear(&e);
    rt_renderer_destroy(r);
    if (have_dev)
        rt_device_destroy(&dev);
    if (have_pack)
        rt_pack_free(&p);
    remove(cache);
    free(al);
    free(no);
    free(ro);
    free(img);
    return status;
}

/* splatbench shadow --pack P [--runs K] [--sun AZ,EL]: the terrain's
 * shadow map marched on the CPU (shadow.c, the reference) and on the
 * device (shadow_gpu.c), side by side: K maps each, the two paths
 * interleaved (map k of the CPU, then of the device, so a change of machine
 * load hits both), the sun turned by 0.01 degree between maps so each is
 * made whole.  Prints one CSV row per map, then per path the median, p10
 * and p90 wall milliseconds, then of the process's CPU milliseconds (all
 * threads: what a loaded machine does not inflate), the ratio of the wall
 * medians, and the largest difference of the last two maps (1/255). */
int bench_shadow(int argc, char **argv)
{
    shadow_opts o = { .runs = 5, .sun = { 144, 21 } };
    int rc = splat_args_parse(&shadow_args, argc, argv, 2, &o);
    if (rc)
        return rc == SPLAT_ARGS_HELP ? 0 : rc;
    if (!o.pack_dir) {
        fprintf(stderr, "splatbench shadow: --pack P is needed\n");
        return 2;
    }
    const char *pack_dir = o.pack_dir;
    int runs = o.runs;
    double sun[2] = { o.sun[0], o.sun[1] };
    bool sun_set = o.sun_set;
    rt_error e = {0};
    rt_pack p;
    rt_device dev;
    rt_renderer *r[2] = { NULL, NULL };
    bool have_pack = false, have_dev = false;
    int status = 1;
    double *ms = NULL, *cpu_ms = NULL;
    uint8_t *map[2] = { NULL, NULL };
    static const char *const names[2] = { "cpu", "gpu" };
    if (!(have_pack = rt_pack_load(&p, pack_dir, &e)) ||
        !(have_dev = rt_device_create(&dev, NULL, &e)))
        goto done;
    size_t n = (size_t)p.hf_width * (size_t)p.hf_height;
    ms = xcalloc((size_t)runs * 2, sizeof *ms);
    cpu_ms = xcalloc((size_t)runs * 2, sizeof *cpu_ms);
    map[0] = xcalloc(n, 1);
    map[1] = xcalloc(n, 1);
    for (int k = 0; k < 2; k++) {
        rt_render_desc rd = { .width = 8, .height = 8, .no_undergrowth = true,
                              .shading = RT_SHADING_FORWARD,
                              .shadow = k ? RT_SHADOW_GPU : RT_SHADOW_CPU };
        if (!rt_renderer_create(&dev, &p, &rd, &r[k], &e))
            goto done;
    }
    rt_light l = *rt_renderer_light(r[0]);
    if (sun_set)
        memcpy(l.sun, sun, sizeof sun);
    printf("device %s, heightfield %d x %d, sun %g/%g, %d maps per path\n", dev.props.deviceName,
           p.hf_width, p.hf_height, l.sun[0], l.sun[1], runs);
    rt_camera cam;
    rt_default_camera(&p, &cam);
    /* an untimed map each: the device's pyramid and pipeline are made,
     * llvmpipe compiles the shader at its first dispatch */
    for (int k = 0; k < 2; k++) {
        rt_renderer_set_light(r[k], &l);
        if (!rt_renderer_frame(r[k], &cam, NULL, &e))
            goto done;
    }
    printf("run,path,ms,process_cpu_ms\n");
    for (int i = 0; i < runs; i++) {
        l.sun[0] += 0.01;
        for (int k = 0; k < 2; k++) {
            rt_frame_stats st;
            rt_renderer_set_light(r[k], &l);
            double c0 = process_cpu_ms();
            if (!rt_renderer_frame(r[k], &cam, &st, &e))
                goto done;
            cpu_ms[k * runs + i] = process_cpu_ms() - c0;
            ms[k * runs + i] = st.shadow_ms;
            printf("%d,%s,%.2f,%.2f\n", i + 1, names[k], st.shadow_ms, cpu_ms[k * runs + i]);
        }
    }
    int worst = 0;
    for (int k = 0; k < 2; k++)
        if (!rt_renderer_shadow_read(r[k], map[k], &e))
            goto done;
    for (size_t i = 0; i < n; i++) {
        int d = abs((int)map[0][i] - (int)map[1][i]);
        worst = d > worst ? d : worst;
    }
    double med[2], lo[2], hi[2];
    for (int k = 0; k < 2; k++) {
        percentiles(ms + k * runs, runs, &med[k], &lo[k], &hi[k]);
        printf("shadow map %s ms: median %.1f  p10 %.1f  p90 %.1f\n", names[k], med[k], lo[k],
               hi[k]);
    }
    /* under load, wall time measures the other processes too; the
     * process's CPU time (every thread's, llvmpipe's included) is the
     * work, about what a quiet machine takes times its busy cores */
    for (int k = 0; k < 2; k++) {
        percentiles(cpu_ms + k * runs, runs, &med[k], &lo[k], &hi[k]);
        printf("shadow map %s process cpu ms (all threads, the 8x8 frame included): median %.1f"
               "  p10 %.1f  p90 %.1f\n", names[k], med[k], lo[k], hi[k]);
    }
    percentiles(ms, runs, &med[0], &lo[0], &hi[0]);
    percentiles(ms + runs, runs, &med[1], &lo[1], &hi[1]);
    printf("shadow map cpu / gpu: %.2fx; largest difference %d/255\n", med[0] / med[1], worst);
    status = 0;
done:
    if (e.msg)
        fprintf(stderr, "splatbench: %s\n", e.msg);
    rt_error_clear(&e);
    rt_renderer_destroy(r[0]);
    rt_renderer_destroy(r[1]);
    if (have_dev)
        rt_device_destroy(&dev);
    if (have_pack)
        rt_pack_free(&p);
    free(ms);
    free(cpu_ms);
    free(map[0]);
    free(map[1]);
    return status;
}
