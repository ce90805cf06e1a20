/* peakrss.c — wall time and peak resident memory of a command, for the
 * benchmarks where GNU time (/usr/bin/time -f "%e %M") is not installed:
 *
 *   peakrss -o FILE CMD [ARGS...]
 *
 * runs CMD, writes "WALL_S PEAK_KB\n" to FILE (the wall seconds and the
 * largest ru_maxrss of the process and the children it waited for,
 * getrusage(RUSAGE_CHILDREN)), and exits with CMD's status (128 + the
 * signal that ended it; 127 when it cannot be run). */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

int main(int argc, char **argv)
{
    if (argc < 4 || strcmp(argv[1], "-o") != 0) {
        fprintf(stderr, "usage: peakrss -o FILE CMD [ARGS...]\n");
        return 2;
    }
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    pid_t pid = fork();
    if (pid < 0) {
        perror("peakrss: fork");
        return 127;
    }
    if (pid == 0) {
        execvp(argv[3], argv + 3);
        fprintf(stderr, "peakrss: %s: %s\n", argv[3], strerror(errno));
        _exit(127);
    }
    int status = 0;
    while (waitpid(pid, &status, 0) < 0)
        if (errno != EINTR) {
            perror("peakrss: waitpid");
            return 127;
        }
    clock_gettime(CLOCK_MONOTONIC, &t1);
    struct rusage ru;
    getrusage(RUSAGE_CHILDREN, &ru);
    FILE *f = fopen(argv[2], "w");
    if (!f || fprintf(f, "%.2f %ld\n", (double)(t1.tv_sec - t0.tv_sec) +
                      (t1.tv_nsec - t0.tv_nsec) / 1e9, ru.ru_maxrss) < 0 || fclose(f) != 0) {
        fprintf(stderr, "peakrss: cannot write %s\n", argv[2]);
        return 127;
    }
    return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}
