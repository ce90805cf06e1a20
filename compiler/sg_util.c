/* sg_util.c — the front end's small utilities: an arena for everything
 * with the program's lifetime and a string -> int map (paths: util.h). */
#include "sg_internal.h"
#include "util.h"

#include <stdlib.h>
#include <string.h>

/* ---- arena ------------------------------------------------------------- */

struct sg_arena_block {
    sg_arena_block *next;
    size_t          used, cap;
    max_align_t     data[];
};

void *sg_alloc(sg_arena *a, size_t n)
{
    n = (n + sizeof(max_align_t) - 1) / sizeof(max_align_t) * sizeof(max_align_t);
    sg_arena_block *b = a->head;
    if (!b || b->cap - b->used < n) {
        size_t cap = 64 * 1024;
        if (n > cap / 4)
            cap = n;               /* big requests get a block of their own */
        b = xmalloc(sizeof *b + cap);               /* out of memory: nothing sane to do */
        b->used = 0;
        b->cap = cap;
        if (n == cap && a->head) { /* keep filling the current block */
            b->next = a->head->next;
            a->head->next = b;
            b->used = n;
            memset(b->data, 0, n);
            return b->data;
        }
        b->next = a->head;
        a->head = b;
    }
    void *p = (char *)b->data + b->used;
    b->used += n;
    memset(p, 0, n);
    return p;
}

char *sg_strndup(sg_arena *a, const char *s, size_t n)
{
    char *r = sg_alloc(a, n + 1);
    memcpy(r, s, n);
    r[n] = 0;
    return r;
}

char *sg_strdup(sg_arena *a, const char *s)
{
    return sg_strndup(a, s, strlen(s));
}

void sg_arena_free(sg_arena *a)
{
    sg_arena_block *b = a->head;
    while (b) {
        sg_arena_block *next = b->next;
        free(b);
        b = next;
    }
    a->head = NULL;
}

void *sg_push(sg_arena *a, void *items_ptr, int *n, int *cap, size_t elem)
{
    char **items = items_ptr;
    if (*n == *cap) {
        int ncap = *cap ? *cap * 2 : 4;
        char *p = sg_alloc(a, (size_t)ncap * elem);
        if (*n)
            memcpy(p, *items, (size_t)*n * elem);
        *items = p;
        *cap = ncap;
    }
    char *e = *items + (size_t)(*n)++ * elem;
    memset(e, 0, elem);
    return e;
}

/* ---- string map -------------------------------------------------------- */

static uint32_t hash_str(const char *s)
{
    uint32_t h = 2166136261u;           /* FNV-1a */
    for (; *s; s++)
        h = (h ^ (uint8_t)*s) * 16777619u;
    return h;
}

void sg_map_free(sg_map *m)
{
    free(m->keys);
    free(m->vals);
    memset(m, 0, sizeof *m);
}

int sg_map_get(const sg_map *m, const char *key)
{
    if (!m->cap)
        return -1;
    for (uint32_t i = hash_str(key) & (m->cap - 1);; i = (i + 1) & (m->cap - 1)) {
        if (!m->keys[i])
            return -1;
        if (!strcmp(m->keys[i], key))
            return m->vals[i];
    }
}

static void map_grow(sg_map *m)
{
    sg_map old = *m;
    m->cap = old.cap ? old.cap * 2 : 16;
    m->keys = calloc(m->cap, sizeof *m->keys);
    m->vals = calloc(m->cap, sizeof *m->vals);
    if (!m->keys || !m->vals)
        abort();
    m->n = 0;
    for (uint32_t i = 0; i < old.cap; i++)
        if (old.keys[i])
            sg_map_put(m, old.keys[i], old.vals[i]);
    free(old.keys);
    free(old.vals);
}

int sg_map_put(sg_map *m, const char *key, int val)
{
    if ((m->n + 1) * 2 > m->cap)
        map_grow(m);
    uint32_t i = hash_str(key) & (m->cap - 1);
    for (; m->keys[i]; i = (i + 1) & (m->cap - 1))
        if (!strcmp(m->keys[i], key))
            return m->vals[i];
    m->keys[i] = key;
    m->vals[i] = val;
    m->n++;
    return -1;
}

