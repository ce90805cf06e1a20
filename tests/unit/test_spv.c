/* test_spv.c — GLSL -> SPIR-V in process (compiler/spv.h): compile,
 * validate, optimise, atomic write, error mapping, threads. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <dirent.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "abi.h"
#include "spv.h"

static const char COMPUTE_OK[] =
    "#version 450\n"
    "layout(local_size_x = 64) in;\n"
    "layout(std430, set = 0, binding = 0) buffer Data { float v[]; } d;\n"
    "void main() {\n"
    "    uint i = gl_GlobalInvocationID.x;\n"
    "    d.v[i] = sin(d.v[i]) * 2.0 + float(i);\n"
    "}\n";

/* Line 5 calls an undeclared function; line 6 assigns a vec3 to a float. */
static const char COMPUTE_BAD[] =
    "#version 450\n"
    "layout(local_size_x = 1) in;\n"
    "layout(std430, set = 0, binding = 0) buffer Data { float v[]; } d;\n"
    "void main() {\n"
    "    float v1 = no_such_function(d.v[0]);\n"
    "    float v2 = vec3(1.0);\n"
    "    d.v[0] = v1 + v2;\n"
    "}\n";

static void compile_ok(const char *src, int stage, uint32_t **w, size_t *n)
{
    char *log = NULL;
    bool ok = spv_compile(src, stage, "test", w, n, &log);
    if (!ok)
        fprintf(stderr, "%s", log ? log : "(no log)");
    assert_true(ok);
    assert_non_null(*w);
    assert_true(*n > 5);
    assert_int_equal((*w)[0], 0x07230203u);     /* SPIR-V magic */
    assert_int_equal((*w)[1], 0x00010500u);     /* version 1.5  */
    free(log);
}

static void test_compute_compiles_and_validates(void **state)
{
    uint32_t *w;
    size_t n;
    compile_ok(COMPUTE_OK, SPV_STAGE_COMPUTE, &w, &n);
    char *log = NULL;
    bool ok = spv_validate(w, n, &log);
    if (!ok)
        fprintf(stderr, "%s", log);
    assert_true(ok);
    assert_null(log);
    free(w);
}

/* The ABI's own shaders: the shared vertex shader and a fragment shader
 * made of the prelude and a trivial main (what the emitter builds on). */
static void test_abi_shaders_compile(void **state)
{
    uint32_t *w;
    size_t n;
    compile_ok(SPLAT_GLSL_VERTEX, SPV_STAGE_VERTEX, &w, &n);
    assert_true(spv_validate(w, n, NULL));
    free(w);

    size_t len = strlen(SPLAT_GLSL_PRELUDE) + 256;
    char *frag = malloc(len);
    snprintf(frag, len, "#version 450\n%s"
             "void main() {\n"
             "    splat_finish(vec3(splat_slope()), splat_normal(), 0.5,\n"
             "                 splat_height(), 1.0);\n"
             "}\n", SPLAT_GLSL_PRELUDE);
    compile_ok(frag, SPV_STAGE_FRAGMENT, &w, &n);
    assert_true(spv_validate(w, n, NULL));
    free(w);
    free(frag);
}

static void test_bad_glsl_is_internal_error_with_line(void **state)
{
    uint32_t *w = (uint32_t *)1;
    size_t n = 7;
    char *log = NULL;
    assert_false(spv_compile(COMPUTE_BAD, SPV_STAGE_COMPUTE, "cliff", &w, &n, &log));
    assert_null(w);
    assert_int_equal(n, 0);
    assert_non_null(log);
    /* Reported as a compiler bug, naming the shader ... */
    assert_non_null(strstr(log, "internal compiler error: generated GLSL for 'cliff' failed to compile:"));
    /* ... with glslang's message at the right line ... */
    assert_non_null(strstr(log, "cliff:5: error: 'no_such_function'"));
    /* ... and the offending line of the generated text, with its number. */
    assert_non_null(strstr(log, "    5 |     float v1 = no_such_function(d.v[0]);"));
    /* Several errors, each mapped (glslang goes on after the first). */
    assert_non_null(strstr(log, "cliff:6: error:"));
    assert_non_null(strstr(log, "    6 |     float v2 = vec3(1.0);"));
    free(log);
}

static void test_bad_stage_and_empty_source(void **state)
{
    uint32_t *w;
    size_t n;
    char *log = NULL;
    assert_false(spv_compile(COMPUTE_OK, 7, "x", &w, &n, &log));
    assert_non_null(strstr(log, "bad shader stage 7"));
    free(log);
    log = NULL;
    assert_false(spv_compile("", SPV_STAGE_COMPUTE, "empty", &w, &n, &log));
    assert_non_null(strstr(log, "internal compiler error: generated GLSL for 'empty'"));
    free(log);
    /* NULL log is allowed. */
    assert_false(spv_compile(COMPUTE_BAD, SPV_STAGE_COMPUTE, "x", &w, &n, NULL));
}

static void test_corrupt_spirv_fails_validation(void **state)
{
    uint32_t *w;
    size_t n;
    compile_ok(COMPUTE_OK, SPV_STAGE_COMPUTE, &w, &n);
    char *log = NULL;

    /* A truncated module. */
    assert_false(spv_validate(w, n - 3, &log));
    assert_non_null(log);
    assert_non_null(strstr(log, "spirv-val:"));
    free(log);
    log = NULL;

    /* An id bound below the ids in use. */
    uint32_t bound = w[3];
    w[3] = 2;
    assert_false(spv_validate(w, n, &log));
    assert_non_null(strstr(log, "spirv-val:"));
    free(log);
    log = NULL;
    w[3] = bound;
    assert_true(spv_validate(w, n, NULL));

    /* Too short to be a module at all. */
    assert_false(spv_validate(w, 3, &log));
    assert_non_null(strstr(log, "too short"));
    free(log);
    free(w);
}

static void test_optimize_keeps_valid(void **state)
{
    uint32_t *w;
    size_t n;
    /* Dead code and a foldable expression for the optimiser to remove. */
    static const char src[] =
        "#version 450\n"
        "layout(local_size_x = 64) in;\n"
        "layout(std430, set = 0, binding = 0) buffer Data { float v[]; } d;\n"
        "float unused(float x) { return x * x; }\n"
        "void main() {\n"
        "    uint i = gl_GlobalInvocationID.x;\n"
        "    float a = 2.0 * 3.0;\n"
        "    float dead = unused(a);\n"
        "    d.v[i] = d.v[i] * a;\n"
        "}\n";
    compile_ok(src, SPV_STAGE_COMPUTE, &w, &n);
    size_t before = n;
    char *log = NULL;
    bool ok = spv_optimize(&w, &n, &log);
    if (!ok)
        fprintf(stderr, "%s", log ? log : "");
    assert_true(ok);
    assert_true(n < before);
    assert_true(spv_validate(w, n, NULL));
    free(log);
    free(w);
}

static void test_write_file_atomic(void **state)
{
    uint32_t *w;
    size_t n;
    compile_ok(COMPUTE_OK, SPV_STAGE_COMPUTE, &w, &n);
    char dir[] = "/tmp/test_spv_XXXXXX";
    assert_non_null(mkdtemp(dir));
    char path[256];
    snprintf(path, sizeof path, "%s/a.spv", dir);
    assert_true(spv_write_file(path, w, n));
    /* Overwrite in place: the reader sees the new, whole file. */
    assert_true(spv_write_file(path, w, n));

    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    uint32_t *back = malloc(n * sizeof *back + 4);
    assert_int_equal(fread(back, 4, n + 1, f), n);
    fclose(f);
    assert_memory_equal(back, w, n * 4);
    free(back);

    /* No temporary file is left behind. */
    DIR *d = opendir(dir);
    int entries = 0;
    for (struct dirent *e; (e = readdir(d));)
        if (e->d_name[0] != '.')
            entries++;
    closedir(d);
    assert_int_equal(entries, 1);

    char bad[300];
    snprintf(bad, sizeof bad, "%s/no/such/dir/a.spv", dir);
    assert_false(spv_write_file(bad, w, n));
    remove(path);
    rmdir(dir);
    free(w);
}

/* Several threads compile at once (splatc build -j N) and all get the same
 * bytes as a single-threaded compile. */
typedef struct job { uint32_t *w; size_t n; bool ok; } job;

static void *compile_job(void *arg)
{
    job *j = arg;
    j->ok = spv_compile(COMPUTE_OK, SPV_STAGE_COMPUTE, "t", &j->w, &j->n, NULL);
    return NULL;
}

/* spv_shape (cache.h: validation skipped for a known shape): equal for
 * modules that differ only in float constants, including two constants
 * that become equal (glslang then merges them: one OpConstant fewer, the
 * ids after it shifted); different for any other change. */
static void shape_of(const char *src, uint64_t h[2])
{
    uint32_t *w;
    size_t n;
    compile_ok(src, SPV_STAGE_COMPUTE, &w, &n);
    assert_true(spv_shape(w, n, h));
    free(w);
}

static void test_shape_ignores_float_constants(void **state)
{
    (void)state;
    static const char *const fmt =
        "#version 450\n"
        "layout(local_size_x = 1) in;\n"
        "layout(std430, set = 0, binding = 0) buffer Data { vec4 v[]; } d;\n"
        "void main() {\n"
        "    vec3 c = vec3(%s, 0.25, 0.5) * d.v[0].x;\n"
        "    if (d.v[1].y > %s) c += vec3(0.75);\n"
        "    d.v[2] = vec4(c, %s);\n"
        "}\n";
    char a[1024], b[1024], merged[1024], other[1024], typed[1024];
    snprintf(a, sizeof a, fmt, "0.9", "0.125", "1.0");
    snprintf(b, sizeof b, fmt, "0.95", "0.375", "2.0");
    snprintf(merged, sizeof merged, fmt, "0.25", "0.5", "0.75");   /* collisions */
    snprintf(other, sizeof other, fmt, "0.9", "0.125", "d.v[3].z");
    snprintf(typed, sizeof typed, fmt, "0.9", "0.125", "float(d.v.length())");
    uint64_t ha[2], hb[2], hm[2], ho[2], ht[2];
    shape_of(a, ha);
    shape_of(b, hb);
    shape_of(merged, hm);
    shape_of(other, ho);
    shape_of(typed, ht);
    assert_memory_equal(ha, hb, sizeof ha);
    assert_memory_equal(ha, hm, sizeof ha);
    assert_memory_not_equal(ha, ho, sizeof ha);
    assert_memory_not_equal(ha, ht, sizeof ha);
    assert_memory_not_equal(ho, ht, sizeof ha);
    static const uint32_t junk[] = {0x07230203u, 0x00010500u, 0, 0, 0, 0xffff0011u};
    assert_false(spv_shape(junk, 6, ha));
}

static void test_threads_deterministic(void **state)
{
    uint32_t *ref;
    size_t nref;
    compile_ok(COMPUTE_OK, SPV_STAGE_COMPUTE, &ref, &nref);
    enum { N = 6 };
    pthread_t t[N];
    job jobs[N] = {0};
    for (int i = 0; i < N; i++)
        assert_int_equal(pthread_create(&t[i], NULL, compile_job, &jobs[i]), 0);
    for (int i = 0; i < N; i++)
        pthread_join(t[i], NULL);
    for (int i = 0; i < N; i++) {
        assert_true(jobs[i].ok);
        assert_int_equal(jobs[i].n, nref);
        assert_memory_equal(jobs[i].w, ref, nref * 4);
        free(jobs[i].w);
    }
    free(ref);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_compute_compiles_and_validates),
        cmocka_unit_test(test_abi_shaders_compile),
        cmocka_unit_test(test_bad_glsl_is_internal_error_with_line),
        cmocka_unit_test(test_bad_stage_and_empty_source),
        cmocka_unit_test(test_corrupt_spirv_fails_validation),
        cmocka_unit_test(test_optimize_keeps_valid),
        cmocka_unit_test(test_write_file_atomic),
        cmocka_unit_test(test_threads_deterministic),
        cmocka_unit_test(test_shape_ignores_float_constants),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
