/* test_pack_checks — the pack checks that splatview cannot show alone:
 *   rt_pack_check_device: each size of a real pack against a device's
 *     limits, with devices made small enough to fail on each one in turn
 *     (lavapipe's own limits equal the pack limits, so a real device never
 *     trips them).  No Vulkan call: the check reads props.limits only.
 *   rt_spirv_check's compute role: every compute variant of a pack built
 *     with --compute-spirv fits it; its fragment shaders do not, nor does a
 *     compute variant in a fragment role.
 *   Shaders read on first use (pack_shaders.c): loading reads none of
 *     them; rt_pack_spirv reads one, the same words as the file, once
 *     (from two threads at once); rt_pack_validate reads the rest.
 *   rt_pipelines_stand_in: with async pipelines, before the frame the
 *     far atlas stands in where there is one, else the flat stand-in (the
 *     über-shader is not made for the first picture); SPLAT_STAND_IN=uber
 *     keeps the über-shader against the composites by their modules'
 *     bytes (it stands in for lists whose modules together outweigh it,
 *     not for one smaller composite); always, never, atlas and flat force
 *     one.
 *
 *   test_pack_checks MINIMAL_PACK DESTRUCTION_PACK COMPUTE_PACK
 *   (all by splatc build)
 */
#include <dirent.h>
#include <pthread.h>
#include <fcntl.h>
#include <unistd.h>
#include <stdlib.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <string.h>

#include "rt_internal.h"

static const char *minimal_dir, *destr_dir, *compute_dir;

/* A device with room for everything, then one limit lowered per check. */
static void roomy(rt_device *d)
{
    memset(d, 0, sizeof *d);
    VkPhysicalDeviceLimits *L = &d->props.limits;
    L->maxImageDimension2D = 16384;
    L->maxImageArrayLayers = 2048;
    L->maxPerStageDescriptorSamplers = 64;
    L->maxPerStageDescriptorSampledImages = 64;
    L->maxUniformBufferRange = 65536;
    L->maxPushConstantsSize = 128;
}

/* The check fails and its message holds each of the strings. */
static void refused(const rt_pack *p, const rt_device *d, const char *a, const char *b)
{
    rt_error e = { 0 };
    assert_false(rt_pack_check_device(p, d, &e));
    assert_int_equal(e.id, RT_E_PACK_LIMIT);
    printf("  %s\n", e.msg);
    assert_non_null(strstr(e.msg, "manifest.json: error: "));
    assert_non_null(strstr(e.msg, a));
    assert_non_null(strstr(e.msg, b));
    rt_error_clear(&e);
}

static void test_minimal(void **state)
{
    (void)state;
    rt_pack p;
    rt_error e = { 0 };
    assert_true(rt_pack_load(&p, minimal_dir, &e));
    assert_non_null(p.sparse);
    rt_device d;
    roomy(&d);
    assert_true(rt_pack_check_device(&p, &d, &e));

    d.props.limits.maxImageDimension2D = 200;   /* the heightfield is 257 */
    refused(&p, &d, "the heightfield's width is 257",
            "over the device's maxImageDimension2D (200)");
    int hw = p.hf_width, hh = p.hf_height;
    p.hf_width = p.hf_height = 16;               /* textures are 256 */
    refused(&p, &d, "textures[0] (textures/grass_albedo.png): the larger side is 256",
            "maxImageDimension2D (200)");
    for (int i = 0; i < p.ntextures; i++)
        p.textures[i].width = p.textures[i].height = 8;
    d.props.limits.maxImageDimension2D = (uint32_t)p.sparse->atlas_width - 1;
    refused(&p, &d, "the painted atlas's larger side", "maxImageDimension2D");
    for (int i = 0; i < p.ntextures; i++)
        p.textures[i].width = p.textures[i].height = 256;
    p.hf_width = hw, p.hf_height = hh;

    roomy(&d);
    d.props.limits.maxImageArrayLayers = 0;
    refused(&p, &d, "the painted index's layer count is 1", "maxImageArrayLayers (0)");

    roomy(&d);
    /* 6 + the texture arrays (one per size, mip levels and sampler state) */
    assert_true(p.narrays >= 1 && p.narrays <= p.ntextures);
    d.props.limits.maxPerStageDescriptorSamplers = (uint32_t)(5 + p.narrays);
    char want[64], lim[64];
    snprintf(want, sizeof want, "sampler count (6 + texture arrays) is %d", 6 + p.narrays);
    snprintf(lim, sizeof lim, "maxPerStageDescriptorSamplers (%d)", 5 + p.narrays);
    refused(&p, &d, want, lim);
    roomy(&d);
    d.props.limits.maxImageArrayLayers = (uint32_t)p.arrays[0].nlayers - 1;
    if (p.arrays[0].nlayers > 1 && (p.sparse ? p.sparse->layers : 0) < p.arrays[0].nlayers)
        refused(&p, &d, "texture array 0's layer count", "maxImageArrayLayers");

    roomy(&d);
    d.props.limits.maxUniformBufferRange = 16;
    refused(&p, &d, "params_size is", "maxUniformBufferRange (16)");
    rt_pack_free(&p);
}

static void test_dense_and_destruction(void **state)
{
    (void)state;
    rt_pack p;
    rt_error e = { 0 };
    assert_true(rt_pack_load(&p, destr_dir, &e));
    assert_true(p.has_destruction);
    rt_device d;
    roomy(&d);
    assert_true(rt_pack_check_device(&p, &d, &e));
    int hw = p.hf_width, hh = p.hf_height;
    p.hf_width = p.hf_height = 8;
    for (int i = 0; i < p.ntextures; i++)
        p.textures[i].width = p.textures[i].height = 8;
    int aw = p.sparse->atlas_width, ah = p.sparse->atlas_height;
    p.sparse->atlas_width = p.sparse->atlas_height = 8;
    d.props.limits.maxImageDimension2D = 31;   /* 512 m / 16 m = 32 cells */
    refused(&p, &d, "the destruction grid's cells per side is 32", "maxImageDimension2D (31)");
    p.sparse->atlas_width = aw, p.sparse->atlas_height = ah;
    p.hf_width = hw, p.hf_height = hh;

    /* a dense painted array of 3 layers on a device with 2 */
    roomy(&d);
    d.props.limits.maxImageArrayLayers = 2;
    sparse_masks *sparse = p.sparse;
    uint8_t layer = 0;
    int np = p.npainted;
    p.sparse = NULL;
    p.painted = &layer;
    p.npainted = 3;
    refused(&p, &d, "the dense painted layer count is 3", "maxImageArrayLayers (2)");
    p.painted = NULL;
    p.npainted = np;
    p.sparse = sparse;
    rt_pack_free(&p);
}

/* Check one SPIR-V file of the compute pack against a role. */
static bool fits(const rt_pack *p, const char *file, rt_shader_role role, rt_error *e)
{
    char path[1024], rel[1024], why[256];
    snprintf(path, sizeof path, "%s/shaders/%s", compute_dir, file);
    snprintf(rel, sizeof rel, "shaders/%s", file);
    int dirfd = open(compute_dir, O_RDONLY | O_DIRECTORY);
    assert_true(dirfd >= 0);
    size_t bytes = 0;   /* a ".zst" file decompressed (PACK.md) */
    uint32_t *words = (uint32_t *)rt_pack_read_content(dirfd, rel, (size_t)64 << 20, &bytes,
                                                        why, sizeof why);
    close(dirfd);
    if (!words)
        fail_msg("%s: %s", rel, why);
    size_t n = bytes / 4;
    rt_interface in;
    assert_true(rt_interface_for(p, role, &in));
    assert_true(rt_spirv_validate(words, n, path, e));
    bool ok = rt_spirv_check(words, n, path, &in, e);
    rt_interface_free(&in);
    free(words);
    return ok;
}

static void test_compute_role(void **state)
{
    (void)state;
    rt_pack p;
    rt_error e = { 0 };
    assert_true(rt_pack_load(&p, compute_dir, &e));
    char shaders[1024];
    snprintf(shaders, sizeof shaders, "%s/shaders", compute_dir);
    DIR *dir = opendir(shaders);
    assert_non_null(dir);
    int ncomp = 0, nug = 0, nstand = 0;
    struct dirent *ent;
    while ((ent = readdir(dir)) != NULL) {
        size_t len = strlen(ent->d_name);
        if (len > 16 && !strcmp(ent->d_name + len - 16, ".ug.comp.spv.zst")) {
            /* undergrowth masks: their own role (set 2), not compute shading */
            if (!fits(&p, ent->d_name, RT_ROLE_UNDERGROWTH, &e))
                fail_msg("%s", e.msg);
            assert_false(fits(&p, ent->d_name, RT_ROLE_COMPUTE, &e));
            rt_error_clear(&e);
            nug++;
        } else if (!strcmp(ent->d_name, "atlas_stand_in.comp.spv.zst")) {
            /* the far atlas's shader: the compute role and set 2's atlas */
            if (!fits(&p, ent->d_name, RT_ROLE_FAR, &e))
                fail_msg("%s", e.msg);
            assert_false(fits(&p, ent->d_name, RT_ROLE_COMPUTE, &e));
            rt_error_clear(&e);
            nstand++;
        } else if (!strcmp(ent->d_name, "flat_stand_in.comp.spv.zst")) {
            /* the flat stand-in (PACK.md "Stand-ins"): compute shading's */
            if (!fits(&p, ent->d_name, RT_ROLE_COMPUTE, &e))
                fail_msg("%s", e.msg);
            nstand++;
        } else if (len > 13 && !strcmp(ent->d_name + len - 13, ".comp.spv.zst")) {
            if (!fits(&p, ent->d_name, RT_ROLE_COMPUTE, &e))
                fail_msg("%s", e.msg);
            assert_false(fits(&p, ent->d_name, RT_ROLE_COMPOSITE, &e));
            assert_non_null(strstr(e.msg, "no fragment entry point"));
            rt_error_clear(&e);
            ncomp++;
        }
    }
    closedir(dir);
    printf("  %d compute variants fit the compute role, %d undergrowth mask shaders theirs, "
           "%d stand-ins theirs\n", ncomp, nug, nstand);
    /* the flat stand-in in every pack with SPIR-V; the atlas's with a far atlas */
    assert_non_null(p.stand_in[SPLAT_STAND_IN_FLAT].mod);
    assert_int_equal(nstand, 1 + (p.stand_in[SPLAT_STAND_IN_ATLAS].mod != NULL));
    int want_ug = 0;
    for (int i = 0; i < p.ncombos; i++)
        want_ug += p.combos[i].ug_compute.mod != NULL;
    assert_int_equal(nug, want_ug);
    assert_int_equal(ncomp, p.ncombos + 1);   /* every composite and the uber */
    assert_false(fits(&p, "0000.spv.zst", RT_ROLE_COMPUTE, &e));
    assert_non_null(strstr(e.msg, "no compute entry point"));
    rt_error_clear(&e);
    rt_pack_free(&p);
}

/* Two threads ask for the same module at once: one reads it. */
typedef struct ask { const rt_pack *p; const rt_spirv *s; const uint32_t *got; } ask;

static void *ask_one(void *arg)
{
    ask *a = arg;
    rt_error e = { 0 };
    size_t n = 0;
    a->got = rt_pack_spirv(a->p, a->s, &n, &e);
    rt_error_clear(&e);
    return NULL;
}

static void test_lazy(void **state)
{
    (void)state;
    rt_pack p;
    rt_error e = { 0 };
    assert_true(rt_pack_load(&p, compute_dir, &e));
    int read = -1, total = rt_pack_shader_count(&p, &read);
    /* every combination: fragment, compute and undergrowth SPIR-V with
     * their GLSL; the über-shader's; the vertex shader */
    assert_true(total > 4 * p.nbase);
    assert_int_equal(read, 0);
    const rt_spirv *s = &p.combos[0].compute_spirv;
    assert_true(rt_spirv_present(s));
    ask a = { &p, s, NULL }, b = { &p, s, NULL };
    pthread_t ta, tb;
    assert_int_equal(pthread_create(&ta, NULL, ask_one, &a), 0);
    assert_int_equal(pthread_create(&tb, NULL, ask_one, &b), 0);
    pthread_join(ta, NULL);
    pthread_join(tb, NULL);
    assert_non_null(a.got);
    assert_ptr_equal(a.got, b.got);   /* one read, kept */
    rt_pack_shader_count(&p, &read);
    assert_int_equal(read, 1);
    /* the words are the file's */
    char why[256];
    size_t bytes = 0, n = 0;
    int dirfd = open(compute_dir, O_RDONLY | O_DIRECTORY);
    uint8_t *file = rt_pack_read_content(dirfd, s->path, (size_t)64 << 20, &bytes, why,
                                         sizeof why);
    close(dirfd);
    assert_non_null(file);
    const uint32_t *w = rt_pack_spirv(&p, s, &n, &e);
    assert_int_equal(n * 4, bytes);
    assert_memory_equal(w, file, bytes);
    free(file);
    const char *text = rt_pack_text(&p, &p.combos[0].compute, &e);
    assert_non_null(text);
    assert_non_null(strstr(text, "void main"));
    rt_pack_shader_count(&p, &read);
    assert_int_equal(read, 2);
    assert_true(rt_pack_validate(&p, &e));
    rt_pack_shader_count(&p, &read);
    assert_int_equal(read, total);
    printf("  %d shader files: none read at load, all by rt_pack_validate\n", total);
    rt_pack_free(&p);
}

static void test_stand_in(void **state)
{
    (void)state;
    rt_pack p;
    rt_error e = { 0 };
    assert_true(rt_pack_load(&p, compute_dir, &e));
    rt_device d;
    memset(&d, 0, sizeof d);
    d.props.deviceType = VK_PHYSICAL_DEVICE_TYPE_CPU;   /* one JIT at a time */
    rt_pipelines pl;
    memset(&pl, 0, sizeof pl);   /* no pipeline made yet */
    int ids[64], n = p.nbase < 64 ? p.nbase : 64;
    size_t uber = rt_pack_spirv_size(&p.uber_compute_spirv), sum = 0, one = 0;
    int small = -1;
    for (int k = 0; k < n; k++) {
        ids[k] = k;
        size_t s = rt_pack_spirv_size(&p.combos[k].compute_spirv);
        assert_true(s > 0);
        sum += s;
        if (s < uber && small < 0)
            small = k, one = s;
    }
    assert_true(small >= 0 && uber > 0);
    /* no workers: nothing stands in, before or after the frame */
    assert_int_equal(rt_pipelines_stand_in(&d, &p, &pl, NULL, 0, 0, true), RT_STAND_NONE);
    assert_int_equal(rt_pipelines_stand_in(&d, &p, &pl, ids, n, 0, false), RT_STAND_NONE);
    pl.async = (struct rt_async *)&pl;   /* only tested against NULL here */
    unsetenv("SPLAT_STAND_IN");
    /* the default: before the frame the atlas (on a GPU: a CPU device
     * decodes its BC blocks per sample) or the flat stand-in, so the
     * lists are never left for after it */
    assert_int_equal(rt_pipelines_stand_in(&d, &p, &pl, NULL, 0, 0, true), RT_STAND_FLAT);
    assert_int_equal(rt_pipelines_stand_in(&d, &p, &pl, NULL, 0, 0, false), RT_STAND_FLAT);
    d.props.deviceType = VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU;
    assert_int_equal(rt_pipelines_stand_in(&d, &p, &pl, NULL, 0, 0, true), RT_STAND_ATLAS);
    assert_int_equal(rt_pipelines_stand_in(&d, &p, &pl, NULL, 0, 0, false), RT_STAND_FLAT);
    d.props.deviceType = VK_PHYSICAL_DEVICE_TYPE_CPU;
    assert_int_equal(rt_pipelines_stand_in(&d, &p, &pl, ids, n, 0, false), RT_STAND_NONE);
    setenv("SPLAT_STAND_IN", "auto", 1);
    assert_int_equal(rt_pipelines_stand_in(&d, &p, &pl, NULL, 0, 0, false), RT_STAND_FLAT);
    /* uber: nothing before the frame, then by the modules' bytes */
    setenv("SPLAT_STAND_IN", "uber", 1);
    assert_int_equal(rt_pipelines_stand_in(&d, &p, &pl, NULL, 0, 0, true), RT_STAND_NONE);
    assert_int_equal(rt_pipelines_stand_in(&d, &p, &pl, &small, 1, 0, false), RT_STAND_NONE);
    assert_int_equal(rt_pipelines_stand_in(&d, &p, &pl, ids, n, 0, false),
                     uber < sum ? RT_STAND_UBER : RT_STAND_NONE);
    printf("  über-shader %zu bytes; combination %d %zu; all %d %zu: stands in %s\n", uber,
           small, one, n, sum, uber < sum ? "for all" : "for none");
    setenv("SPLAT_STAND_IN", "always", 1);
    assert_int_equal(rt_pipelines_stand_in(&d, &p, &pl, NULL, 0, 0, true), RT_STAND_NONE);
    assert_int_equal(rt_pipelines_stand_in(&d, &p, &pl, &small, 1, 0, false), RT_STAND_UBER);
    setenv("SPLAT_STAND_IN", "never", 1);
    assert_int_equal(rt_pipelines_stand_in(&d, &p, &pl, NULL, 0, 0, true), RT_STAND_NONE);
    assert_int_equal(rt_pipelines_stand_in(&d, &p, &pl, ids, n, 0, false), RT_STAND_NONE);
    setenv("SPLAT_STAND_IN", "atlas", 1);
    assert_int_equal(rt_pipelines_stand_in(&d, &p, &pl, NULL, 0, 0, true), RT_STAND_ATLAS);
    assert_int_equal(rt_pipelines_stand_in(&d, &p, &pl, NULL, 0, 0, false), RT_STAND_FLAT);
    setenv("SPLAT_STAND_IN", "flat", 1);
    assert_int_equal(rt_pipelines_stand_in(&d, &p, &pl, NULL, 0, 0, true), RT_STAND_FLAT);
    assert_int_equal(rt_pipelines_stand_in(&d, &p, &pl, ids, n, 0, false), RT_STAND_NONE);
    unsetenv("SPLAT_STAND_IN");
    pl.async = NULL;
    rt_pack_free(&p);
}

int main(int argc, char **argv)
{
    if (argc != 4) {
        fprintf(stderr, "usage: test_pack_checks MINIMAL_PACK DESTRUCTION_PACK COMPUTE_PACK\n");
        return 2;
    }
    minimal_dir = argv[1];
    destr_dir = argv[2];
    compute_dir = argv[3];
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_minimal),
        cmocka_unit_test(test_dense_and_destruction),
        cmocka_unit_test(test_compute_role),
        cmocka_unit_test(test_lazy),
        cmocka_unit_test(test_stand_in),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
