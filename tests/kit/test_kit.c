/* test_kit.c — the test kit's own checks fail when they should: pictures
 * that differ by more than the tolerance, a NaN on one side, a missing
 * picture, an unreadable file each count one failure, and kit_finish then
 * exits 1; equal pictures and a file read back count none.  (The kit's
 * failures here are wanted, so this program keeps its own verdict.) */
#include "kit.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static int wrong;

static void expect(bool cond, const char *what)
{
    if (!cond) {
        fprintf(stderr, "WRONG: %s\n", what);
        wrong++;
    }
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: test_kit OUTDIR\n");
        return 2;
    }
    enum { W = 4, H = 3, N = W * H * 4 };
    float a[N], b[N];
    for (int i = 0; i < N; i++)
        a[i] = b[i] = (float)i / N;
    int f0 = kit_failures();
    expect(kit_image_equal(a, b, W, H, "same"), "equal pictures are not equal");
    b[4 * 5 + 1] += 0.01f;
    expect(kit_image_near(a, b, W, H, 0.02, "within 0.02"), "0.01 apart is not within 0.02");
    expect(kit_failures() == f0, "passing checks counted failures");
    expect(!kit_image_near(a, b, W, H, 0.005, "within 0.005"), "0.01 apart passed 0.005");
    expect(kit_failures() == f0 + 1, "a failed comparison was not counted");
    b[4 * 5 + 1] = NAN;
    expect(!kit_image_near(a, b, W, H, 1e9, "NaN"), "a NaN passed");
    expect(isnan(kit_max_diff(a, b, N)), "kit_max_diff hides a NaN");
    expect(!kit_image_equal(a, NULL, W, H, "missing"), "a missing picture passed");
    expect(kit_failures() == f0 + 3, "NaN and missing pictures not counted");

    char *path = kit_join(argv[1], "kit_file.txt");
    FILE *f = path ? fopen(path, "wb") : NULL;
    expect(f && fwrite("abc\0def", 1, 7, f) == 7 && fclose(f) == 0, "cannot write a file");
    size_t n = 0;
    char *text = kit_read_file(path, &n);
    expect(text && n == 7 && !memcmp(text, "abc\0def", 8), "the file does not read back whole");
    free(text);
    expect(kit_failures() == f0 + 3, "a file read counted a failure");
    char *missing = kit_join(argv[1], "no_such_file");
    expect(!kit_read_file(missing, NULL) && kit_failures() == f0 + 4,
           "a missing file was read or not counted");
    free(missing);
    free(path);

    expect(kit_finish("kit") == 1, "kit_finish passed with failures counted");
    if (wrong) {
        fprintf(stderr, "test_kit: %d wrong\n", wrong);
        return 1;
    }
    printf("test_kit: the kit's checks fail when they should\n");
    return 0;
}
