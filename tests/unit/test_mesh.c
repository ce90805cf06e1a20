/* test_mesh.c — undergrowth meshes (mesh.h): every built-in is a sound
 * triangle list of the stated size, deterministic, and so are the far
 * versions, which keep the cover with a third of the triangles or fewer;
 * OBJ files round-trip
 * (a cube with and without normals) and broken ones give a message. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "mesh.h"

typedef struct box { float lo[3], hi[3]; } box;

/* Indices in range, whole triangles, unit normals, uv in [0, 1]; the box. */
static box check_sound(const splat_mesh *m)
{
    assert_true(m->nv > 0);
    assert_true(m->nidx > 0);
    assert_int_equal(m->nidx % 3, 0);
    for (uint32_t i = 0; i < m->nidx; i++)
        assert_true(m->idx[i] < m->nv);
    box b = { { INFINITY, INFINITY, INFINITY }, { -INFINITY, -INFINITY, -INFINITY } };
    for (uint32_t i = 0; i < m->nv; i++) {
        const splat_mesh_vertex *v = &m->v[i];
        double len = sqrt(v->nrm[0] * v->nrm[0] + v->nrm[1] * v->nrm[1] + v->nrm[2] * v->nrm[2]);
        assert_true(fabs(len - 1) < 1e-5);
        assert_true(v->uv[1] >= 0 && v->uv[1] <= 1);
        for (int k = 0; k < 3; k++) {
            b.lo[k] = fminf(b.lo[k], v->pos[k]);
            b.hi[k] = fmaxf(b.hi[k], v->pos[k]);
        }
    }
    return b;
}

/* Flat normals, pointing out of a stone: each face's vertices share the
 * normal, and the winding agrees. */
static void check_flat_outward(const splat_mesh *m)
{
    for (uint32_t t = 0; t < m->nidx; t += 3) {
        const float *p0 = m->v[m->idx[t]].pos, *p1 = m->v[m->idx[t + 1]].pos,
                    *p2 = m->v[m->idx[t + 2]].pos, *nrm = m->v[m->idx[t]].nrm;
        float a[3], c[3];
        for (int k = 0; k < 3; k++)
            a[k] = p1[k] - p0[k], c[k] = p2[k] - p0[k];
        float x[3] = { a[1] * c[2] - a[2] * c[1], a[2] * c[0] - a[0] * c[2],
                       a[0] * c[1] - a[1] * c[0] };
        assert_true(x[0] * nrm[0] + x[1] * nrm[1] + x[2] * nrm[2] > 0);
        assert_memory_equal(m->v[m->idx[t + 1]].nrm, nrm, sizeof m->v->nrm);
        float mid = (p0[0] + p1[0] + p2[0]) * nrm[0] +
                    ((p0[1] + p1[1] + p2[1]) / 3 - 0.07f) * 3 * nrm[1] +
                    (p0[2] + p1[2] + p2[2]) * nrm[2];
        assert_true(mid > 0);
    }
}

/* The summed area of a mesh's triangles (its cover, seen from the side). */
static double area(const splat_mesh *m)
{
    double sum = 0;
    for (uint32_t t = 0; t < m->nidx; t += 3) {
        const float *p0 = m->v[m->idx[t]].pos, *p1 = m->v[m->idx[t + 1]].pos,
                    *p2 = m->v[m->idx[t + 2]].pos;
        double a[3], c[3];
        for (int k = 0; k < 3; k++)
            a[k] = p1[k] - p0[k], c[k] = p2[k] - p0[k];
        double x[3] = { a[1] * c[2] - a[2] * c[1], a[2] * c[0] - a[0] * c[2],
                        a[0] * c[1] - a[1] * c[0] };
        sum += 0.5 * sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
    }
    return sum;
}

/* The far versions: sound, deterministic, at most a third of the near
 * triangles, the near one's cover within 15 % and its box (grass: its
 * height) within 5 cm;
 * stones keep flat outward normals; plant has none. */
static void test_far(void **state)
{
    static const char *const with_far[] = { "grass", "stone" };
    for (int i = 0; i < 2; i++) {
        splat_mesh near, far, again;
        assert_true(splat_mesh_builtin(with_far[i], &near));
        assert_true(splat_mesh_builtin_far(with_far[i], &far));
        box bn = check_sound(&near), bf = check_sound(&far);
        assert_true(splat_mesh_builtin_far(with_far[i], &again));
        assert_int_equal(again.nv, far.nv);
        assert_memory_equal(again.v, far.v, far.nv * sizeof *far.v);
        splat_mesh_free(&again);
        assert_true(3 * far.nidx <= near.nidx);
        if (i == 0) {
            assert_int_equal(far.nidx, 4 * 6);                  /* 4 quads */
            assert_true(fabs(area(&far) / area(&near) - 1) < 0.15);
        } else {
            check_flat_outward(&far);
        }
        for (int k = i == 0 ? 1 : 0; k < (i == 0 ? 2 : 3); k++) {   /* grass: height */
            assert_true(fabsf(bf.lo[k] - bn.lo[k]) < 0.05f);
            assert_true(fabsf(bf.hi[k] - bn.hi[k]) < 0.05f);
        }
        splat_mesh_free(&near);
        splat_mesh_free(&far);
    }
    splat_mesh m;
    assert_false(splat_mesh_builtin_far("plant", &m));
    assert_false(splat_mesh_builtin_far("fern", &m));
}

static void test_builtins(void **state)
{
    splat_mesh m;
    int n = 0;
    for (; splat_mesh_builtins[n]; n++) {
        assert_true(splat_mesh_builtin(splat_mesh_builtins[n], &m));
        box b = check_sound(&m);
        /* deterministic: the same bytes again */
        splat_mesh again;
        assert_true(splat_mesh_builtin(splat_mesh_builtins[n], &again));
        assert_int_equal(again.nv, m.nv);
        assert_int_equal(again.nidx, m.nidx);
        assert_memory_equal(again.v, m.v, m.nv * sizeof *m.v);
        assert_memory_equal(again.idx, m.idx, m.nidx * sizeof *m.idx);
        splat_mesh_free(&again);

        const char *name = splat_mesh_builtins[n];
        if (!strcmp(name, "grass")) {
            assert_int_equal(m.nv, 12 * 6);               /* 12 blades, 3 x 2 */
            assert_true(fabsf(b.lo[1]) < 1e-6f);
            assert_true(b.hi[1] >= 0.35f && b.hi[1] <= 0.5f + 1e-6f);
            for (int k = 0; k < 3; k += 2)
                assert_true(b.lo[k] > -0.3f && b.hi[k] < 0.3f);
            for (uint32_t i = 0; i < m.nv; i++)         /* lit like the ground */
                assert_true(m.v[i].nrm[1] > 0.9f);
        } else if (!strcmp(name, "plant")) {
            assert_int_equal(m.nidx, 12);                 /* two quads */
            for (int k = 0; k < 3; k += 2) {
                assert_true(fabsf(b.lo[k] + 0.3f) < 1e-6f);
                assert_true(fabsf(b.hi[k] - 0.3f) < 1e-6f);
            }
            assert_true(fabsf(b.lo[1]) < 1e-6f && fabsf(b.hi[1] - 0.6f) < 1e-6f);
        } else {
            assert_string_equal(name, "stone");
            assert_true(b.lo[1] < 0 && b.lo[1] > -0.1f);   /* sunk in the ground */
            assert_true(b.hi[1] > 0.15f && b.hi[1] <= 0.25f);
            for (int k = 0; k < 3; k += 2)
                assert_true(b.hi[k] - b.lo[k] > 0.3f && b.hi[k] - b.lo[k] < 0.5f);
            check_flat_outward(&m);
        }
        splat_mesh_free(&m);
    }
    assert_int_equal(n, 3);
    assert_false(splat_mesh_builtin("fern", &m));
}

static char dir[64];

static char *write_file(const char *name, const char *text)
{
    static char path[128];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs(text, f);
    fclose(f);
    return path;
}

/* The unit cube [0,1]^3, quads wound counter-clockwise seen from outside. */
static const char cube_v[] =
    "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n";
static const char cube_f[] =
    "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 4 8 7 3\nf 1 5 8 4\nf 2 3 7 6\n";

static void test_obj_cube(void **state)
{
    char text[2048], *err = NULL;
    splat_mesh m;

    /* no normals, no uv: flat normals (4 vertices a face after merging),
     * uv.y from height */
    snprintf(text, sizeof text, "# cube\n%s%s", cube_v, cube_f);
    assert_true(splat_mesh_obj(write_file("cube.obj", text), &m, &err));
    assert_null(err);
    check_sound(&m);
    assert_int_equal(m.nidx, 36);
    assert_int_equal(m.nv, 24);
    for (uint32_t t = 0; t < m.nidx; t += 3) {
        const splat_mesh_vertex *v = &m.v[m.idx[t]];
        float out = 0;               /* normal . (centroid - cube centre) */
        for (int k = 0; k < 3; k++) {
            float c = (m.v[m.idx[t]].pos[k] + m.v[m.idx[t + 1]].pos[k] +
                       m.v[m.idx[t + 2]].pos[k]) / 3 - 0.5f;
            out += v->nrm[k] * c;
            assert_true(fabsf(v->nrm[k]) < 1e-6f || fabsf(fabsf(v->nrm[k]) - 1) < 1e-6f);
        }
        assert_true(out > 0);
    }
    for (uint32_t i = 0; i < m.nv; i++) {
        assert_true(m.v[i].uv[0] == 0.5f);
        assert_true(m.v[i].uv[1] == m.v[i].pos[1]);
    }
    splat_mesh_free(&m);

    /* smooth normals and uv from the file: the 8 corners, 12 triangles;
     * uv.y clamped to [0, 1] */
    char vn[512] = "", f[512] = "";
    for (int i = 0; i < 8; i++) {
        int x = (i == 1 || i == 2 || i == 5 || i == 6), y = (i == 2 || i == 3 || i >= 6), z = i >= 4;
        char line[64];
        snprintf(line, sizeof line, "vn %d %d %d\nvt %d %d\n", 2 * x - 1, 2 * y - 1, 2 * z - 1,
                 x, 3 * y - 1);
        strcat(vn, line);
    }
    for (const char *p = cube_f; *p; p++) {
        if (*p >= '1' && *p <= '8') {
            char c[16];
            snprintf(c, sizeof c, "%c/%c/%c", *p, *p, *p);
            strcat(f, c);
        } else {
            size_t n = strlen(f);
            f[n] = *p;
            f[n + 1] = 0;
        }
    }
    snprintf(text, sizeof text, "%s%s%s", cube_v, vn, f);
    assert_true(splat_mesh_obj(write_file("smooth.obj", text), &m, &err));
    check_sound(&m);
    assert_int_equal(m.nidx, 36);
    assert_int_equal(m.nv, 8);
    for (uint32_t i = 0; i < m.nv; i++) {
        assert_true(fabsf(m.v[i].nrm[1] - (m.v[i].pos[1] - 0.5f) * 2 / sqrtf(3)) < 1e-5f);
        assert_true(m.v[i].uv[1] == m.v[i].pos[1]);     /* -1 -> 0, 2 -> 1 */
        assert_true(m.v[i].uv[0] == m.v[i].pos[0]);
    }
    splat_mesh_free(&m);
}

static void test_obj_errors(void **state)
{
    splat_mesh m;
    char *err = NULL;
    static const struct { const char *name, *text, *msg; } bad[] = {
        { "empty.obj", "", "no triangles" },
        { "points.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n", "no triangles" },
        { "range.obj", "v 0 0 0\nv 1 0 0\nf 1 2 3\n", "a face refers to" },
        { "zero.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n", "not an OBJ file" },
        /* non-finite text, which tinyobjloader reads as 0, and values the
         * runtime refuses: refused with their line before parsing */
        { "nan.obj", "v nan 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
          "line 1: 'v' value 'nan' is not a finite number" },
        { "inf.obj", "v 0 0 0\n# a comment\nv 1 -inf 0\nv 0 1 0\nf 1 2 3\n",
          "line 3: 'v' value '-inf' is not a finite number" },
        { "big.obj", "v 0 0 0\nv 1e999 0 0\nv 0 1 0\nf 1 2 3\n",
          "line 2: 'v' value '1e999' is not a finite number" },
        { "vn.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 NaN 1\nf 1//1 2//1 3//1\n",
          "line 4: 'vn' value 'NaN' is not a finite number" },
        { "vt.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt infinity 0\nf 1/1 2/1 3/1\n",
          "line 4: 'vt' value 'infinity' is not a finite number" },
        { "far.obj", "v 0 0 0\nv 5000 0 0\nv 0 1 0\nf 1 2 3\n",
          "line 2: vertex coordinate 5000 is beyond the pack limit of 1000 m" },
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        assert_false(splat_mesh_obj(write_file(bad[i].name, bad[i].text), &m, &err));
        assert_non_null(err);
        if (!strstr(err, bad[i].msg))
            fail_msg("%s: '%s' lacks '%s'", bad[i].name, err, bad[i].msg);
        assert_null(m.v);
        free(err);
        err = NULL;
    }
    char path[128];
    snprintf(path, sizeof path, "%s/nope.obj", dir);
    assert_false(splat_mesh_obj(path, &m, &err));
    assert_string_equal(err, "No such file or directory");
    free(err);
    assert_false(splat_mesh_obj(dir, &m, &err));          /* a folder */
    assert_string_equal(err, "not a regular file: it is a folder");
    free(err);
    assert_false(splat_mesh_obj("/dev/zero", &m, &err));  /* would never end */
    assert_string_equal(err, "not a regular file: it is a character device");
    free(err);
}

/* The limits are checked on the text, before tinyobjloader parses or
 * triangulates anything: one face of 100000 corners (30 s of
 * triangulation before), more triangles than the index limit, more `v`
 * lines than any mesh within it can use.  Each is refused at once. */
static void test_obj_limits(void **state)
{
    (void)state;
    splat_mesh m;
    char *err = NULL;
    enum { CORNERS = 100000 };
    size_t cap = (size_t)CORNERS * 24 + 64, n = 0;
    char *text = malloc(cap);
    assert_non_null(text);
    /* one face of 100000 corners */
    n = (size_t)snprintf(text, cap, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf");
    for (int i = 0; i < CORNERS; i++)
        n += (size_t)snprintf(text + n, cap - n, " %d", 1 + i % 3);
    snprintf(text + n, cap - n, "\n");
    double t0 = (double)clock() / CLOCKS_PER_SEC;
    assert_false(splat_mesh_obj(write_file("face.obj", text), &m, &err));
    assert_true((double)clock() / CLOCKS_PER_SEC - t0 < 1.0);
    assert_non_null(strstr(err, "line 4: a face of more than 1024 corners"));
    free(err);
    /* a face of 1024 corners is within the limit */
    n = (size_t)snprintf(text, cap, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf");
    for (int i = 0; i < 1024; i++)
        n += (size_t)snprintf(text + n, cap - n, " %d", 1 + i % 3);
    snprintf(text + n, cap - n, "\n");
    assert_true(splat_obj_scan(text, strlen(text), &err));
    /* 65537 triangles: 196611 indices */
    n = (size_t)snprintf(text, cap, "v 0 0 0\nv 1 0 0\nv 0 1 0\n");
    for (int i = 0; i < 65537; i++)
        n += (size_t)snprintf(text + n, cap - n, "f 1 2 3\n");
    assert_false(splat_mesh_obj(write_file("faces.obj", text), &m, &err));
    assert_non_null(strstr(err, "line 65540: the faces so far make more than 196608 indices"));
    free(err);
    /* 196609 positions */
    n = 0;
    for (int i = 0; i < 196609; i++)
        n += (size_t)snprintf(text + n, cap - n, "v 0 0 0\n");
    assert_false(splat_obj_scan(text, n, &err));
    assert_non_null(strstr(err, "line 196609: more than 196608 'v' lines"));
    free(err);
    free(text);
}

static int setup(void **state)
{
    snprintf(dir, sizeof dir, "/tmp/test_mesh_XXXXXX");
    return mkdtemp(dir) ? 0 : -1;
}

static int teardown(void **state)
{
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    return system(cmd) == 0 ? 0 : -1;
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_builtins),
        cmocka_unit_test(test_far),
        cmocka_unit_test(test_obj_cube),
        cmocka_unit_test(test_obj_errors),
        cmocka_unit_test(test_obj_limits),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
