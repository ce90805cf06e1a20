/* cli_texgen.c — `splatc texgen`: write the example textures.
 *
 *   splatc texgen --out DIR [options]      (the table `options` below)
 *
 * DIR is created if missing.  Same seed and size give the same files.  The
 * colour PBR surface sets (texgen_surfaces.c) go to DIR/surfaces/.
 */
#include "args.h"
#include "cli.h"
#include "texgen.h"

#include <errno.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

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

typedef struct texgen_opts {
    const char *out, *sheet;
    unsigned long seed, size, ssize;
    bool all_mips;
} texgen_opts;

static bool parse_seed(const char *v, void *o, splat_arg_why *why)
{
    (void)why;
    return parse_uint(v, 0xffffffffUL, &((texgen_opts *)o)->seed);
}

static bool parse_size(const char *v, void *o, splat_arg_why *why)
{
    unsigned long *n = &((texgen_opts *)o)->size;
    (void)why;
    return parse_uint(v, 4096, n) && *n >= 4 && !(*n & (*n - 1));
}

static bool parse_surface_size(const char *v, void *o, splat_arg_why *why)
{
    unsigned long *n = &((texgen_opts *)o)->ssize;
    (void)why;
    return parse_uint(v, 4096, n) && *n >= 16 && !(*n & (*n - 1));
}

#define F(field) offsetof(texgen_opts, field)
static const splat_arg options[] = {
    { "--out", SPLAT_ARG_STRING, "DIR", "the folder to write (created if missing)", F(out) },
    { "-o", SPLAT_ARG_STRING, "DIR", "the same as --out", F(out) },
    { "--seed", SPLAT_ARG_CUSTOM, "N", "seed (default 1)", .parse = parse_seed,
      .expects = "a seed 0..4294967295" },
    { "--size", SPLAT_ARG_CUSTOM, "N", "texels per side, a power of two 4..4096 (default 256)",
      .parse = parse_size, .expects = "a power of two 4..4096" },
    { "--all-mips", SPLAT_ARG_FLAG, NULL, "also write box-filtered NAME.mipK.png files (by "
      "default only textures whose mips must not be box-filtered get them)", F(all_mips) },
    { "--surface-size", SPLAT_ARG_CUSTOM, "N", "texels per side of the surface sets, a power "
      "of two 16..4096 (default 256)", .parse = parse_surface_size,
      .expects = "a power of two 16..4096" },
    { "--sheet", SPLAT_ARG_STRING, "FILE.png", "also write the swatch sheet of the surface "
      "sets", F(sheet) },
};
#undef F

/* The usage lines and the textures written (the examples' own table). */
static char *usage_text(void)
{
    char *text = NULL;
    size_t n = 0;
    FILE *f = open_memstream(&text, &n);
    if (!f)
        return NULL;
    fprintf(f, "usage: splatc texgen --out DIR [options]\n"
               "  Writes the example textures (tileable, deterministic) as PNG files:\n");
    for (int i = 0; i < texgen_example_count(); i++)
        fprintf(f, "    %-12s %s\n", texgen_example_name(i), texgen_example_about(i));
    fprintf(f, "  and into DIR/surfaces/ the colour PBR sets "
               "NAME_{albedo,normal,height,roughness,ao}.png:\n");
    for (int i = 0; i < texgen_surface_count(); i++)
        fprintf(f, "    %-12s %s\n", texgen_surface_name(i), texgen_surface_about(i));
    fclose(f);
    return text;
}

int splat_cli_texgen(int argc, char **argv)
{
    texgen_opts o = { .seed = 1, .size = 256, .ssize = 256 };
    char *text = usage_text();
    splat_args_desc d = { .prog = "splatc texgen", .usage = text, .args = options,
                          .nargs = (int)(sizeof options / sizeof options[0]), .column = 20 };
    int rc = splat_args_parse(&d, argc, argv, 1, &o);
    if (rc == 0 && !o.out) {
        fprintf(stderr, "splatc texgen: --out DIR is required\n");
        splat_args_help(&d, stderr);
        rc = 2;
    }
    free(text);
    if (rc)
        return rc == SPLAT_ARGS_HELP ? 0 : rc;
    const char *out = o.out, *sheet = o.sheet;
    unsigned long seed = o.seed, size = o.size, ssize = o.ssize;
    bool all_mips = o.all_mips;
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
