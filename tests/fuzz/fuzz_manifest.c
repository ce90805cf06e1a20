/* fuzz_manifest.c — libFuzzer target for the pack loader (rt_pack_load):
 * the input is manifest.json of a pack folder that holds a real pack's
 * other files ($SPLAT_FUZZ_PACK, copied once into a temporary folder at
 * start; without it the folder is empty and only the manifest's own checks
 * run).  Every file read goes through the loader's checks as in splatview. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "rt_internal.h"

int LLVMFuzzerInitialize(int *argc, char ***argv);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static char dir[64], manifest[96];

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc;
    (void)argv;
    snprintf(dir, sizeof dir, "/tmp/splat-fuzz-pack-XXXXXX");
    if (!mkdtemp(dir))
        abort();
    const char *src = getenv("SPLAT_FUZZ_PACK");
    if (src && *src) {
        char cmd[1024];
        snprintf(cmd, sizeof cmd, "cp -r '%s'/. '%s'/", src, dir);
        if (system(cmd) != 0)
            abort();
    }
    snprintf(manifest, sizeof manifest, "%s/manifest.json", dir);
    return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    FILE *f = fopen(manifest, "wb");
    if (!f)
        return 0;
    fwrite(data, 1, size, f);
    fclose(f);
    rt_pack p;
    rt_error e = { 0 };
    if (rt_pack_load(&p, dir, &e)) {
        rt_pack_validate(&p, &e);   /* the shaders it names, read on first use */
        rt_pack_free(&p);
    }
    rt_error_clear(&e);
    return 0;
}
