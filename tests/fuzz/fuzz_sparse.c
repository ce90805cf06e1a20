/* fuzz_sparse.c — libFuzzer target for the painted.sparse reader
 * (sparse_read): arbitrary bytes as the file; a file it accepts is sampled
 * and its ranges read, as the runtime and the analysis would. */
#include <stdint.h>
#include <stdlib.h>

#include "sparse.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    sparse_masks s;
    sparse_error err;
    if (!sparse_read(&s, data, size, "fuzz", &err))
        return 0;
    for (int m = 0; m < s.nmasks && m < 8; m++) {
        volatile double v = sparse_sample(&s, m, 0.3, 0.7) + sparse_sample(&s, m, 1.5, -0.5);
        double lo, hi;
        sparse_range(&s, m, 0, 0, s.width, s.height, &lo, &hi);
        (void)v;
    }
    sparse_free(&s);
    return 0;
}
