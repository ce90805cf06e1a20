/* lowered.h — a material lowered from graph text, for the node tests
 * (lowered.c; test_nodes.c, test_parallax.c). */
#ifndef SPLAT_TEST_LOWERED_H
#define SPLAT_TEST_LOWERED_H

#include "sg.h"

typedef struct lowered { sg_program *p; ir ir; } lowered;

/* Load `text` (imports searched from the repository root, ".") and lower
 * its material `t`; fails the test (cmocka) on any diagnostic. */
void lowered_load(lowered *l, const char *text);
void lowered_free(lowered *l);

#endif
