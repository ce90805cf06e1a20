/* progress.c — what a long build is doing, on stderr: on a terminal one
 * line rewritten in place (phase, k/N, per cent, ETA), cleared when the
 * phase ends; elsewhere nothing, unless SPLATC_PROGRESS=lines (for logs: a
 * line when a phase ends, and one per further tenth done at most once a
 * second) or never (not even on a terminal).  Any
 * thread may call splat_progress_step; prints are throttled to 10 a
 * second and serialised by the caller's lock (build_jobs.c's pool). */
#include "progress.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "util.h"   /* splat_now */

static int mode_from_env(void)
{
    const char *m = getenv("SPLATC_PROGRESS");
    if (m && !strcmp(m, "never"))
        return SPLAT_PROGRESS_OFF;
    if (m && !strcmp(m, "lines"))
        return SPLAT_PROGRESS_LINES;
    return isatty(STDERR_FILENO) ? SPLAT_PROGRESS_BAR : SPLAT_PROGRESS_OFF;
}

void splat_progress_begin(splat_progress *p, const char *phase, int total)
{
    memset(p, 0, sizeof *p);
    p->mode = total > 0 ? mode_from_env() : SPLAT_PROGRESS_OFF;
    p->phase = phase;
    p->total = total;
    p->t0 = p->shown = splat_now();
}

void splat_progress_step(splat_progress *p)
{
    p->done++;
    if (p->mode == SPLAT_PROGRESS_OFF)
        return;
    double now = splat_now(), el = now - p->t0;
    int tenth = 10 * p->done / p->total;
    if (p->mode == SPLAT_PROGRESS_LINES) {   /* a tenth more, a second on; or the end */
        if ((tenth > p->tenth && now - p->shown >= 1.0) || p->done == p->total) {
            fprintf(stderr, "splatc: %s %d/%d (%.1f s)\n", p->phase, p->done, p->total, el);
            p->tenth = tenth;
            p->shown = now;
        }
        return;
    }
    if (now - p->shown < 0.1 && p->done < p->total)
        return;
    p->shown = now;
    double eta = p->done ? el * (p->total - p->done) / p->done : 0;
    fprintf(stderr, "\rsplatc: %-10s %5d/%-5d %3d %%  ETA %4.0f s", p->phase, p->done,
            p->total, 100 * p->done / p->total, eta);
    p->drawn = true;
}

void splat_progress_end(splat_progress *p)
{
    if (p->drawn)
        fprintf(stderr, "\r\033[K");   /* the line goes: the report follows */
    p->drawn = false;
}
