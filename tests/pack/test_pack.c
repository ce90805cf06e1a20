/* test_pack.c — `splatc build` end to end on examples/minimal: the pack's
 * manifest and grid, every shader through glslangValidator and spirv-val,
 * byte-identical rebuilds, incremental rebuilds through the cache, and bad
 * scenes that must leave an existing pack untouched.
 *
 * Usage: test_pack SPLATC (run from the repository root). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <dirent.h>
#include <glob.h>
#include <jansson.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

static const char *splatc;   /* the CLI under test                         */
static char tmp[64];         /* scratch folder of this run                 */

/* Run a shell command; its stdout + stderr into *out (if non-NULL). */
static int run(char **out, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static int run(char **out, const char *fmt, ...)
{
    char cmd[4096];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(cmd, sizeof cmd, fmt, ap);
    va_end(ap);
    char full[4200];
    snprintf(full, sizeof full, "(%s) 2>&1", cmd);
    FILE *p = popen(full, "r");
    assert_non_null(p);
    size_t cap = 4096, n = 0;
    char *buf = malloc(cap);
    size_t got;
    while ((got = fread(buf + n, 1, cap - n - 1, p)) > 0) {
        n += got;
        if (n + 1 == cap)
            buf = realloc(buf, cap *= 2);
    }
    buf[n] = 0;
    int st = pclose(p);
    if (out)
        *out = buf;
    else
        free(buf);
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

/* Build `scene` into `pack` with the given extra options; the output.
 * (Not inlined: GCC 12's -Wdangling-pointer then mistakes pointers into
 * the returned text for pointers to the local `out`.) */
__attribute__((noinline))
static char *build(int expect, const char *scene, const char *pack, const char *opts)
{
    char *out;
    int rc = run(&out, "'%s' build '%s' -o '%s' %s", splatc, scene, pack, opts);
    if (rc != expect)
        fail_msg("splatc build %s -> %s: exit %d, expected %d\n%s", scene, pack, rc, expect,
                 out);
    return out;
}

/* "combinations: N (A from cache, B compiled)" of --stats. */
static void stats_line(const char *out, const char *what, int *n, int *cached, int *compiled)
{
    char key[32];
    snprintf(key, sizeof key, "\n%s: ", what);
    const char *p = strstr(out, "phase ");  /* after the analysis report */
    p = p ? strstr(p, key) : NULL;
    if (!p)
        fail_msg("no '%s' line in:\n%s", what, out);
    assert_int_equal(sscanf(p + strlen(key), "%d (%d from cache, %d compiled)", n, cached,
                            compiled), 3);
}

/* The report of --stats before the phase times, without the line that
 * times the analysis (malloc'd). */
static char *stats_report(const char *out)
{
    const char *end = strstr(out, "phase ");
    assert_non_null(end);
    char *r = calloc(1, (size_t)(end - out) + 1);
    assert_non_null(r);
    for (const char *p = out; p < end;) {
        const char *nl = memchr(p, '\n', (size_t)(end - p));
        size_t len = nl ? (size_t)(nl - p) + 1 : (size_t)(end - p);
        if (strncmp(p, "analysis time:", 14))
            strncat(r, p, len);
        p += len;
    }
    return r;
}

static json_t *load_manifest(const char *pack)
{
    char path[256];
    snprintf(path, sizeof path, "%s/manifest.json", pack);
    json_error_t err;
    json_t *m = json_load_file(path, JSON_STRICT, &err);
    if (!m)
        fail_msg("%s:%d: %s", path, err.line, err.text);
    return m;
}

static long file_size(const char *pack, const char *name)
{
    char path[512];
    snprintf(path, sizeof path, "%s/%s", pack, name);
    struct stat sb;
    return stat(path, &sb) == 0 ? (long)sb.st_size : -1;
}

static int geti(json_t *o, const char *key)
{
    json_t *v = json_object_get(o, key);
    assert_true(json_is_integer(v));
    return (int)json_integer_value(v);
}

/* ---- tests ------------------------------------------------------------------ */

static char pack_a[128];

static void test_manifest_and_grid(void **state)
{
    snprintf(pack_a, sizeof pack_a, "%s/a", tmp);
    char opts[256];
    snprintf(opts, sizeof opts, "--cache '%s/cache' -j 2 --stats", tmp);
    free(build(0, "examples/minimal/scene.sg", pack_a, opts));
    json_t *m = load_manifest(pack_a);
    assert_string_equal(json_string_value(json_object_get(m, "format")), "splatc-pack");
    json_t *scene = json_object_get(m, "scene");
    json_t *hf = json_object_get(scene, "heightfield");
    int W = geti(hf, "width"), H = geti(hf, "height");
    assert_int_equal(file_size(pack_a, "heightfield.r16"), 2L * W * H);
    int cell = geti(scene, "cell_texels");
    assert_true(cell > 0);

    int nmat = (int)json_array_size(json_object_get(m, "materials"));
    json_t *combos = json_object_get(m, "combinations");
    int ncombos = (int)json_array_size(combos);
    assert_true(ncombos >= 2);
    for (int i = 0; i < ncombos; i++) {
        json_t *c = json_array_get(combos, i);
        assert_int_equal(geti(c, "id"), i);
        json_t *mats = json_object_get(c, "materials");
        assert_true(json_array_size(mats) >= 1);
        for (size_t k = 0; k < json_array_size(mats); k++) {
            json_int_t mi = json_integer_value(json_array_get(mats, k));
            assert_true(mi >= 0 && mi < nmat);
        }
        assert_true(file_size(pack_a, json_string_value(json_object_get(c, "glsl"))) > 0);
        assert_true(file_size(pack_a, json_string_value(json_object_get(c, "spirv"))) > 0);
        /* the compute variant: its GLSL and, by default, its SPIR-V made
         * at build time (PACK.md, issue 29: nothing compiled at load); a
         * positive cost */
        json_t *cx = json_object_get(c, "compute");
        const char *comp = json_string_value(json_object_get(cx, "glsl"));
        assert_non_null(comp);
        assert_true(file_size(pack_a, comp) > 0);
        const char *cspv = json_string_value(json_object_get(cx, "spirv"));
        assert_non_null(cspv);
        assert_true(file_size(pack_a, cspv) > 0);
        assert_int_equal(strlen(json_string_value(json_object_get(cx, "hash"))), 32);
        assert_true(json_real_value(json_object_get(c, "cost")) > 0);
    }
    assert_true(file_size(pack_a, json_string_value(json_object_get(
                    json_object_get(json_object_get(m, "uber"), "compute"), "glsl"))) > 0);

    /* the leaf grid covers the heightfield; each level halves (rounding up)
     * down to one node; combos.bin holds exactly the levels; ids in range */
    json_t *qt = json_object_get(m, "quadtree");
    json_t *levels = json_object_get(qt, "levels");
    int nl = (int)json_array_size(levels);
    assert_true(nl >= 1);
    json_t *l0 = json_array_get(levels, 0);
    int w0 = geti(l0, "width"), h0 = geti(l0, "height");
    assert_true((long)w0 * cell >= W && (long)(w0 - 1) * cell < W);
    assert_true((long)h0 * cell >= H && (long)(h0 - 1) * cell < H);
    long total = 0;
    int pw = 0, ph = 0;
    for (int l = 0; l < nl; l++) {
        json_t *lv = json_array_get(levels, l);
        int w = geti(lv, "width"), h = geti(lv, "height");
        if (l > 0) {
            assert_int_equal(w, (pw + 1) / 2);
            assert_int_equal(h, (ph + 1) / 2);
        }
        assert_int_equal(geti(lv, "offset"), total);
        total += 2L * w * h;
        pw = w;
        ph = h;
    }
    assert_int_equal(pw, 1);
    assert_int_equal(ph, 1);
    char path[256];
    snprintf(path, sizeof path, "%s/%s", pack_a,
             json_string_value(json_object_get(qt, "file")));
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    uint8_t *ids = malloc((size_t)total);
    assert_int_equal(fread(ids, 1, (size_t)total + 1, f), (size_t)total);
    fclose(f);
    /* coarse nodes (past level 0) may have no combination: compositions
     * come from leaf cells only (analysis.c) */
    long leaf = 2L * w0 * h0;
    for (long i = 0; i < total; i += 2) {
        int id = ids[i] + 256 * ids[i + 1];
        assert_true(id < ncombos || (i >= leaf && id == 0xFFFE)   /* SPLAT_COMBO_UBER */);
    }
    free(ids);
    json_decref(m);
}

/* The pack's shader files are zstd frames (PACK.md "Compressed shaders"):
 * each is checked as the file it holds, written beside it without ".zst". */
static void test_shaders_validate(void **state)
{
    char pattern[256];
    glob_t g;
    snprintf(pattern, sizeof pattern, "%s/shaders/*.spv.zst", pack_a);
    assert_int_equal(glob(pattern, 0, NULL, &g), 0);
    assert_true(g.gl_pathc >= 5);  /* composites, refs, uber, vertex */
    for (size_t i = 0; i < g.gl_pathc; i++) {
        char *out;
        if (run(&out, "zstd -q -dc '%s' > '%s/check.spv' && "
                      "spirv-val --target-env vulkan1.2 '%s/check.spv'",
                g.gl_pathv[i], tmp, tmp) != 0)
            fail_msg("spirv-val %s:\n%s", g.gl_pathv[i], out);
        free(out);
    }
    globfree(&g);
    snprintf(pattern, sizeof pattern, "%s/shaders/*.frag.zst", pack_a);
    assert_int_equal(glob(pattern, 0, NULL, &g), 0);
    snprintf(pattern, sizeof pattern, "%s/shaders/*.vert.zst", pack_a);
    assert_int_equal(glob(pattern, GLOB_APPEND, NULL, &g), 0);
    snprintf(pattern, sizeof pattern, "%s/shaders/*.comp.zst", pack_a);
    assert_int_equal(glob(pattern, GLOB_APPEND, NULL, &g), 0);
    for (size_t i = 0; i < g.gl_pathc; i++) {
        const char *f = g.gl_pathv[i];
        size_t len = strlen(f);
        const char *ext = f + len - 9;   /* ".frag.zst" */
        char *out;
        if (run(&out, "zstd -q -dc '%s' > '%s/check%.5s' && "
                      "glslangValidator -V --target-env vulkan1.2 -o /dev/null '%s/check%.5s'",
                f, tmp, ext, tmp, ext) != 0)
            fail_msg("glslangValidator %s:\n%s", f, out);
        free(out);
    }
    globfree(&g);
    (void)state;
}

/* Same inputs, same bytes: with a cold cache, without one, and again. */
static void test_byte_identical(void **state)
{
    char b[160], c[160], opts[256];
    snprintf(b, sizeof b, "%s/b", tmp);
    snprintf(c, sizeof c, "%s/c", tmp);
    snprintf(opts, sizeof opts, "--cache '%s/cache-b'", tmp);
    free(build(0, "examples/minimal/scene.sg", b, opts));
    free(build(0, "examples/minimal/scene.sg", c, "--no-cache -j 2"));
    char *out;
    if (run(&out, "diff -r '%s' '%s' && diff -r '%s' '%s'", pack_a, b, pack_a, c) != 0)
        fail_msg("packs differ:\n%s", out);
    free(out);
    /* rebuilding over an existing pack replaces it with the same bytes
     * (named with a trailing slash: the swap happens beside it, not in it) */
    char bslash[170];
    snprintf(bslash, sizeof bslash, "%s/", b);
    free(build(0, "examples/minimal/scene.sg", bslash, "--no-cache"));
    assert_int_equal(run(NULL, "diff -r '%s' '%s'", pack_a, b), 0);
}

static void replace_in_file(const char *path, const char *from, const char *to)
{
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    char *text = calloc(1, 1 << 20);
    size_t n = fread(text, 1, (1 << 20) - 1, f);
    fclose(f);
    char *at = strstr(text, from);
    assert_non_null(at);
    assert_null(strstr(at + 1, from));  /* exactly one place */
    f = fopen(path, "wb");
    assert_non_null(f);
    fwrite(text, 1, (size_t)(at - text), f);
    fputs(to, f);
    fputs(at + strlen(from), f);
    fclose(f);
    (void)n;
    free(text);
}

/* Damages file `path` in place: the byte at `at` xor `mask`. */
static void flip_byte(const char *path, long at, int mask)
{
    FILE *f = fopen(path, "r+b");
    assert_non_null(f);
    fseek(f, at, SEEK_SET);
    int byte = fgetc(f);
    assert_true(byte != EOF);
    fseek(f, at, SEEK_SET);
    fputc(byte ^ mask, f);
    fclose(f);
}

/* The SPIR-V modules a manifest entry names: its "spirv" and those of
 * the objects and arrays inside it (compute variant, undergrowth masks,
 * distance classes). */
static int spirv_count(json_t *v)
{
    int n = 0;
    if (json_is_object(v)) {
        const char *k;
        json_t *x;
        json_object_foreach(v, k, x)
            n += !strcmp(k, "spirv") ? json_is_string(x) : spirv_count(x);
    } else if (json_is_array(v)) {
        for (size_t i = 0; i < json_array_size(v); i++)
            n += spirv_count(json_array_get(v, i));
    }
    return n;
}

/* Touching a graph recompiles nothing; editing one material recompiles
 * exactly the combinations that contain it (plus its reference pass and
 * the über-shader), and gives the pack a cold build gives. */
static void test_incremental(void **state)
{
    char root[160], scene[256], pack[200], cold[200], opts[256];
    snprintf(root, sizeof root, "%s/tree", tmp);
    assert_int_equal(run(NULL, "mkdir -p '%s/examples' && cp -r nodes graphs '%s/' && "
                               "cp -r examples/minimal '%s/examples/'", root, root, root), 0);
    snprintf(scene, sizeof scene, "%s/examples/minimal/scene.sg", root);
    snprintf(pack, sizeof pack, "%s/inc", tmp);
    snprintf(cold, sizeof cold, "%s/inc-cold", tmp);
    snprintf(opts, sizeof opts, "--cache '%s/cache-inc' --stats", tmp);

    char *out = build(0, scene, pack, opts);
    int n, cached, compiled;
    stats_line(out, "combinations", &n, &cached, &compiled);
    assert_int_equal(cached, 0);
    assert_int_equal(compiled, n);
    char *report = stats_report(out);
    free(out);

    /* touched, not changed: the pack is up to date, nothing is rebuilt,
     * and --stats still prints the same report (analysis, painted masks,
     * shaders) and the phase times */
    assert_int_equal(run(NULL, "touch '%s' '%s/graphs/grass.sg'", scene, root), 0);
    out = build(0, scene, pack, opts);
    if (!strstr(out, "pack up to date"))
        fail_msg("touched scene rebuilt:\n%s", out);
    char *again = stats_report(out);
    if (strcmp(report, again))
        fail_msg("the up-to-date report differs:\n%s\n--- the build's:\n%s", again, report);
    assert_non_null(strstr(again, "\ncells: "));
    assert_non_null(strstr(again, "\nmean composite size: "));
    assert_non_null(strstr(out, "\nanalysis "));
    assert_non_null(strstr(out, "\ntotal "));
    free(report);
    free(again);
    free(out);

    /* a new pack from the same cache: every shader from the cache */
    char pack2[200];
    snprintf(pack2, sizeof pack2, "%s/inc2", tmp);
    out = build(0, scene, pack2, opts);
    stats_line(out, "combinations", &n, &cached, &compiled);
    assert_int_equal(compiled, 0);
    assert_int_equal(cached, n);
    int ns, scached, scompiled;
    stats_line(out, "shaders", &ns, &scached, &scompiled);
    assert_int_equal(scompiled, 0);
    free(out);
    assert_int_equal(run(NULL, "diff -r '%s' '%s'", pack, pack2), 0);

    /* which combinations hold the rock material */
    json_t *m = load_manifest(pack);
    json_t *mats = json_object_get(m, "materials");
    int rock = -1;
    for (size_t i = 0; i < json_array_size(mats); i++)
        if (!strcmp(json_string_value(json_object_get(json_array_get(mats, i), "name")),
                    "rock"))
            rock = (int)i;
    assert_true(rock >= 0);
    json_t *combos = json_object_get(m, "combinations");
    int with_rock = 0, rock_modules = 0;   /* the modules of those combinations */
    char kept[256] = "", changed[256] = "";  /* a file of one without rock, and with */
    for (size_t i = 0; i < json_array_size(combos); i++) {
        json_t *cm = json_object_get(json_array_get(combos, i), "materials");
        int has = 0;
        for (size_t k = 0; k < json_array_size(cm); k++)
            has += json_integer_value(json_array_get(cm, k)) == rock;
        with_rock += has;
        if (has)
            rock_modules += spirv_count(json_array_get(combos, i));
        snprintf(has ? changed : kept, sizeof kept, "%s/%s", pack, json_string_value(
                 json_object_get(json_array_get(combos, i), "spirv")));
    }
    assert_true(kept[0] && changed[0]);
    struct stat kept_before, changed_before, hf_before;
    char hf[256];
    snprintf(hf, sizeof hf, "%s/heightfield.r16", pack);
    assert_int_equal(stat(kept, &kept_before), 0);
    assert_int_equal(stat(changed, &changed_before), 0);
    assert_int_equal(stat(hf, &hf_before), 0);
    char count_cmd[300];
    snprintf(count_cmd, sizeof count_cmd, "find '%s' -type f | wc -l", pack);
    char *count = NULL;
    assert_int_equal(run(&count, "%s", count_cmd), 0);
    int nfiles = atoi(count);
    free(count);
    /* an old pack file that is not what it should be is never kept: that
     * combination's GLSL, one byte changed (the cold pack's diff below) */
    char damaged[300];
    snprintf(damaged, sizeof damaged, "%.*s.frag.zst", (int)(strlen(kept) - 8), kept);
    assert_true(strstr(damaged, ".frag.zst") && !strstr(damaged, ".spv"));
    flip_byte(damaged, 20, 0x10);
    /* + rock's reference pass and the über-shader's fragment and compute;
     * not its stand-ins (PACK.md "Stand-ins"): their text is the
     * über-shader's head and prelude, which a material's colour does not
     * change, so they come from the cache */
    json_t *uber = json_object_get(m, "uber");
    assert_int_equal(spirv_count(json_object_get(uber, "stand_in")), 1);   /* flat: no atlas */
    rock_modules += 1 + spirv_count(uber) - spirv_count(json_object_get(uber, "stand_in"));
    json_decref(m);
    assert_true(with_rock >= 1 && with_rock < n);

    replace_in_file(scene, "out roughness = 0.8", "out roughness = 0.7");
    out = build(0, scene, pack, opts);
    stats_line(out, "combinations", &n, &cached, &compiled);
    assert_int_equal(compiled, with_rock);
    assert_int_equal(cached, n - with_rock);
    stats_line(out, "shaders", &ns, &scached, &scompiled);
    assert_int_equal(scompiled, rock_modules);
    /* a constant edit: every recompiled module's shape passed spirv-val in
     * the first build, so none is validated again (cache.h) */
    const char *sv = strstr(out, "\nspirv-val: ");
    assert_non_null(sv);
    int validated = -1, known = -1;
    assert_int_equal(sscanf(sv, "\nspirv-val: %d modules validated, %d of known shape",
                            &validated, &known), 2);
    assert_int_equal(validated, 0);
    assert_int_equal(known, rock_modules);
    /* only what changed is written: each recompiled module's SPIR-V and
     * GLSL (a reference pass has no GLSL) and the manifest; every other
     * file is the old pack's, linked (pack_write.c) */
    const char *pf = strstr(out, "\npack files: ");
    assert_non_null(pf);
    int written = -1, nkept = -1;
    assert_int_equal(sscanf(pf, "\npack files: %d written, %d kept", &written, &nkept), 2);
    assert_int_equal(written, 2 * rock_modules - 1 + 1 + 1);   /* + the damaged one */
    assert_int_equal(written + nkept, nfiles);
    struct stat kept_after, changed_after, hf_after;
    assert_int_equal(stat(kept, &kept_after), 0);
    assert_int_equal(stat(changed, &changed_after), 0);
    assert_int_equal(stat(hf, &hf_after), 0);
    assert_true(kept_after.st_ino == kept_before.st_ino);
    assert_true(hf_after.st_ino == hf_before.st_ino);
    assert_true(changed_after.st_ino != changed_before.st_ino);
    free(out);

    free(build(0, scene, cold, "--no-cache"));
    if (run(&out, "diff -r '%s' '%s'", pack, cold) != 0)
        fail_msg("cached and cold packs differ:\n%s", out);
    free(out);

    /* a damaged cache entry (combination 0's) is a miss, compiled afresh */
    m = load_manifest(pack);
    const char *key = json_string_value(
        json_object_get(json_array_get(json_object_get(m, "combinations"), 0), "hash"));
    assert_non_null(key);
    char entry[400];
    snprintf(entry, sizeof entry, "%s/cache-inc/spv1/%.2s/%s.spv", tmp, key, key);
    json_decref(m);
    flip_byte(entry, 40, 0x40);
    char pack3[200];
    snprintf(pack3, sizeof pack3, "%s/inc3", tmp);
    out = build(0, scene, pack3, opts);
    stats_line(out, "combinations", &n, &cached, &compiled);
    assert_int_equal(compiled, 1);
    free(out);
    assert_int_equal(run(NULL, "diff -r '%s' '%s'", pack, pack3), 0);
}

/* Each bad scene: exit 1, a file:line:col error, the pack untouched and no
 * temporary folder left behind. */
static void test_bad_scenes_leave_pack(void **state)
{
    char snap[160];
    snprintf(snap, sizeof snap, "%s/a-snapshot", tmp);
    assert_int_equal(run(NULL, "cp -r '%s' '%s'", pack_a, snap), 0);

    /* a negative world size, next to the fixtures it imports */
    char neg[160];
    snprintf(neg, sizeof neg, "tests/scene/bad_size.sg");
    char negative[200];
    snprintf(negative, sizeof negative, "%s/bad_negative_size.sg", tmp);
    char cwd[512];
    assert_non_null(getcwd(cwd, sizeof cwd));
    assert_int_equal(run(NULL, "sed -e 's#size = 0 32#size = 64 -32#' "
                               "-e 's#import \"materials.sg\"#import \"%s/tests/scene/materials.sg\"#' "
                               "-e 's#\"hf16.png\"#\"%s/tests/scene/hf16.png\"#' '%s' > '%s'",
                         cwd, cwd, neg, negative), 0);

    const char *bad[] = {
        "tests/scene/bad_missing_heightfield.sg", "tests/scene/bad_raw_size.sg",
        "tests/scene/bad_rgb_heightfield.sg",     "tests/scene/bad_painted_size.sg",
        "tests/scene/bad_unknown_material.sg",    "tests/scene/bad_empty_stack.sg",
        "tests/scene/bad_size.sg",                negative,
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        char *out = build(1, bad[i], pack_a, "--no-cache");
        /* "FILE:LINE:COL: error:" naming the scene file */
        char want[300];
        snprintf(want, sizeof want, "%s:", bad[i]);
        const char *at = strstr(out, want);
        if (!at)
            fail_msg("%s: no located error in:\n%s", bad[i], out);
        int line = 0, col = 0;
        if (sscanf(at + strlen(want), "%d:%d: error:", &line, &col) != 2 || line < 1 || col < 1)
            fail_msg("%s: not file:line:col: error:\n%s", bad[i], out);
        free(out);
        char *diff = NULL;
        if (run(&diff, "diff -r '%s' '%s'", snap, pack_a) != 0)
            fail_msg("%s changed the pack:\n%s", bad[i], diff);
        free(diff);
    }
    char pattern[200];
    glob_t g;
    snprintf(pattern, sizeof pattern, "%s.tmp-*", pack_a);
    assert_int_equal(glob(pattern, 0, NULL, &g), GLOB_NOMATCH);

    /* a folder that is not a pack is never replaced */
    char other[160];
    snprintf(other, sizeof other, "%s/not-a-pack", tmp);
    assert_int_equal(run(NULL, "mkdir -p '%s' && echo keep > '%s/notes.txt'", other, other), 0);
    char *out = build(1, "examples/minimal/scene.sg", other, "--no-cache");
    assert_non_null(strstr(out, "not a shader pack"));
    free(out);
    assert_int_equal(file_size(other, "notes.txt"), 5);
}

static void test_usage_errors(void **state)
{
    assert_int_equal(run(NULL, "'%s' build", splatc), 2);
    assert_int_equal(run(NULL, "'%s' build examples/minimal/scene.sg", splatc), 2);
    assert_int_equal(run(NULL, "'%s' build examples/minimal/scene.sg -o x -j 0", splatc), 2);
    assert_int_equal(run(NULL, "'%s' build --help", splatc), 0);
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: test_pack SPLATC\n");
        return 2;
    }
    splatc = argv[1];
    snprintf(tmp, sizeof tmp, "/tmp/splatc-pack-XXXXXX");
    if (!mkdtemp(tmp))
        return 1;
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_manifest_and_grid),
        cmocka_unit_test(test_shaders_validate),
        cmocka_unit_test(test_byte_identical),
        cmocka_unit_test(test_incremental),
        cmocka_unit_test(test_bad_scenes_leave_pack),
        cmocka_unit_test(test_usage_errors),
    };
    int failed = cmocka_run_group_tests(tests, NULL, NULL);
    if (!failed)
        run(NULL, "rm -rf '%s'", tmp);
    else
        fprintf(stderr, "test_pack: scratch files kept in %s\n", tmp);
    return failed;
}
