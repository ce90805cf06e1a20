/* async_compile.c — compute pipelines made on worker threads while frames
 * go on (rt_render_desc.async_pipelines: the viewer's default).  A frame
 * shades a list whose pipeline is not made yet with the über-shader's
 * (the same materials, other branching: within 1/255 of the composite,
 * render.screen_* holds that); after the frame, the lists that got tiles
 * are queued here, and a later frame takes each pipeline once it is made.
 * Slots are published under the lock; every reader of a compute slot goes
 * through rt_pipelines_has_compute / rt_pipelines_compute, which take it
 * while workers run. */
#include "rt_internal.h"

#include <pthread.h>
#include <stdlib.h>

#define MAX_WORKERS 16

typedef struct rt_async {
    rt_async_make   make;     /* rt_pipelines_compute_make: what a worker runs */
    rt_device      *d;
    const rt_pack  *p;
    rt_pipelines   *pl;
    pthread_mutex_t lock;
    pthread_cond_t  wake;
    pthread_cond_t  idle;       /* pending came down to 0 (rt_async_wait)   */
    int            *queue;      /* slot indices (id * RT_CVARIANTS + variant) */
    int             head, tail, cap;
    unsigned char  *queued;     /* per slot: queued or being made            */
    int             pending;    /* queued + being made                       */
    bool            stop;
    rt_error        e;          /* the first failure                         */
    pthread_t       th[MAX_WORKERS];
    int             nth;
} rt_async;

static void *worker(void *arg)
{
    rt_async *a = arg;
    pthread_mutex_lock(&a->lock);
    for (;;) {
        while (!a->stop && a->head == a->tail)
            pthread_cond_wait(&a->wake, &a->lock);
        if (a->stop)
            break;
        int slot = a->queue[a->head++];
        pthread_mutex_unlock(&a->lock);
        VkPipeline pipe = VK_NULL_HANDLE;
        rt_error e = {0};
        bool ok = a->make(a->d, a->p, a->pl, slot / RT_CVARIANTS,
                          (unsigned)(slot % RT_CVARIANTS), &pipe, &e);
        pthread_mutex_lock(&a->lock);
        if (ok && a->pl->compute[slot])   /* made meanwhile by a frame */
            vkDestroyPipeline(a->d->dev, pipe, NULL);
        else if (ok)
            a->pl->compute[slot] = pipe;
        else if (a->e.id == RT_OK)
            a->e = e;
        else
            rt_error_clear(&e);
        a->queued[slot] = 0;
        if (--a->pending == 0)
            pthread_cond_broadcast(&a->idle);
    }
    pthread_mutex_unlock(&a->lock);
    return NULL;
}

bool rt_async_start(rt_device *d, const rt_pack *p, rt_pipelines *pl, rt_async_make make,
                    rt_error *e)
{
    rt_async *a = calloc(1, sizeof *a);
    int nslots = (p->ncombos + 1) * RT_CVARIANTS;
    if (a) {
        a->queue = malloc((size_t)nslots * sizeof *a->queue);
        a->queued = calloc((size_t)nslots, 1);
    }
    if (!a || !a->queue || !a->queued) {
        if (a) {
            free(a->queue);
            free(a->queued);
        }
        free(a);
        return rt_fail(e, RT_E_VULKAN, "pipelines", "out of memory");
    }
    a->make = make;
    a->d = d;
    a->p = p;
    a->pl = pl;
    a->cap = nslots;
    pthread_mutex_init(&a->lock, NULL);
    pthread_cond_init(&a->wake, NULL);
    pthread_cond_init(&a->idle, NULL);
    /* the caller's thread records frames: the workers take the rest */
    int want = rt_job_threads(MAX_WORKERS) - 1;
    for (int i = 0; i < (want > 0 ? want : 1); i++)
        if (pthread_create(&a->th[a->nth], NULL, worker, a) == 0)
            a->nth++;
    if (a->nth == 0) {
        pthread_cond_destroy(&a->idle);
        pthread_cond_destroy(&a->wake);
        pthread_mutex_destroy(&a->lock);
        free(a->queue);
        free(a->queued);
        free(a);
        return rt_fail(e, RT_E_VULKAN, "pipelines", "no worker thread could be started");
    }
    pl->async = a;
    return true;
}

void rt_async_stop(rt_pipelines *pl)
{
    rt_async *a = pl->async;
    if (!a)
        return;
    pthread_mutex_lock(&a->lock);
    a->stop = true;   /* what is queued is dropped; what is being made finishes */
    pthread_cond_broadcast(&a->wake);
    pthread_mutex_unlock(&a->lock);
    for (int i = 0; i < a->nth; i++)
        pthread_join(a->th[i], NULL);
    rt_error_clear(&a->e);
    pthread_cond_destroy(&a->idle);
    pthread_cond_destroy(&a->wake);
    pthread_mutex_destroy(&a->lock);
    free(a->queue);
    free(a->queued);
    free(a);
    pl->async = NULL;
}

void rt_async_request(rt_pipelines *pl, int id, unsigned variant)
{
    rt_async *a = pl->async;
    int slot = id * RT_CVARIANTS + (int)(variant % RT_CVARIANTS);
    pthread_mutex_lock(&a->lock);
    if (!a->queued[slot] && !pl->compute[slot] && a->tail < a->cap) {
        a->queued[slot] = 1;
        a->queue[a->tail++] = slot;   /* each slot at most once: cap suffices */
        a->pending++;
        pthread_cond_signal(&a->wake);
    }
    pthread_mutex_unlock(&a->lock);
}

int rt_async_pending(rt_pipelines *pl)
{
    rt_async *a = pl->async;
    if (!a)
        return 0;
    pthread_mutex_lock(&a->lock);
    int n = a->pending;
    pthread_mutex_unlock(&a->lock);
    return n;
}

void rt_async_wait(rt_pipelines *pl)
{
    rt_async *a = pl->async;
    if (!a)
        return;
    pthread_mutex_lock(&a->lock);
    while (a->pending > 0)
        pthread_cond_wait(&a->idle, &a->lock);
    pthread_mutex_unlock(&a->lock);
}

bool rt_async_failed(rt_pipelines *pl, rt_error *e)
{
    rt_async *a = pl->async;
    if (!a)
        return false;
    pthread_mutex_lock(&a->lock);
    bool failed = a->e.id != RT_OK;
    if (failed) {
        *e = a->e;
        a->e = (rt_error){0};
    }
    pthread_mutex_unlock(&a->lock);
    return failed;
}

VkPipeline rt_async_slot(rt_pipelines *pl, size_t slot)
{
    rt_async *a = pl->async;
    if (!a)
        return pl->compute[slot];
    pthread_mutex_lock(&a->lock);
    VkPipeline pipe = pl->compute[slot];
    pthread_mutex_unlock(&a->lock);
    return pipe;
}

VkPipeline rt_async_publish(rt_device *d, rt_pipelines *pl, size_t slot, VkPipeline pipe)
{
    rt_async *a = pl->async;
    if (a)
        pthread_mutex_lock(&a->lock);
    if (pl->compute[slot])   /* a worker made it meanwhile */
        vkDestroyPipeline(d->dev, pipe, NULL);
    else
        pl->compute[slot] = pipe;
    pipe = pl->compute[slot];
    if (a)
        pthread_mutex_unlock(&a->lock);
    return pipe;
}
