/* search.c — where imports are found: the one search path that every
 * entry point uses (splatc's subcommands, splat_scene_load without one,
 * the viewer's hot reload), so a scene resolves the same way everywhere.
 *
 * Order: the -I folders as given, $SPLATC_PATH (':'-separated), the
 * current folder, the project root (the nearest folder at or above the
 * file's that holds nodes/, so `import "graphs/grass.sg"` works from
 * examples/NAME/scene.sg), and last the installed node library
 * (splat_data_dir), as a C compiler finds its own headers.  The importing
 * file's folder and the scene's come before all of these (parse.c,
 * scene.c).
 */
#include "scene_load.h"
#include "util.h"

#include <limits.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#ifndef SPLATC_DATA_SUBDIR          /* CMake: CMAKE_INSTALL_DATADIR/splatc */
#define SPLATC_DATA_SUBDIR "share/splatc"
#endif

typedef struct paths {
    char **v;
    int    n, cap;
} paths;

static void add(paths *p, const char *dir)
{
    if (p->n + 2 > p->cap) {
        p->cap = p->cap ? 2 * p->cap : 8;
        p->v = xrealloc(p->v, (size_t)p->cap * sizeof *p->v);
    }
    p->v[p->n] = xstrdup(dir);
    p->v[++p->n] = NULL;
}

/* The nearest folder at or above `dir` holding a nodes/ folder, or NULL. */
static char *project_root(const char *dir)
{
    char *d = xstrdup(dir);
    for (int depth = 0; d && depth < 32; depth++) {
        char *nodes = splat_path_join(d, "nodes");
        bool found = splat_is_dir(nodes);
        free(nodes);
        if (found)
            return d;
        char *up = splat_path_parent(d);
        free(d);
        d = up;
    }
    free(d);
    return NULL;
}

char *splat_data_dir(void)
{
    char exe[PATH_MAX];
    ssize_t n = readlink("/proc/self/exe", exe, sizeof exe - 1);
    if (n <= 0)
        return NULL;
    exe[n] = 0;
    char *bin = splat_path_dir(exe);                 /* PREFIX/bin */
    char *prefix = splat_path_dir(bin);              /* PREFIX     */
    char *data = splat_path_join(prefix, SPLATC_DATA_SUBDIR);
    char *nodes = splat_path_join(data, "nodes");
    bool found = splat_is_dir(nodes);
    free(nodes);
    free(prefix);
    free(bin);
    if (!found) {
        free(data);
        return NULL;
    }
    return data;
}

char **splat_search_path(const char *const *include, int ninclude, const char *file)
{
    paths p = {0};
    for (int i = 0; i < ninclude; i++)
        add(&p, include[i]);
    const char *env = getenv("SPLATC_PATH");
    if (env && *env) {
        char *copy = xstrdup(env), *save = NULL;
        for (char *t = strtok_r(copy, ":", &save); t; t = strtok_r(NULL, ":", &save))
            add(&p, t);
        free(copy);
    }
    add(&p, ".");
    char *dir = splat_path_dir(file ? file : "./x");
    char *root = project_root(dir);
    if (root)
        add(&p, root);
    free(root);
    free(dir);
    char *data = splat_data_dir();
    if (data)
        add(&p, data);
    free(data);
    return p.v;
}

char **splat_import_path(const char *scene, const char *const *search)
{
    char **defaults = search ? NULL : splat_search_path(NULL, 0, scene);
    if (!search)
        search = (const char *const *)defaults;
    paths p = {0};
    char *dir = splat_path_dir(scene);
    add(&p, dir);
    free(dir);
    for (int i = 0; search[i]; i++)
        add(&p, search[i]);
    splat_search_path_free(defaults);
    return p.v;
}

void splat_search_path_free(char **v)
{
    for (int i = 0; v && v[i]; i++)
        free(v[i]);
    free(v);
}
