/* probe_check — the vector masks the GPU computed against the CPU
 * reference (compiler/vector.c), pixel by pixel:
 *   probe_check SCENE.sg IMAGE.f32 WHICH
 * IMAGE is splatview's --float-out of tests/vector/probe.sg at the albedo
 * view: per pixel (value, x / 1024, z / 1024), the value vector.road
 * (WHICH 0), vector.road.across (1) or vector.yard (2), each from the
 * shader's grid walk at that pixel's position.  The reference is the
 * distance over every segment of the shape (and the even-odd rule over
 * every polygon edge), through the same profile.  Fails on any pixel off
 * by more than 1e-3, or when the picture holds fewer than 200 pixels of
 * values over 0.9, between and under 0.1 (so a blank or constant picture
 * fails). */
#include "scene_load.h"
#include "splatrt.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

int main(int argc, char **argv)
{
    if (argc != 4) {
        fprintf(stderr, "usage: probe_check SCENE.sg IMAGE.f32 WHICH\n");
        return 2;
    }
    int which = atoi(argv[3]);
    sg_diags d;
    sg_diags_init(&d);
    splat_scene s;
    if (!splat_scene_load(&s, argv[1], NULL, &d)) {
        sg_diags_print(&d, stderr);
        return 1;
    }
    sg_diags_free(&d);
    float *px;
    int w, h;
    rt_error e = { 0 };
    if (!rt_read_float(argv[2], &px, &w, &h, &e)) {
        fprintf(stderr, "probe_check: %s\n", e.msg ? e.msg : "cannot read the image");
        return 1;
    }
    int shape = which == 2 ? 1 : 0;
    bool across = which == 1;
    long core = 0, edge = 0, out = 0, bad = 0, n = 0;
    double worst = 0, wx = 0, wz = 0;
    for (long i = 0; i < (long)w * h; i++) {
        const float *p = &px[4 * i];
        double x = p[1] * s.terrain.size[0], z = p[2] * s.terrain.size[1];
        double dist = splat_vector_distance(&s.vectors, shape, x, z);
        double want = splat_vector_profile(&s.vectors, shape, dist, across);
        double err = fabs(p[0] - want);
        n++;
        if (err > worst) worst = err, wx = x, wz = z;
        if (err > 1e-3) bad++;
        if (want > 0.9) core++;
        else if (want < 0.1) out++;
        else edge++;
    }
    printf("probe %d: %ld pixels, %ld over 0.9, %ld between, %ld under 0.1; largest error %.3g at "
           "x %.2f z %.2f; %ld over 1e-3\n", which, n, core, edge, out, worst, wx, wz, bad);
    free(px);
    splat_scene_free(&s);
    if (bad > 0) {
        fprintf(stderr, "FAIL: %ld pixels differ from the CPU reference by more than 1e-3\n",
                bad);
        return 1;
    }
    if (core < 200 || edge < 200 || out < 200) {
        fprintf(stderr, "FAIL: the picture does not show values over 0.9, between and under "
                "0.1 (200 pixels each)\n");
        return 1;
    }
    return 0;
}
