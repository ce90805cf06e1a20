/* cli_init.c — `splatc init DIR`: a starter project that builds and
 * renders as it stands, as `cargo new` does for a crate:
 *
 *   DIR/scene.sg         three materials (grass, rock on slopes, snow up
 *                        high) over the heightfield, a light with fog set
 *                        for this 1 km terrain, a camera
 *   DIR/heightfield.png  129 x 129 16-bit hills and a ridge (deterministic)
 *   DIR/README.md        five lines: build, render, look around
 *
 * Its imports are the node library's ("nodes/…"), which splatc and
 * splatview find from any folder (search.c: the installed share/splatc,
 * or the build tree's share/splatc beside the built tools).  DIR must not
 * exist, or be an empty folder; everything is written into DIR.tmp-XXXXXX
 * first and renamed, so a failure leaves nothing behind.
 */
#include "cli.h"
#include "texgen.h"
#include "util.h"

#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

enum { HF_N = 129 };   /* heightfield texels per side */

static const char scene_text[] =
    "# A starter scene written by `splatc init`: three materials over a small\n"
    "# heightfield, a light and a camera.  Build and render it:\n"
    "#   splatc build scene.sg -o pack\n"
    "#   splatview pack --headless -o scene.png\n"
    "import \"nodes/masks.sg\"          # ramp, slope_ramp, height_ramp, overlay\n"
    "import \"nodes/noise.sg\"          # value_fbm4\n"
    "import \"nodes/compositors.sg\"    # linear_alpha\n"
    "\n"
    "# Grass everywhere, its colour broken up by noise every ~40 m.\n"
    "material grass {\n"
    "    param vec3 colour = vec3(0.20, 0.33, 0.09)\n"
    "    node p : mul { a = terrain.position.xz, b = 0.025 }\n"
    "    node n : value_fbm4 { p = p.out }\n"
    "    node k : mix { a = 0.75, b = 1.2, t = n.out }\n"
    "    node c : mul { a = colour, b = k.out }\n"
    "    out albedo    = c.out\n"
    "    out roughness = 0.9\n"
    "}\n"
    "\n"
    "# Rock where the ground is steep (slope = 1 - normal.y).\n"
    "material rock {\n"
    "    node m : slope_ramp { lo = 0.12, hi = 0.22 }\n"
    "    out mask      = m.out\n"
    "    out albedo    = vec3(0.32, 0.30, 0.28)\n"
    "    out roughness = 0.8\n"
    "}\n"
    "\n"
    "# Snow above 145 m, fading in over 20 m.\n"
    "material snow {\n"
    "    param float line = 145 range 60 180\n"
    "    node t : add { a = line, b = 20 }\n"
    "    node m : height_ramp { lo = line, hi = t.out }\n"
    "    out mask      = m.out\n"
    "    out albedo    = vec3(0.85, 0.87, 0.90)\n"
    "    out roughness = 0.5\n"
    "}\n"
    "\n"
    "scene starter {\n"
    "    heightfield = \"heightfield.png\"    # 129 x 129, 16-bit greyscale\n"
    "    size = 1024 1024                   # metres, x and z\n"
    "    max_height = 180                   # metres at white\n"
    "    materials = [grass, rock, snow]    # bottom first\n"
    "    compositor = linear_alpha\n"
    "    # sun: azimuth and elevation in degrees; fog: per metre of view\n"
    "    light { sun = 140 30, fog_density = 0.0001, exposure = -0.5 }\n"
    "    camera overview { position = 512 380 1350, look = 512 40 420 }\n"
    "}\n";

static const char readme_text[] =
    "# A splatc starter project (written by `splatc init`)\n"
    "Build the shader pack: `splatc build scene.sg -o pack`\n"
    "Render a picture: `splatview pack --headless -o scene.png`\n"
    "Look around live, reloading as you edit scene.sg: `splatview pack --scene scene.sg`\n"
    "The language, the node library and the viewer: docs/getting-started.md in splatc.\n";

/* Height in metres (0 .. 180): rolling hills, a ridge across the north
 * with steep flanks and a snowy crest. */
static double height_at(int x, int z)
{
    double u = x / (double)(HF_N - 1), v = z / (double)(HF_N - 1);
    double h = 25 + 12 * sin(u * 6.0 + 0.4) * cos(v * 5.0 - 0.3) +
               14 * texgen_value_noise(x, z, 16) + 5 * texgen_value_noise(x, z, 5);
    double ridge = 0.32 + 0.08 * sin(u * 7.0);          /* the crest line, in v */
    double d = fabs(v - ridge) / 0.11;
    h += 130 * exp(-d * d) * (0.75 + 0.25 * sin(u * 9.0 + 1.0));
    return fmin(fmax(h, 0), 180);
}

static int fail(const char *dir, const char *what, const char *why)
{
    fprintf(stderr, "splatc init: error: cannot write '%s': %s%s%s\n", dir, what,
            why ? ": " : "", why ? why : "");
    return 1;
}

static bool write_text(const char *dir, const char *name, const char *text)
{
    char *path = splat_path_join(dir, name);
    bool ok = splat_write_atomic(path, text, strlen(text));
    free(path);
    return ok;
}

int splat_cli_init(int argc, char **argv)
{
    if (argc != 2 || argv[1][0] == '-') {
        fputs("usage: splatc init DIR\n"
              "  writes a starter project into DIR (which must not exist, or be\n"
              "  empty): scene.sg, heightfield.png and README.md\n", argc == 2 ? stdout : stderr);
        return argc == 2 && (!strcmp(argv[1], "--help") || !strcmp(argv[1], "-h")) ? 0 : 2;
    }
    char *dir = xstrdup(argv[1]);
    for (size_t n = strlen(dir); n > 1 && dir[n - 1] == '/'; n--)
        dir[n - 1] = 0;
    struct stat st;
    bool exists = stat(dir, &st) == 0;
    if (exists && (!S_ISDIR(st.st_mode) || rmdir(dir) != 0)) {
        /* rmdir: only an empty folder goes (and comes back renamed) */
        int st2 = fail(dir, "it exists and is not an empty folder", NULL);
        free(dir);
        return st2;
    }
    char *parent = splat_path_dir(dir);
    if (!splat_is_dir(parent)) {
        fprintf(stderr, "splatc init: error: cannot write '%s': its folder '%s' does not "
                "exist (create it first: mkdir -p '%s')\n", dir, parent, parent);
        free(parent);
        free(dir);
        return 1;
    }
    free(parent);
    char *tmp = xasprintf("%s.tmp-XXXXXX", dir);
    if (!mkdtemp(tmp)) {
        int st2 = fail(dir, "a temporary folder beside it", strerror(errno));
        free(tmp);
        free(dir);
        return st2;
    }
    chmod(tmp, 0755);
    uint16_t *hf = xmalloc(sizeof *hf * HF_N * HF_N);
    for (int z = 0; z < HF_N; z++)
        for (int x = 0; x < HF_N; x++)
            hf[z * HF_N + x] = (uint16_t)lround(height_at(x, z) / 180.0 * 65535.0);
    char *hf_path = splat_path_join(tmp, "heightfield.png"), *err = NULL;
    bool ok = texgen_write_png16(hf_path, HF_N, HF_N, hf, &err);
    free(hf_path);
    free(hf);
    int status = 0;
    if (!ok) {
        status = fail(dir, "heightfield.png", err);
    } else if (!write_text(tmp, "scene.sg", scene_text) ||
               !write_text(tmp, "README.md", readme_text)) {
        status = fail(dir, "scene.sg or README.md", strerror(errno));
    } else if (rename(tmp, dir) != 0) {
        status = fail(dir, "renaming the new project into place", strerror(errno));
    }
    free(err);
    if (status) {
        if (exists)
            mkdir(dir, 0755);   /* the empty folder it was */
        char *f[] = { "heightfield.png", "scene.sg", "README.md" };
        for (int i = 0; i < 3; i++) {
            char *p = splat_path_join(tmp, f[i]);
            unlink(p);
            free(p);
        }
        rmdir(tmp);
    } else {
        printf("wrote %s/scene.sg, %s/heightfield.png and %s/README.md\n"
               "next:  splatc build %s/scene.sg -o %s/pack\n"
               "       splatview %s/pack --headless -o scene.png\n",
               dir, dir, dir, dir, dir, dir);
    }
    free(tmp);
    free(dir);
    return status;
}
