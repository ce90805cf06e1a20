/* glsl_check.c — see glsl_check.h. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>

#include "glsl_check.h"

void glsl_check_compiles(const char *glsl, spv_stage stage, const char *name)
{
    uint32_t *w = NULL;
    size_t n = 0;
    char *log = NULL;
    bool ok = spv_compile(glsl, stage, name, &w, &n, &log);
    if (!ok)
        fprintf(stderr, "%s\n%s", glsl, log ? log : "");
    assert_true(ok);
    free(log);
    log = NULL;
    ok = spv_validate(w, n, &log);
    if (!ok)
        fprintf(stderr, "%s", log ? log : "");
    assert_true(ok);
    free(log);
    free(w);
}
