/* heightfield.c — the CPU's reading of a heightfield: the bilinear height
 * the shaders read, and a ray's first hit (picking).  Shared by the
 * shadow march (shadow.c), craters and the renderer's picking. */
#include "rt_internal.h"

#include <math.h>

/* Bilinear height (metres) at terrain-local (x, z), clamp to edge. */
static double height_at(const uint16_t *h, const rt_pack *p, double x, double z)
{
    double tx = x / p->size[0] * p->hf_width - 0.5, tz = z / p->size[1] * p->hf_height - 0.5;
    int x0 = (int)floor(tx), z0 = (int)floor(tz);
    double fx = tx - x0, fz = tz - z0;
    double v[4];
    for (int k = 0; k < 4; k++) {
        int xi = x0 + (k & 1), zi = z0 + (k >> 1);
        xi = xi < 0 ? 0 : xi >= p->hf_width ? p->hf_width - 1 : xi;
        zi = zi < 0 ? 0 : zi >= p->hf_height ? p->hf_height - 1 : zi;
        v[k] = h[(size_t)zi * (size_t)p->hf_width + (size_t)xi];
    }
    double s = (v[0] * (1 - fx) + v[1] * fx) * (1 - fz) + (v[2] * (1 - fx) + v[3] * fx) * fz;
    return s / 65535.0 * p->max_height + p->height_offset;
}

double rt_height_at(const uint16_t *heights, const rt_pack *p, double x, double z)
{
    return height_at(heights, p, x, z);
}

bool rt_heightfield_pick(const uint16_t *heights, const rt_pack *p, const double o[3],
                         const double dir[3], double hit[3])
{
    double len = sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
    if (!(len > 0))
        return false;
    double d[3] = { dir[0] / len, dir[1] / len, dir[2] / len };
    double step = 0.5 * fmin(p->size[0] / p->hf_width, p->size[1] / p->hf_height);
    double far = 4.0 * (p->size[0] + p->size[1] + p->max_height + fabs(p->height_offset));
    double prev = 0;
    for (double t = 0; t <= far; t += step) {
        double x = o[0] + d[0] * t, y = o[1] + d[1] * t, z = o[2] + d[2] * t;
        bool inside = x >= 0 && z >= 0 && x <= p->size[0] && z <= p->size[1];
        if (inside && y <= height_at(heights, p, x, z)) {
            double a = prev, b = t;   /* refine between the last two steps */
            for (int i = 0; i < 40; i++) {
                double m = 0.5 * (a + b);
                double mx = o[0] + d[0] * m, mz = o[2] + d[2] * m;
                if (o[1] + d[1] * m <= height_at(heights, p, mx, mz))
                    b = m;
                else
                    a = m;
            }
            hit[0] = o[0] + d[0] * b;
            hit[2] = o[2] + d[2] * b;
            hit[1] = height_at(heights, p, hit[0], hit[2]);
            return true;
        }
        prev = t;
        /* bigger steps high above the terrain */
        double above = y - (p->height_offset + p->max_height);
        if (above > step)
            t += above * 0.5;
    }
    return false;
}

