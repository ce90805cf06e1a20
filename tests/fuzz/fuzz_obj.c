/* fuzz_obj.c — libFuzzer target for the undergrowth's OBJ reader: the
 * bytes are the file (written to a temporary file, as splat_mesh_obj
 * reads a path), so the size bound, the line scan (splat_obj_scan: finite
 * numbers, vertex, corner and index limits), tinyobjloader's parse and the
 * triangulation all run; a mesh that loads is walked once. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

#include "mesh.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static char path[64];
    if (!path[0])
        snprintf(path, sizeof path, "/tmp/splat-fuzz-obj-%d.obj", (int)getpid());
    FILE *f = fopen(path, "wb");
    if (!f)
        return 0;
    fwrite(data, 1, size, f);
    fclose(f);
    splat_mesh m = {0};
    char *err = NULL;
    if (splat_mesh_obj(path, &m, &err)) {
        volatile float sum = 0;
        for (uint32_t i = 0; i < m.nv; i++)
            sum += m.v[i].pos[0] + m.v[i].pos[1] + m.v[i].pos[2] + m.v[i].uv[1];
        (void)sum;
        splat_mesh_free(&m);
    }
    free(err);
    return 0;
}
