/* points.c — checking the scene analysis at points (points.h). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "points.h"

uint32_t points_rnd(uint64_t *state)
{
    *state ^= *state << 13;
    *state ^= *state >> 7;
    *state ^= *state << 17;
    return (uint32_t)(*state >> 16);
}

double points_rnd01(uint64_t *state) { return points_rnd(state) / 4294967296.0; }

bool points_combo_has(const splat_combo *c, int material)
{
    for (int i = 0; i < c->nmaterials; i++)
        if (c->materials[i] == material)
            return true;
    return false;
}

void points_any_texture(void *user, int texture, double u, double v, double rgba[4])
{
    (void)user;
    uint32_t h = (uint32_t)texture * 0x9e3779b9u ^ (uint32_t)(int64_t)floor(u * 512) * 0x85ebca6bu ^
                 (uint32_t)(int64_t)floor(v * 512) * 0xc2b2ae35u;
    for (int c = 0; c < 4; c++) {
        h ^= h >> 15;
        h *= 0x2c1b3c6du;
        h ^= h >> 12;
        rgba[c] = (h & 0xffff) / 65535.0;
    }
}

double points_raster_bilinear(const uint8_t *px, int w, int h, double u, double v)
{
    double x = u * w - 0.5, z = v * h - 0.5;
    int ix = (int)floor(x), iz = (int)floor(z);
    double ax = x - ix, az = z - iz;
#define P(i, j) (px[(size_t)((j) < 0 ? 0 : (j) >= h ? h - 1 : (j)) * w + \
                    ((i) < 0 ? 0 : (i) >= w ? w - 1 : (i))] / 255.0)
    double a = P(ix, iz) + (P(ix + 1, iz) - P(ix, iz)) * ax;
    double b = P(ix, iz + 1) + (P(ix + 1, iz + 1) - P(ix, iz + 1)) * ax;
#undef P
    return a + (b - a) * az;
}

void points_env(const splat_terrain *t, double u, double v, ir_env *env)
{
    memset(env, 0, sizeof *env);
    env->height = splat_terrain_height(t, u, v);
    splat_terrain_normal(t, u, v, env->normal);
    env->cavity = splat_terrain_cavity(t, u, v);
    env->slope = 1 - env->normal[1];
    env->uv[0] = u;
    env->uv[1] = v;
    env->position[0] = u * t->size[0];
    env->position[1] = env->height;
    env->position[2] = v * t->size[1];
}

int points_check_sound(const splat_scene *s, const splat_analysis *a, int samples,
                       uint64_t *rng, points_painted_fn painted_at, void *user)
{
    const splat_terrain *t = &s->terrain;
    int n = s->nmaterials, checked = 0;
    ir_ref *masks = calloc((size_t)n, sizeof *masks);
    double *params = calloc((size_t)s->ir.nparams * 4 + 4, sizeof *params);
    double *painted = calloc((size_t)s->ir.npainted + 1, sizeof *painted);
    assert_true(masks && params && painted);
    for (int m = 0; m < n; m++) {
        char root[256];
        snprintf(root, sizeof root, "%s.mask", s->desc->materials[m]);
        masks[m] = ir_find_root(&s->ir, root);
        assert_true(ir_ref_ok(masks[m]));
    }
    int T = a->cell_texels;
    for (int cz = 0; cz < a->cells_z; cz++)
        for (int cx = 0; cx < a->cells_x; cx++) {
            const splat_combo *c = &a->combos[a->levels[0].ids[cz * a->cells_x + cx]];
            int x1 = (cx + 1) * T < t->width ? (cx + 1) * T : t->width;
            int z1 = (cz + 1) * T < t->height ? (cz + 1) * T : t->height;
            for (int k = 0; k < samples; k++) {
                double u = (cx * T + points_rnd01(rng) * (x1 - cx * T)) / t->width;
                double v = (cz * T + points_rnd01(rng) * (z1 - cz * T)) / t->height;
                ir_env env;
                points_env(t, u, v, &env);
                env.view_distance = points_rnd01(rng) * 5000;
                for (int p = 0; p < s->ir.nparams; p++) {
                    const ir_param *ip = &s->ir.params[p];
                    for (int q = 0; q < 4; q++)
                        params[4 * p + q] = ip->lo == ip->hi ? ip->def[q]
                                          : ip->lo + points_rnd01(rng) * (ip->hi - ip->lo);
                }
                env.params = params;
                for (int p = 0; p < s->ir.npainted; p++)
                    painted[p] = painted_at(user, p, u, v);
                env.painted = painted;
                env.sample = points_any_texture;
                double cover = 1;
                for (int m = n - 1; m >= 0 && cover > 0; m--) {
                    double mask[4] = { 1 };
                    if (m > 0)
                        ir_eval(&s->ir, masks[m], &env, mask);
                    double w = cover * mask[0];
                    if (w > 0 && !points_combo_has(c, m)) {
                        print_error("cell (%d, %d): '%s' visible (w = %g) at uv "
                                    "(%.9f, %.9f) but not in the combination\n", cx, cz,
                                    s->desc->materials[m], w, u, v);
                        fail();
                    }
                    cover -= w;
                }
                checked++;
            }
        }
    free(masks);
    free(params);
    free(painted);
    return checked;
}
