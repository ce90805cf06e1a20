/* lowered.h — a material lowered from graph text, and what the node
 * tests evaluate it with (lowered.c; test_nodes.c, test_parallax.c,
 * test_look_nodes.c, test_shading_lod.c, test_footprint.c).  Include
 * after cmocka.h. */
#ifndef SPLAT_TEST_LOWERED_H
#define SPLAT_TEST_LOWERED_H

#include "sg.h"

typedef struct lowered { sg_program *p; ir ir; } lowered;

/* Load `text` (imports searched from the repository root, ".") and lower
 * its material `t`; fails the test (cmocka) on any diagnostic. */
void lowered_load(lowered *l, const char *text);
void lowered_free(lowered *l);

/* A texture: a smooth, non-periodic function of the raw uv, per channel,
 * so that a wrong offset or weight shows; lowered_sample reads it for
 * every texture (an ir_env.sample). */
void lowered_texture(double u, double v, double rgba[4]);
void lowered_sample(void *user, int texture, double u, double v, double rgba[4]);

/* An environment at terrain-local (x, y, z): the normal straight up,
 * lowered_sample for textures, everything else 0. */
ir_env lowered_env(double x, double y, double z);

/* `value` of material t as its `output` (albedo, mask, ...), after the
 * node text `node` (instanced as n) and `import "nodes/FILE"`, with a
 * texture tx declared, evaluated with ir_eval in `e`. */
void lowered_eval_node(const char *file, const ir_env *e, const char *output,
                       const char *value, const char *node, double out[4]);

/* nodes/noise.sg's hash_perm of an integer lattice point, in [0, 1). */
double lowered_hash_perm(double ix, double iy);

/* Fails the test unless |a - b| <= tol, naming a and the line. */
#define CLOSE(a, b, tol)                                                            \
    do {                                                                            \
        double a_ = (a), b_ = (b);                                                  \
        if (!(fabs(a_ - b_) <= (tol)))                                              \
            fail_msg("%s = %.17g, want %.17g (line %d)", #a, a_, b_, __LINE__);     \
    } while (0)

#endif
