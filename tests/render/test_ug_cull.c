/* test_ug_cull.c — the undergrowth's cull passes (runtime/undergrowth.c
 * "cull": per-instance frustum and fade culling on the GPU, one indirect
 * draw per block and LOD) on a Vulkan device with SPLAT_VALIDATE=1.
 *
 *   test_ug_cull OUTDIR   (run from the repository root)
 *
 * A flat 128 m meadow with grass (2 per m^2) and stones, every 16 m cell
 * allocated (radius 96 m), seen from a low camera near a corner looking
 * across it:
 *   - the drawn list (read back from the device) is as long as the stats
 *     say, holds no instance twice, and every instance in it lies inside
 *     the horizontal field of view (widened by its bounding radius);
 *   - the cull removed what the frustum hides: the instances drawn are
 *     fewer than half of those the distance LOD and the fade keep in the
 *     allocated cells (the probe's count, rt_renderer_undergrowth_rings);
 *   - per block its keys: the near mesh, the far mesh, and for the grass
 *     (whose far mesh is tapered quads) single triangles, each with fewer
 *     indices per instance than the one before, the grass drawn at every
 *     LOD, each key's instances in its ring: from 0, 14 m (the LOD
 *     distance) and 28 m on, to the next ring's start plus a cell's
 *     diagonal;
 *   - a second renderer draws the same list, byte for byte and in the
 *     same order;
 *   - the camera turned round draws none of the first view's instances
 *     that lie more than 3 m outside the turned frustum. */
#include "kit.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <stb_image_write.h>

enum { N = 129, W = 256, H = 192, MAXI = 1 << 16, RINGS = 16 };
static const double LOD_NEAR = 14.0, CELL = 16.0, BOUND = 3.0;

static bool write_inputs(const char *dir)
{
    static uint8_t hf[N * N];
    char *png = kit_join(dir, "flat.png"), *sg = kit_join(dir, "meadow.sg");
    bool ok = stbi_write_png(png, N, N, 1, hf, N) != 0;
    FILE *f = ok ? fopen(sg, "w") : NULL;
    free(png);
    free(sg);
    if (!f)
        return false;
    fprintf(f, "import \"nodes/compositors.sg\"\nimport \"nodes/masks.sg\"\n"
               "material ground {\n    out albedo = vec3(0.30, 0.25, 0.20)\n}\n"
               "material meadow {\n    out mask = 0.5\n    out albedo = vec3(0.2, 0.4, 0.1)\n"
               "    undergrowth grass { density = 2, scale = 0.8 1.2 }\n"
               "    undergrowth stone { density = 0.1, align = normal }\n}\n"
               "scene meadow {\n    heightfield = \"flat.png\"\n    size = 128 128\n"
               "    max_height = 10\n    materials = [ground, meadow]\n    cell = 16\n}\n");
    return fclose(f) == 0;
}

static rt_renderer *renderer(rt_device *dev, const rt_pack *p)
{
    rt_render_desc rd = { .width = W, .height = H, .shading = RT_SHADING_FORWARD };
    rt_error e = { 0 };
    rt_renderer *r = NULL;
    CHECK(rt_renderer_create(dev, p, &rd, &r, &e), "renderer: %s", e.msg ? e.msg : "?");
    rt_error_clear(&e);
    return r;
}

/* The angle (radians) between the root's direction from the camera and
 * the camera's look direction, both on the ground plane. */
static double off_axis(const rt_camera *c, const rt_ug_instance *v)
{
    double lx = c->look[0] - c->position[0], lz = c->look[2] - c->position[2];
    double dx = v->pos[0] - c->position[0], dz = v->pos[2] - c->position[2];
    double cosang = (lx * dx + lz * dz) / (hypot(lx, lz) * hypot(dx, dz) + 1e-12);
    return acos(cosang < -1 ? -1 : cosang > 1 ? 1 : cosang);
}

/* Whether the instance may be seen: inside the horizontal field of view
 * widened by BOUND metres at its distance (or within BOUND of the camera). */
static bool in_view(const rt_camera *c, const rt_ug_instance *v, double half)
{
    double d = hypot(v->pos[0] - c->position[0], v->pos[2] - c->position[2]);
    return d <= BOUND || off_axis(c, v) <= half + asin(BOUND / d);
}

static int frame_drawn(rt_renderer *r, const rt_camera *cam, rt_frame_stats *st,
                       rt_ug_instance *out, int *key)
{
    rt_error e = { 0 };
    CHECK(rt_renderer_frame(r, cam, st, &e), "frame: %s", e.msg ? e.msg : "?");
    rt_error_clear(&e);
    int n = rt_renderer_undergrowth_drawn(r, out, key, MAXI, &e);
    CHECK(n >= 0 && n <= MAXI, "drawn list: %d (%s)", n, e.msg ? e.msg : "?");
    rt_error_clear(&e);
    return n < 0 ? 0 : n > MAXI ? MAXI : n;
}

static int cmp_inst(const void *a, const void *b)
{
    return memcmp(a, b, sizeof(rt_ug_instance));
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: test_ug_cull OUTDIR (run from the repository root)\n");
        return 2;
    }
    const char *dir = argv[1];
    char *sg = kit_join(dir, "meadow.sg"), *packdir = kit_join(dir, "meadow.pack");
    bool built = write_inputs(dir) && kit_build_pack_ok(sg, packdir);
    rt_pack *p = built ? kit_pack(packdir) : NULL;
    rt_device *dev = p ? kit_device() : NULL;
    rt_ug_instance *a = malloc(sizeof *a * MAXI), *b = malloc(sizeof *b * MAXI);
    int *ka = malloc(sizeof *ka * MAXI), *kb = malloc(sizeof *kb * MAXI);
    if (!dev || !a || !b || !ka || !kb)
        return kit_finish("ug_cull");
    rt_renderer *r1 = renderer(dev, p), *r2 = renderer(dev, p);
    if (!r1 || !r2)
        return kit_finish("ug_cull");

    rt_camera cam = { .position = { 12, 2, 12 }, .look = { 60, 0, 50 } };
    double half = atan(tan(M_PI / 6) * W / H);   /* the default 60 degrees vertical */
    rt_frame_stats st;
    int n = frame_drawn(r1, &cam, &st, a, ka);
    const rt_ug_stats *u = &st.undergrowth;
    printf("cells %d, candidates %ld, instances %ld, drawn %ld (%d listed), triangles %ld, "
           "%d draws, %d keys\n", u->cells, u->candidates, u->instances, u->drawn, n,
           u->triangles, u->draws, u->keys);
    CHECK(n > 100 && n == u->drawn, "drawn list %d, stats %ld", n, u->drawn);
    CHECK(u->candidates >= u->instances && u->instances > u->drawn,
          "candidates %ld, instances %ld, drawn %ld", u->candidates, u->instances, u->drawn);

    /* inside the frustum, each once */
    int outside = 0, dup = 0;
    for (int i = 0; i < n; i++)
        outside += !in_view(&cam, &a[i], half);
    memcpy(b, a, sizeof *a * (size_t)n);
    qsort(b, (size_t)n, sizeof *b, cmp_inst);
    for (int i = 1; i < n; i++)
        dup += memcmp(&b[i - 1], &b[i], sizeof *b) == 0;
    CHECK(outside == 0, "%d of %d drawn instances outside the field of view", outside, n);
    CHECK(dup == 0, "%d instances drawn twice", dup);

    /* what the LOD and the fade keep in all the cells, against the drawn */
    uint32_t rings[2 * RINGS];
    rt_error e = { 0 };
    CHECK(rt_renderer_undergrowth_rings(r1, 16.0, RINGS, rings, &e) > 0, "rings: %s",
          e.msg ? e.msg : "?");
    rt_error_clear(&e);
    long kept = 0;
    for (int k = 0; k < RINGS; k++)
        kept += rings[k];
    printf("kept by the LOD and the fade: %ld, drawn after the frustum: %d\n", kept, n);
    CHECK(n * 2L < kept, "drawn %d of %ld kept: the frustum culled too little", n, kept);

    /* the keys: per block a near, a far mesh and (grass: tapered quads) a
     * single-triangle one, fewer indices each, their instances in rings */
    for (int blk = 0; blk < 2; blk++) {
        int key[3] = { -1, -1, -1 }, nk = 0;
        for (int k = 0; k < u->keys; k++)
            if (u->key_block[k] == blk && nk < 3)
                key[nk++] = k;
        CHECK(nk == (blk == 0 ? 3 : 2), "block %d: %d keys", blk, nk);
        for (int l = 0; l < nk; l++)
            printf("block %d, LOD %d: %u instances x %u indices\n", blk, l, u->key_drawn[key[l]],
                   u->key_indices[key[l]]);
        for (int l = 1; l < nk; l++)
            CHECK(u->key_indices[key[l]] < u->key_indices[key[l - 1]],
                  "block %d: LOD %d has %u indices, LOD %d %u", blk, l, u->key_indices[key[l]],
                  l - 1, u->key_indices[key[l - 1]]);
        for (int l = 0; l < nk && blk == 0; l++)
            CHECK(u->key_drawn[key[l]] > 0, "block %d: nothing drawn at LOD %d", blk, l);
        int bad = 0;
        for (int i = 0; i < n; i++) {
            double d = hypot(a[i].pos[0] - cam.position[0], a[i].pos[2] - cam.position[2]);
            for (int l = 0; l < nk; l++) {
                if (ka[i] != key[l])
                    continue;
                /* LOD l from its cell's nearest point on: 0, 14 m, 28 m */
                double lo = l == 0 ? 0 : l == 1 ? LOD_NEAR : 2 * LOD_NEAR;
                double hi = l == nk - 1 ? 1e9 : l == 0 ? LOD_NEAR : 2 * LOD_NEAR;
                bad += d < lo - 1e-3 || d > hi + CELL * sqrt(2.0) + 1e-3 ||
                       a[i].block != (uint32_t)blk;
            }
        }
        CHECK(bad == 0, "block %d: %d instances in the wrong LOD ring or key", blk, bad);
    }

    /* a second renderer: the same list, in the same order */
    rt_frame_stats st2;
    int m = frame_drawn(r2, &cam, &st2, b, kb);
    CHECK(m == n && memcmp(a, b, sizeof *a * (size_t)n) == 0 &&
              memcmp(ka, kb, sizeof *ka * (size_t)n) == 0,
          "a second renderer drew %d instances, not the same %d", m, n);

    /* turned round: nothing of the first view that the new one cannot see */
    rt_camera back = cam;
    back.look[0] = 2 * cam.position[0] - cam.look[0];
    back.look[2] = 2 * cam.position[2] - cam.look[2];
    int nb = frame_drawn(r1, &back, &st2, b, NULL), seen = 0, wrong = 0;
    for (int i = 0; i < nb; i++) {
        seen += in_view(&cam, &b[i], half);
        wrong += !in_view(&back, &b[i], half);
    }
    printf("turned round: %d drawn, %d of them inside the first view's (widened) field\n", nb,
           seen);
    CHECK(wrong == 0 && seen * 20 < n, "turned round: %d outside its view, %d of the first's", wrong,
          seen);

    float *img = kit_frame(r1, &cam, W, H);
    if (img)
        kit_write_picture(dir, "cull.png", img, W, H, SPLAT_VIEW_FINAL);
    free(img);
    rt_renderer_destroy(r1);
    rt_renderer_destroy(r2);
    free(a);
    free(b);
    free(ka);
    free(kb);
    free(sg);
    free(packdir);
    rt_pack_close(p);
    kit_device_close(dev);
    return kit_finish("ug_cull");
}
