/* fuzz_parse.c — libFuzzer target for the front end: lex, parse, resolve
 * and type-check arbitrary bytes, print the diagnostics, and lower every
 * material of an error-free program (the builder asserts its invariants).
 * Built with -DSPLAT_FUZZ=ON (clang); `make fuzz` runs it from a corpus of
 * the project's graph files.  Imports resolve under a folder that does not
 * exist, so inputs cannot make it read the fuzzing machine's files (only
 * absolute paths remain, and only regular files are read). */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sg.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char *text = malloc(size + 1);
    if (!text)
        return 0;
    memcpy(text, data, size);
    text[size] = 0;
    sg_diags d;
    sg_diags_init(&d);
    sg_program *p = sg_load_string("/nonexistent-splat-fuzz/in.sg", text, NULL, &d);
    static FILE *null_out;
    if (!null_out)
        null_out = fopen("/dev/null", "w");
    if (null_out)
        sg_diags_print(&d, null_out);
    if (p && d.nerrors == 0) {
        for (int i = 0; i < sg_material_count(p); i++) {
            ir ir;
            ir_init(&ir);
            sg_lower_material(p, sg_material_name(p, i), &ir, &d);
            ir_free(&ir);
        }
    }
    sg_free(p);
    sg_diags_free(&d);
    free(text);
    return 0;
}
