/* texture_mips.c — a texture's stored mip files, texgen.h's contract:
 * "X.mipK.ext" beside "X.ext" for K = 1, 2, ... while they exist and the
 * texture has levels below its base.  The inputs' list (build_inputs.c),
 * the pack writer and the far atlas read them.
 */
#include "build.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

/* A texture's stored mip files (texgen.h's contract): "X.mipK.ext" beside
 * "X.ext" for K = 1, 2, … while they exist.  build_mip_path(path, k) is that name
 * for any path (source or pack); build_mip_count(src) how many the source has. */
char *build_mip_path(const char *path, int k)
{
    const char *slash = strrchr(path, '/');
    const char *dot = strrchr(path, '.');
    if (!dot || (slash && dot < slash))
        return xasprintf("%s.mip%d", path, k);
    return xasprintf("%.*s.mip%d%s", (int)(dot - path), path, k, dot);
}

int build_mip_count(const char *src)
{
    /* never more than the texture has below its base (PACK.md "Limits") */
    long long w = 0, h = 0;
    int comp, levels = 0;
    bool is16;
    char why[256];
    FILE *f = splat_input_fopen(src, SPLAT_MAX_IMAGE_BYTES, why, sizeof why);
    if (f && splat_image_info(f, &w, &h, &comp, &is16))
        while ((w > h ? w : h) >> (levels + 1))
            levels++;
    if (f)
        fclose(f);
    int k = 0;
    for (;;) {
        char *p = build_mip_path(src, k + 1);
        struct stat st;
        bool there = stat(p, &st) == 0 && S_ISREG(st.st_mode);   /* stat: no open */
        free(p);
        if (!there || k >= levels)
            return k;
        k++;
    }
}
