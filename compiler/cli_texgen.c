/* cli_texgen.c — `splatc texgen`: write the example textures.
 *
 *   splatc texgen --out DIR [--seed N] [--size N] [--all-mips]
 *                 [--surface-size N] [--sheet FILE.png]
 *
 * DIR is created if missing.  Same seed and size give the same files.  The
 * colour PBR surface sets (texgen_surfaces.c) go to DIR/surfaces/.
 */
#include "cli.h"
#include "texgen.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

static int usage(FILE *out, int status)
{
    fprintf(out,
            "usage: splatc texgen --out DIR [--seed N] [--size N] [--all-mips]\n"
            "                     [--surface-size N] [--sheet FILE.png]\n"
            "  Writes the example textures (tileable, deterministic) as PNG files:\n");
    for (int i = 0; i < texgen_example_count(); i++)
        fprintf(out, "    %-12s %s\n", texgen_example_name(i), texgen_example_about(i));
    fprintf(out, "  and into DIR/surfaces/ the colour PBR sets NAME_{albedo,normal,height,roughness,ao}.png:\n");
    for (int i = 0; i < texgen_surface_count(); i++)
        fprintf(out, "    %-12s %s\n", texgen_surface_name(i), texgen_surface_about(i));
    fprintf(out,
            "  --seed N     seed (default 1)\n"
            "  --size N     texels per side, a power of two 4..4096 (default 256)\n"
            "  --all-mips   also write box-filtered NAME.mipK.png files (by default\n"
            "               only textures whose mips must not be box-filtered get them)\n"
            "  --surface-size N  texels per side of the surface sets, a power of two\n"
            "               16..4096 (default 256)\n"
            "  --sheet FILE.png  also write the swatch sheet of the surface sets\n");
    return status;
}

static bool parse_uint(const char *s, unsigned long max, unsigned long *out)
{
    char *end;
    errno = 0;
    unsigned long v = strtoul(s, &end, 0);
    if (errno || end == s || *end || s[0] == '-' || v > max)
        return false;
    *out = v;
    return true;
}

int splat_cli_texgen(int argc, char **argv)
{
    const char *out = NULL;
    const char *sheet = NULL;
    unsigned long seed = 1, size = 256, ssize = 256;
    bool all_mips = false;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (!strcmp(a, "--help") || !strcmp(a, "-h"))
            return usage(stdout, 0);
        if (!strcmp(a, "--all-mips")) {
            all_mips = true;
        } else if ((!strcmp(a, "--out") || !strcmp(a, "-o")) && i + 1 < argc) {
            out = argv[++i];
        } else if (!strcmp(a, "--seed") && i + 1 < argc) {
            if (!parse_uint(argv[++i], 0xffffffffUL, &seed)) {
                fprintf(stderr, "splatc texgen: bad --seed '%s'\n", argv[i]);
                return 2;
            }
        } else if (!strcmp(a, "--size") && i + 1 < argc) {
            if (!parse_uint(argv[++i], 4096, &size) || size < 4 || (size & (size - 1))) {
                fprintf(stderr, "splatc texgen: --size must be a power of two 4..4096, not '%s'\n", argv[i]);
                return 2;
            }
        } else if (!strcmp(a, "--surface-size") && i + 1 < argc) {
            if (!parse_uint(argv[++i], 4096, &ssize) || ssize < 16 || (ssize & (ssize - 1))) {
                fprintf(stderr, "splatc texgen: --surface-size must be a power of two 16..4096, not '%s'\n", argv[i]);
                return 2;
            }
        } else if (!strcmp(a, "--sheet") && i + 1 < argc) {
            sheet = argv[++i];
        } else {
            fprintf(stderr, "splatc texgen: unexpected argument '%s'\n", a);
            return usage(stderr, 2);
        }
    }
    if (!out) {
        fprintf(stderr, "splatc texgen: --out DIR is required\n");
        return usage(stderr, 2);
    }
    if (mkdir(out, 0777) != 0 && errno != EEXIST) {
        fprintf(stderr, "splatc texgen: cannot create '%s': %s\n", out, strerror(errno));
        return 1;
    }
    char *err = NULL;
    if (!texgen_write_examples(out, (int)size, (uint32_t)seed, all_mips, stdout, &err)) {
        fprintf(stderr, "splatc texgen: %s\n", err ? err : "failed");
        free(err);
        return 1;
    }
    size_t n = strlen(out) + 16;
    char *sdir = malloc(n);
    if (!sdir)
        return 1;
    snprintf(sdir, n, "%s/surfaces", out);
    if (mkdir(sdir, 0777) != 0 && errno != EEXIST) {
        fprintf(stderr, "splatc texgen: cannot create '%s': %s\n", sdir, strerror(errno));
        free(sdir);
        return 1;
    }
    bool ok = texgen_write_surfaces(sdir, (int)ssize, (uint32_t)seed, stdout, &err);
    free(sdir);
    if (ok && sheet) {
        ok = texgen_write_sheet(sheet, (int)ssize, (uint32_t)seed, ssize < 96 ? (int)ssize : 96, &err);
        if (ok)
            printf("%s  swatch sheet\n", sheet);
    }
    if (!ok) {
        fprintf(stderr, "splatc texgen: %s\n", err ? err : "failed");
        free(err);
        return 1;
    }
    return 0;
}
