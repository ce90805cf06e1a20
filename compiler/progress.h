/* progress.h — progress of a build's long phases on stderr (progress.c). */
#ifndef SPLAT_PROGRESS_H
#define SPLAT_PROGRESS_H

#include <stdbool.h>

enum { SPLAT_PROGRESS_OFF, SPLAT_PROGRESS_BAR, SPLAT_PROGRESS_LINES };

typedef struct splat_progress {
    int         mode;           /* SPLAT_PROGRESS_*, from the terminal and
                                   $SPLATC_PROGRESS                        */
    const char *phase;          /* "compose", "glslang", "spirv-val"      */
    int         done, total;
    int         tenth;          /* lines mode: the last tenth printed     */
    double      t0, shown;      /* the phase's start, the last print      */
    bool        drawn;          /* bar mode: a line to clear at the end   */
} splat_progress;

void splat_progress_begin(splat_progress *p, const char *phase, int total);
/* One more of total done (callers serialise calls). */
void splat_progress_step(splat_progress *p);
void splat_progress_end(splat_progress *p);

#endif
