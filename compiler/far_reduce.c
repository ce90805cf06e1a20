/* far_reduce.c — far_atlas_reduce (far_atlas.h): atlas points to texels,
 * for both bakes.  Its own file, so the runtime's device bake links it
 * without the rest of the build (far_atlas.c and what it pulls in). */
#include "far_atlas.h"

#include <math.h>
#include <stddef.h>

enum { FAR_SS = FAR_ATLAS_SS };

void far_atlas_reduce(const float *points, int w, float *albedo, float *normal, float *rough)
{
    size_t nx = (size_t)FAR_SS * w;
    for (int x = 0; x < w; x++) {
        double al[3] = {0}, no[3] = {0}, ro = 0;
        int n = 0;
        for (int k = 0; k < FAR_SS * FAR_SS; k++) {
            const float *p = points + ((k / FAR_SS) * nx + (size_t)FAR_SS * x + k % FAR_SS) * 8;
            if (!(p[7] > 0.5f))
                continue;
            for (int c = 0; c < 3; c++) {
                al[c] += p[c];
                no[c] += p[3 + c];
            }
            ro += p[6];
            n++;
        }
        double len = sqrt(no[0] * no[0] + no[1] * no[1] + no[2] * no[2]);
        for (int c = 0; c < 3; c++) {
            albedo[3 * x + c] = n ? (float)(al[c] / n) : 0.0f;
            normal[3 * x + c] = len > 0 ? (float)(no[c] / len) : (float)(c == 1);
        }
        rough[x] = n ? (float)(ro / n) : 1.0f;
    }
}
