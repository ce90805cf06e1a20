/* lowered.c — a material lowered from graph text (lowered.h). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>

#include "lowered.h"

void lowered_load(lowered *l, const char *text)
{
    static const char *const search[] = {".", NULL};
    sg_diags d;
    sg_diags_init(&d);
    l->p = sg_load_string("test.sg", text, search, &d);
    ir_init(&l->ir);
    if (!l->p || d.nerrors || !sg_lower_material(l->p, "t", &l->ir, &d) || d.nerrors) {
        sg_diags_print(&d, stderr);
        fail_msg("cannot lower:\n%s", text);
    }
    sg_diags_free(&d);
}

void lowered_free(lowered *l)
{
    ir_free(&l->ir);
    sg_free(l->p);
}
