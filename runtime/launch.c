/* launch.c — the seconds since this process was launched, for the first
 * picture's time (issue 29: what the user waits for, from the command to
 * the picture).  The kernel's start time of the process (/proc/self/stat
 * field 22, clock ticks since boot, so 10 ms steps at the usual 100 Hz)
 * against CLOCK_BOOTTIME now; where /proc cannot be read, the time since
 * the first call, which splatview and splatbench make first thing in
 * main (so it misses only the loader's and the C runtime's start). */
#define _GNU_SOURCE
#include "splatrt.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

static double boot_now(void)
{
    struct timespec ts;
    if (clock_gettime(CLOCK_BOOTTIME, &ts) != 0)
        return -1;
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* The process's start in seconds since boot, or -1. */
static double start_since_boot(void)
{
    FILE *f = fopen("/proc/self/stat", "r");
    if (!f)
        return -1;
    char buf[1024];
    size_t n = fread(buf, 1, sizeof buf - 1, f);
    fclose(f);
    buf[n] = 0;
    /* the command name (field 2) may hold spaces and ')': fields 3 on
     * follow the last ')' */
    const char *s = strrchr(buf, ')');
    if (!s)
        return -1;
    unsigned long long start = 0;
    /* fields 3..21 skipped, 22 read */
    if (sscanf(s + 1, " %*c %*d %*d %*d %*d %*d %*u %*u %*u %*u %*u %*u %*u %*d %*d %*d %*d "
                      "%*d %*d %llu", &start) != 1)
        return -1;
    long hz = sysconf(_SC_CLK_TCK);
    return hz > 0 ? (double)start / (double)hz : -1;
}

double rt_seconds_since_launch(void)
{
    static double first = -1;   /* the fallback's origin: the first call */
    double now = boot_now();
    if (first < 0)
        first = now;
    double start = start_since_boot();
    if (start >= 0 && now >= start)
        return now - start;
    return now >= first ? now - first : 0;
}

bool rt_launch_tracing(void)
{
    static int on = -1;
    if (on < 0)
        on = getenv("SPLAT_LAUNCH_TRACE") != NULL;
    return on;
}

bool rt_launch_mark(const char *fmt, ...)
{
    if (!rt_launch_tracing())
        return true;
    char what[256];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(what, sizeof what, fmt, ap);
    va_end(ap);
    fprintf(stderr, "launch %.3f s: %s\n", rt_seconds_since_launch(), what);
    return true;
}
