/* jobs.c — run n independent jobs on every core (at most RT_JOB_THREADS
 * threads, the caller's among them): the runtime's shader compiles
 * (glslang, spirv-val and the driver's compiler per pipeline; the pipeline
 * cache and vkCreate*Pipelines are free-threaded).  The first failure is
 * kept and stops the jobs not yet started. */
#include "rt_internal.h"

#include <pthread.h>
#include <unistd.h>

#define RT_JOB_THREADS 16

typedef struct jobs {
    rt_job_fn       fn;
    void           *ctx;
    int             n, next;
    pthread_mutex_t lock;
    rt_error        e;     /* the first failure */
} jobs;

static void *worker(void *arg)
{
    jobs *j = arg;
    for (;;) {
        pthread_mutex_lock(&j->lock);
        int k = j->e.id == RT_OK && j->next < j->n ? j->next++ : -1;
        pthread_mutex_unlock(&j->lock);
        if (k < 0)
            return NULL;
        rt_error e = {0};
        if (!j->fn(j->ctx, k, &e)) {
            pthread_mutex_lock(&j->lock);
            if (j->e.id == RT_OK)
                j->e = e;
            else
                rt_error_clear(&e);
            pthread_mutex_unlock(&j->lock);
        }
    }
}

int rt_job_threads(int n)
{
    long cores = sysconf(_SC_NPROCESSORS_ONLN);
    int t = cores > 1 ? (cores < RT_JOB_THREADS ? (int)cores : RT_JOB_THREADS) : 1;
    return n < t ? (n > 1 ? n : 1) : t;
}

bool rt_parallel(int n, rt_job_fn fn, void *ctx, rt_error *e)
{
    if (n <= 0)
        return true;
    jobs j = { .fn = fn, .ctx = ctx, .n = n };
    pthread_mutex_init(&j.lock, NULL);
    pthread_t th[RT_JOB_THREADS];
    int started = 0, nth = rt_job_threads(n);
    for (int i = 1; i < nth; i++)
        if (pthread_create(&th[started], NULL, worker, &j) == 0)
            started++;
    worker(&j);   /* the caller's share, or all of it when no thread started */
    for (int i = 0; i < started; i++)
        pthread_join(th[i], NULL);
    pthread_mutex_destroy(&j.lock);
    if (j.e.id == RT_OK)
        return true;
    *e = j.e;
    return false;
}
