/* glsl_check.c — see glsl_check.h. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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

void glsl_check_every_stage(const splat_layout *L, const splat_composite *c, const int *ug_slot,
                            const char *const *needles)
{
    struct { splat_glsl_desc g; spv_stage st; } v[] = {
        {{.title = "forward"}, SPV_STAGE_FRAGMENT},
        {{.title = "flat", .flat = true}, SPV_STAGE_FRAGMENT},
        {{.title = "compute", .compute = true}, SPV_STAGE_COMPUTE},
        {{.title = "ug", .compute = true, .ug_slot = ug_slot}, SPV_STAGE_COMPUTE},
    };
    for (size_t i = 0; i < sizeof v / sizeof v[0]; i++) {
        ir_buf b = {0};
        splat_composite_glsl(L, c, &v[i].g, &b);
        for (int k = 0; needles && needles[k]; k++)
            if (!strstr(b.s, needles[k]))
                fail_msg("%s: no '%s' in\n%s", v[i].g.title, needles[k], b.s);
        glsl_check_compiles(b.s, v[i].st, v[i].g.title);
        ir_buf_free(&b);
    }
}
