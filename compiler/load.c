/* load.c — program loading (sg_load, sg_load_overlay, sg_load_string):
 * the files and their imports, each parsed (parse.c), then the whole
 * program resolved (resolve.c).
 *
 * Imports are loaded depth first after the importing file is parsed; a
 * file reached twice (diamond) is parsed once; a file reached while it is
 * still being loaded is an import cycle. */
#include "sg_internal.h"
#include "util.h"

#include <errno.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

typedef struct loader {
    sg_program *p;
    sg_diags   *d;
    const sg_overlay *ov;    /* texts held in memory, or NULL              */
    sg_map      keys;        /* file key -> index                          */
    int        *stack;       /* files being loaded (import cycle check)    */
    int         depth;
} loader;

/* Search folder s is the importing file's folder or an earlier one. */
static bool seen_before(const sg_program *p, const char *dir, int s)
{
    if (!strcmp(p->search[s], dir))
        return true;
    for (int k = 0; k < s; k++)
        if (!strcmp(p->search[k], p->search[s]))
            return true;
    return false;
}

/* An import found nowhere: the folders searched, in order, and how to add
 * one.  The errors that only follow from it (names it would have defined)
 * are left out by resolve (p->failed_imports). */
static void missing_import(loader *l, const sg_file *f, const sg_import *im)
{
    sg_program *p = l->p;
    size_t n = 256 + strlen(f->dir);
    for (int s = 0; s < p->nsearch; s++)
        n += strlen(p->search[s]) + 6;
    char *msg = xmalloc(n);
    size_t o = (size_t)snprintf(msg, n, "not found in '%s' (the importing file's folder)",
                                f->dir);
    /* each folder once, as given (the scene's folder often comes twice) */
    int last = -1;
    for (int s = 0; s < p->nsearch; s++)
        if (!seen_before(p, f->dir, s))
            last = s;
    for (int s = 0; s < p->nsearch; s++)
        if (!seen_before(p, f->dir, s))
            o += (size_t)snprintf(msg + o, n - o, "%s'%s'", s == last ? " or " : ", ",
                                  p->search[s]);
    snprintf(msg + o, n - o, "; add the folder that holds it with -I DIR or "
             "SPLATC_PATH=DIR[:DIR...]");
    sg_error(l->d, im->loc, SG_E_MISSING_IMPORT, im->path, msg);
    free(msg);
    p->failed_imports++;
}

/* The overlay's text for `path`, or NULL (read the disk). */
static const char *overlay_text(const loader *l, const char *path, size_t *len)
{
    return l->ov && l->ov->text ? l->ov->text(l->ov->user, path, len) : NULL;
}

/* File `known` reached again: an import cycle if it is still being
 * loaded (on the stack), reported with its path stack[i] -> ... -> known. */
static void report_cycle(const loader *l, int known, sg_loc from)
{
    const sg_program *p = l->p;
    for (int i = 0; i < l->depth; i++)
        if (l->stack[i] == known) {
            size_t n = 1;
            for (int j = i; j < l->depth; j++)
                n += strlen(p->files[l->stack[j]]->path) + 4;
            n += strlen(p->files[known]->path);
            char *msg = xmalloc(n);
            msg[0] = 0;
            for (int j = i; j < l->depth; j++) {
                strcat(msg, p->files[l->stack[j]]->path);
                strcat(msg, " -> ");
            }
            strcat(msg, p->files[known]->path);
            sg_error(l->d, from, SG_E_IMPORT_CYCLE, msg);
            free(msg);
            return;
        }
}

/* Lex, parse and load the imports of `path` (text given, or read). */
static int load_file(loader *l, const char *path, const char *text, size_t len,
                     sg_loc from, bool is_import)
{
    sg_program *p = l->p;
    char *rp = realpath(path, NULL);
    const char *key = rp ? rp : path;
    int known = sg_map_get(&l->keys, key);
    if (known >= 0) {
        free(rp);
        report_cycle(l, known, from);
        return known;
    }
    if (l->depth >= SG_MAX_DEPTH) {
        free(rp);
        sg_error(l->d, from, SG_E_TOO_DEEP, SG_MAX_DEPTH);
        return -1;
    }
    char *owned = NULL;
    if (!text && (text = overlay_text(l, path, &len)) && len > SPLAT_MAX_GRAPH_BYTES) {
        free(rp);
        sg_errorf(l->d, from, is_import ? SG_E_MISSING_IMPORT : SG_E_IO,
                  is_import ? "cannot import '%s': %s" : "cannot read '%s': %s", path,
                  "larger than the 16 MiB a graph file may have");
        if (is_import)
            p->failed_imports++;
        return -1;
    }
    if (!text) {
        /* only regular files: an import of /dev/zero or a FIFO must not hang */
        char err[256];
        owned = splat_input_read(path, SPLAT_MAX_GRAPH_BYTES, &len, err, sizeof err);
        if (!owned) {
            free(rp);
            if (is_import) {
                sg_error(l->d, from, SG_E_MISSING_IMPORT, path, err);
                p->failed_imports++;
            }
            else
                sg_error(l->d, from, SG_E_IO, path, err);
            return -1;
        }
        text = owned;
    }
    sg_file *f = sg_alloc(&p->arena, sizeof *f);
    f->path = sg_strdup(&p->arena, path);
    char *dir = splat_path_dir(path);
    f->dir = sg_strdup(&p->arena, dir);
    free(dir);
    f->key = sg_strdup(&p->arena, key);
    f->from = from;
    if (!is_import)
        f->from.file = f->path;   /* the caller's string need not outlive the load */
    free(rp);
    f->text = sg_alloc(&p->arena, len + 1);
    memcpy(f->text, text, len);
    f->len = len;
    free(owned);
    int fi = p->nfiles;
    *SG_PUSH(&p->arena, p->files, p->nfiles, p->capfiles) = f;
    sg_map_put(&l->keys, f->key, fi);
    sg_diags_add_source(l->d, f->path, f->text, f->len);

    sg_lex(&p->arena, f, l->d);
    sg_import *imports = NULL;
    int nimports = 0;
    sg_parse(p, fi, &imports, &nimports, l->d);

    l->stack[l->depth++] = fi;
    for (int i = 0; i < nimports; i++) {
        /* relative to the importing file, then the search paths */
        char *cand = splat_path_join(f->dir, imports[i].path);
        size_t olen;
        bool found = access(cand, R_OK) == 0 || overlay_text(l, cand, &olen);
        for (int s = 0; !found && s < p->nsearch; s++) {
            free(cand);
            cand = splat_path_join(p->search[s], imports[i].path);
            found = access(cand, R_OK) == 0 || overlay_text(l, cand, &olen);
        }
        if (!found) {
            free(cand);
            missing_import(l, f, &imports[i]);
            continue;
        }
        load_file(l, cand, NULL, 0, imports[i].loc, true);
        free(cand);
    }
    l->depth--;
    return fi;
}

static sg_program *load(const char *path, const char *text, size_t len,
                        const char *const *search_paths, const sg_overlay *ov,
                        sg_diags *d)
{
    sg_program *p = calloc(1, sizeof *p);
    if (!p)
        return NULL;
    int nsearch = 0;
    while (search_paths && search_paths[nsearch])
        nsearch++;
    p->search = sg_alloc(&p->arena, (size_t)(nsearch + 1) * sizeof *p->search);
    for (int i = 0; i < nsearch; i++)
        p->search[i] = sg_strdup(&p->arena, search_paths[i]);
    p->nsearch = nsearch;

    int errors0 = d->nerrors;
    loader l = { p, d, ov, { 0 }, NULL, 0 };
    l.stack = xmalloc(SG_MAX_DEPTH * sizeof *l.stack);
    load_file(&l, path, text, len, (sg_loc){ path, 0, 0 }, false);
    free(l.stack);
    sg_map_free(&l.keys);
    if (p->nfiles)
        sg_resolve(p, d);
    p->load_errors = d->nerrors - errors0;   /* this load's errors only */
    return p;
}

sg_program *sg_load(const char *path, const char *const *search_paths, sg_diags *d)
{
    return load(path, NULL, 0, search_paths, NULL, d);
}

sg_program *sg_load_overlay(const char *path, const char *const *search_paths,
                            const sg_overlay *ov, sg_diags *d)
{
    return load(path, NULL, 0, search_paths, ov, d);
}

sg_program *sg_load_string(const char *name, const char *text,
                           const char *const *search_paths, sg_diags *d)
{
    return load(name, text, strlen(text), search_paths, NULL, d);
}
