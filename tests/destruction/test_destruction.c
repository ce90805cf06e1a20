/* test_destruction.c — the destruction mask end to end on a Vulkan device
 * (lavapipe here, SPLAT_VALIDATE=1: any validation message fails).
 *
 *   test_destruction PACK OUTDIR
 *
 * PACK is tests/destruction/scene.sg built by splatc: grass under
 * burnt_dirt, whose mask is 0 wherever terrain.destruction is below 0.02.
 * A scripted series of craters, then, from a camera straight above:
 *   - the mask view of burnt_dirt is 0 at every pixel whose ground point is
 *     farther than a pixel from every crater (other cells untouched) and
 *     above 0.5 near each accepted crater's centre;
 *   - the heightfield is lowered at the centres by about the depth, no
 *     texel outside the discs changed, and the GPU's texels equal the CPU's
 *     (the partial uploads landed);
 *   - the tiles allocated are exactly the cells the discs meet;
 *   - a crater outside the area is reported OUTSIDE and changes nothing;
 *   - with a pool of 4 tiles, a crater needing more is REFUSED with a
 *     warning on stderr, and changes neither the mask nor the heights,
 *     while a later crater over tiles it already has still works.
 * Pictures of the final and mask views go to OUTDIR. */
#include "kit.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

enum { W = 384, H = 384 };
static const double CAM_Y = 700.0, FOVY = M_PI / 3.0;

typedef struct scene {
    rt_device   *dev;
    rt_pack     *pack;
    rt_pack_info info;
    rt_renderer *r;
    rt_camera    cam;
    float       *rgba;
} scene;

/* The ground point under pixel (px, py) of the straight-down camera at
 * (cx, CAM_Y, cz) (render.c's matrix: image x = +x, image y = +z). */
static void ground_of_pixel(const scene *s, int px, int py, double *x, double *z)
{
    double t = 1.0 / tan(FOVY / 2.0), aspect = (double)W / H;
    double nx = (px + 0.5) / W * 2.0 - 1.0, ny = (py + 0.5) / H * 2.0 - 1.0;
    const uint16_t *h = rt_renderer_heights(s->r);
    double y = rt_height_at(h, s->pack, s->cam.position[0], s->cam.position[2]);
    for (int i = 0; i < 6; i++) {   /* the height under the point, iterated */
        double dist = CAM_Y - y;
        *x = s->cam.position[0] + nx * aspect / t * dist;
        *z = s->cam.position[2] + ny / t * dist;
        y = rt_height_at(h, s->pack, *x, *z);
    }
}

static bool render(scene *s, splat_view view, int material, const char *png)
{
    rt_error e = { 0 };
    rt_renderer_set_view(s->r, view, material);
    bool ok = rt_renderer_frame(s->r, &s->cam, NULL, &e) && rt_renderer_read(s->r, s->rgba, &e);
    if (ok && png) {
        uint8_t *px = malloc((size_t)W * H * 4);
        rt_tonemap_rgba8(s->rgba, W, H, rt_view_tonemap(view), px);
        ok = px && rt_write_png(png, px, W, H, &e);
        free(px);
    }
    if (!ok)
        fprintf(stderr, "render: %s\n", e.msg ? e.msg : "?");
    rt_error_clear(&e);
    return ok;
}

static bool open_scene(scene *s, const char *pack, int pool)
{
    rt_error e = { 0 };
    memset(s, 0, sizeof *s);
    if (!(s->pack = kit_pack(pack)) || !(s->dev = kit_device()))
        return false;
    s->info = kit_pack_info(s->pack);
    rt_render_desc rd = { .width = W, .height = H, .destruction_pool = pool };
    if (!rt_renderer_create(s->dev, s->pack, &rd, &s->r, &e)) {
        fprintf(stderr, "renderer: %s\n", e.msg);
        rt_error_clear(&e);
        return false;
    }
    s->cam = (rt_camera){ .position = { 512, CAM_Y, 512 }, .look = { 512, 0, 512 },
                          .fovy = FOVY };
    s->rgba = malloc((size_t)W * H * 16);
    return s->rgba != NULL;
}

static void close_scene(scene *s)
{
    free(s->rgba);
    rt_renderer_destroy(s->r);
    kit_device_close(s->dev);
    rt_pack_close(s->pack);
}

static bool crater(scene *s, rt_crater c, rt_crater_stats *st)
{
    rt_error e = { 0 };
    bool ok = rt_renderer_crater(s->r, &c, st, &e);
    if (!ok)
        fprintf(stderr, "crater: %s\n", e.msg);
    rt_error_clear(&e);
    printf("crater (%g, %g) r %g: result %d, %d cells, %d new tiles, %d texels, %.3f ms cpu "
           "(+%.3f ms waiting)\n", c.x, c.z, c.radius, st->result, st->cells, st->tiles_new,
           st->texels, st->cpu_ms, st->wait_ms);
    return ok;
}

/* Does the disc of c meet grid cell (x, z) of the test scene's area? */
static bool disc_meets_cell(const rt_crater *c, int x, int z)
{
    double x0 = 256 + 16.0 * x, z0 = 256 + 16.0 * z;
    double qx = fmin(fmax(c->x, x0), x0 + 16), qz = fmin(fmax(c->z, z0), z0 + 16);
    return (qx - c->x) * (qx - c->x) + (qz - c->z) * (qz - c->z) < c->radius * c->radius;
}

/* Checks the mask view against the accepted craters `ok` (n of them) and
 * the rejected ones `no`: 0 everywhere a pixel away from the accepted
 * ones, > 0.5 near their centres, 0 inside the rejected ones. */
static void check_mask(scene *s, const rt_crater *ok, int n, const rt_crater *no, int nno)
{
    double pixel_m = 2.0 * CAM_Y * tan(FOVY / 2.0) / H;   /* ground metres per pixel */
    int zero = 0, inside = 0, rejected = 0;
    double worst_out = 0, worst_in = 1;
    for (int py = 0; py < H; py++)
        for (int px = 0; px < W; px++) {
            double x, z;
            ground_of_pixel(s, px, py, &x, &z);
            double m = s->rgba[((size_t)py * W + px) * 4];
            double near = 1e30, core = 1e30;
            for (int i = 0; i < n; i++) {
                double d = hypot(x - ok[i].x, z - ok[i].z);
                near = fmin(near, d - ok[i].radius);
                core = fmin(core, d / ok[i].radius);
            }
            if (near > 2 * pixel_m) {
                zero++;
                worst_out = fmax(worst_out, m);
                bool in_no = false;
                for (int i = 0; i < nno; i++)
                    in_no |= hypot(x - no[i].x, z - no[i].z) < no[i].radius;
                rejected += in_no;
            }
            if (core < 0.4) {
                inside++;
                worst_in = fmin(worst_in, m);
            }
        }
    printf("mask view: %d pixels away from craters (max %.3g; %d inside refused or outside "
           "craters), %d near centres (min %.3f)\n", zero, worst_out, rejected, inside, worst_in);
    CHECK(worst_out == 0.0, "destruction material outside the craters: %g", worst_out);
    CHECK(worst_in > 0.5, "crater centres show mask %g", worst_in);
    CHECK(inside > 0 || n == 0, "no pixel near a crater centre was checked");
    CHECK(nno == 0 || rejected > 0, "no pixel inside a refused crater was checked");
}

/* Heights: lowered at the accepted centres, unchanged outside every
 * accepted disc, and the GPU's copy equal to the CPU's. */
static void check_heights(scene *s, const uint16_t *before, const rt_crater *ok, int n)
{
    const rt_pack *pack = s->pack;
    const rt_pack_info *p = &s->info;
    const uint16_t *now = rt_renderer_heights(s->r);
    int changed = 0, stray = 0;
    for (int z = 0; z < p->hf_height; z++)
        for (int x = 0; x < p->hf_width; x++) {
            size_t i = (size_t)z * p->hf_width + x;
            if (now[i] == before[i])
                continue;
            changed++;
            double wx = (x + 0.5) * p->size[0] / p->hf_width;
            double wz = (z + 0.5) * p->size[1] / p->hf_height;
            bool in = false;
            for (int k = 0; k < n; k++)
                in |= hypot(wx - ok[k].x, wz - ok[k].z) < ok[k].radius;
            stray += !in;
            CHECK(now[i] < before[i], "texel (%d, %d) was raised", x, z);
        }
    CHECK(stray == 0, "%d texels changed outside every crater", stray);
    for (int k = 0; k < n; k++) {
        double h0 = rt_height_at(before, pack, ok[k].x, ok[k].z);
        double h1 = rt_height_at(now, pack, ok[k].x, ok[k].z);
        printf("crater (%g, %g): centre lowered %.3f m (depth %.3f)\n", ok[k].x, ok[k].z,
               h0 - h1, ok[k].depth);
        CHECK(h0 - h1 > 0.7 * ok[k].depth && h0 - h1 <= ok[k].depth * 1.5 + 0.01,
              "crater (%g, %g) lowered by %g m, depth %g", ok[k].x, ok[k].z, h0 - h1,
              ok[k].depth);
    }
    uint16_t *gpu = malloc((size_t)p->hf_width * p->hf_height * 2);
    rt_error e = { 0 };
    bool read = gpu && rt_renderer_read_heights(s->r, gpu, &e);
    CHECK(read, "read heights: %s", e.msg ? e.msg : "?");
    rt_error_clear(&e);
    if (read)
        CHECK(memcmp(gpu, now, (size_t)p->hf_width * p->hf_height * 2) == 0,
              "the GPU heightfield differs from the CPU's");
    printf("heights: %d texels lowered, none outside the craters; GPU copy equal\n", changed);
    free(gpu);
}

int main(int argc, char **argv)
{
    if (argc != 3) {
        fprintf(stderr, "usage: test_destruction PACK OUTDIR\n");
        return 2;
    }
    char path[4096];
    scene s;
    if (!open_scene(&s, argv[1], 0))
        return 1;
    int burnt = rt_pack_material_find(s.pack, "burnt_dirt");
    CHECK(burnt > 0, "the pack has no burnt_dirt");
    size_t nt = (size_t)s.info.hf_width * s.info.hf_height;
    uint16_t *before = malloc(nt * 2);
    memcpy(before, rt_pack_heights(s.pack), nt * 2);

    /* nothing destroyed yet: the mask is 0 everywhere */
    CHECK(render(&s, SPLAT_VIEW_MASK, burnt, NULL), "render");
    check_mask(&s, NULL, 0, NULL, 0);

    const rt_crater script[] = {
        { 320, 330, 24, 6, 1 }, { 500, 420, 30, 8, 1 }, { 600, 600, 20, 5, 1 },
        { 618, 612, 20, 5, 1 },                  /* overlaps the one before */
        { 700, 330, 25, 6, 1 }, { 360, 690, 18, 4, 1 },
    };
    const int n = (int)(sizeof script / sizeof script[0]);
    rt_crater_stats st;
    double max_ms = 0;
    int expect_tiles = 0;
    bool has_tile[32][32] = { { false } };
    for (int i = 0; i < n; i++) {
        CHECK(crater(&s, script[i], &st), "crater %d", i);
        CHECK(st.result == RT_CRATER_DONE, "crater %d: result %d", i, st.result);
        max_ms = fmax(max_ms, st.cpu_ms);
        int cells = 0, fresh = 0;
        for (int z = 0; z < 32; z++)
            for (int x = 0; x < 32; x++)
                if (disc_meets_cell(&script[i], x, z)) {
                    cells++;
                    fresh += !has_tile[z][x];
                    has_tile[z][x] = true;
                }
        expect_tiles += fresh;
        CHECK(st.cells == cells && st.tiles_new == fresh,
              "crater %d: %d cells / %d new tiles, expected %d / %d", i, st.cells,
              st.tiles_new, cells, fresh);
    }
    CHECK(st.tiles_used == expect_tiles, "%d tiles used, expected %d", st.tiles_used, expect_tiles);
    rt_crater away = { 190, 500, 20, 5, 1 };   /* west of the area, in view */
    CHECK(crater(&s, away, &st) && st.result == RT_CRATER_OUTSIDE, "outside: %d", st.result);
    printf("crater events: max %.3f ms cpu (target < 1 ms; not a timed test)\n", max_ms);

    snprintf(path, sizeof path, "%s/mask.png", argv[2]);
    CHECK(render(&s, SPLAT_VIEW_MASK, burnt, path), "render");
    check_mask(&s, script, n, &away, 1);
    check_heights(&s, before, script, n);
    snprintf(path, sizeof path, "%s/final.png", argv[2]);
    CHECK(render(&s, SPLAT_VIEW_FINAL, 0, path), "render");
    close_scene(&s);

    /* A pool of 4 tiles: a crater over 4 cells fits, the next is refused. */
    if (!open_scene(&s, argv[1], 4))
        return 1;
    rt_crater fits = { 256 + 16 * 10, 256 + 16 * 10, 10, 4, 1 };   /* a cell corner */
    rt_crater refused = { 560, 420, 12, 4, 1 };
    rt_crater again = { 256 + 16 * 10 + 2, 256 + 16 * 10 - 2, 6, 3, 1 };
    CHECK(crater(&s, fits, &st) && st.result == RT_CRATER_DONE && st.tiles_used == 4,
          "4-cell crater: result %d, %d tiles", st.result, st.tiles_used);
    memcpy(before, rt_renderer_heights(s.r), nt * 2);
    snprintf(path, sizeof path, "%s/stderr.txt", argv[2]);
    fflush(stderr);
    int saved = dup(2);
    FILE *log = freopen(path, "w", stderr);
    bool done = crater(&s, refused, &st);
    fflush(stderr);
    dup2(saved, 2);
    close(saved);
    CHECK(log && done && st.result == RT_CRATER_REFUSED, "full pool: result %d", st.result);
    FILE *f = fopen(path, "r");
    char msg[512] = "";
    size_t got = f ? fread(msg, 1, sizeof msg - 1, f) : 0;
    msg[got] = 0;
    if (f)
        fclose(f);
    printf("refused crater's warning: %s", msg);
    CHECK(strstr(msg, "pool exhausted") && strstr(msg, "refused"), "no clear warning: '%s'", msg);
    CHECK(memcmp(before, rt_renderer_heights(s.r), nt * 2) == 0,
          "a refused crater changed the heights");
    CHECK(crater(&s, again, &st) && st.result == RT_CRATER_DONE && st.tiles_new == 0,
          "a crater over allocated tiles: result %d", st.result);
    rt_crater kept[2] = { fits, again };
    CHECK(render(&s, SPLAT_VIEW_MASK, burnt, NULL), "render");
    check_mask(&s, kept, 2, &refused, 1);
    close_scene(&s);
    free(before);
    return kit_finish("destruction");
}
