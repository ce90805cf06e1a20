/* lowered.c — a material lowered from graph text (lowered.h). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

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

void lowered_texture(double u, double v, double rgba[4])
{
    for (int c = 0; c < 4; c++)
        rgba[c] = 0.5 + 0.25 * sin(2.1 * u + 1.3 * c) * cos(1.7 * v - 0.6 * c) +
                  0.2 * sin(0.37 * u * v + c);
}

void lowered_sample(void *user, int texture, double u, double v, double rgba[4])
{
    (void)user;
    (void)texture;
    lowered_texture(u, v, rgba);
}

ir_env lowered_env(double x, double y, double z)
{
    ir_env e;
    memset(&e, 0, sizeof e);
    e.normal[1] = 1;
    e.position[0] = x;
    e.position[1] = y;
    e.position[2] = z;
    e.sample = lowered_sample;
    return e;
}

void lowered_eval_node(const char *file, const ir_env *e, const char *output,
                       const char *value, const char *node, double out[4])
{
    char text[2048];
    snprintf(text, sizeof text,
             "import \"nodes/%s\"\n"
             "texture tx { file = \"graphs/textures/noise.png\" }\n"
             "material t {\n"
             "    node n : %s\n"
             "    out %s = %s\n"
             "}\n",
             file, node, output, value);
    lowered l;
    lowered_load(&l, text);
    char root[64];
    snprintf(root, sizeof root, "t.%s", output);
    ir_ref r = ir_find_root(&l.ir, root);
    assert_true(ir_ref_ok(r));
    ir_eval(&l.ir, r, e, out);
    lowered_free(&l);
}

static double perm(double x) { return fmod((34 * x + 1) * x, 289); }
static double pmod(double x) { return x - 289 * floor(x / 289); }

double lowered_hash_perm(double ix, double iy) { return perm(perm(pmod(ix)) + pmod(iy)) / 289; }
