/* texture_files.c — the texture files a program names (texture
 * declarations and undergrowth textures): where one is named
 * (sg_texture_file_loc) and whether each is there and readable as an
 * image (sg_check_texture_files, `splatc check`). */
#include "sg_internal.h"
#include "util.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include <stb_image.h>

/* ---- texture files ----------------------------------------------------------- */

typedef void (*tex_fn)(void *user, const char *file, sg_loc loc);

/* Every texture file named in the program, with where: declarations,
 * then inline strings on node ports and input defaults, in file order. */
static void each_texture_file(const sg_program *p, tex_fn fn, void *user)
{
    for (int i = 0; i < p->ntextures; i++) {
        const sg_texdecl *t = p->textures[i];
        if (t->file && *t->file)
            fn(user, t->file, t->file_loc.line > 0 ? t->file_loc : t->loc);
    }
    for (int i = 0; i < p->nshaders; i++) {
        const sg_shader *s = p->shaders[i];
        const char *dir = p->files[s->file]->dir;
        for (int k = 0; k < s->nins; k++)
            if (s->ins[k].has_value && s->ins[k].value.kind == SG_V_STRING &&
                s->ins[k].type == IR_T_TEX) {
                char *path = splat_path_join(dir, s->ins[k].value.str);
                fn(user, path, s->ins[k].value.loc);
                free(path);
            }
        for (int k = 0; k < s->nnodes; k++) {
            const sg_node *n = &s->nodes[k];
            if (n->kind == SG_NODE_PAINTED)
                continue;
            for (int a = 0; a < n->nargs; a++)
                if (n->args[a].val.kind == SG_V_STRING) {
                    char *path = splat_path_join(dir, n->args[a].val.str);
                    fn(user, path, n->args[a].val.loc);
                    free(path);
                }
        }
    }
}

typedef struct tex_find { const char *file; sg_loc loc; } tex_find;

static void find_file(void *user, const char *file, sg_loc loc)
{
    tex_find *f = user;
    if (f->loc.line == 0 && !strcmp(f->file, file))
        f->loc = loc;
}

sg_loc sg_texture_file_loc(const sg_program *p, const char *file)
{
    tex_find f = { file, { NULL, 0, 0 } };
    each_texture_file(p, find_file, &f);
    return f.loc;
}

typedef struct tex_check {
    sg_diags *d;
    sg_map    seen;
    char    **keys;
    int       nkeys, cap;
    bool      ok;
} tex_check;

static void check_file(void *user, const char *file, sg_loc loc)
{
    tex_check *c = user;
    if (sg_map_get(&c->seen, file) >= 0)
        return;
    if (c->nkeys == c->cap) {
        c->cap = c->cap ? 2 * c->cap : 16;
        c->keys = xrealloc(c->keys, (size_t)c->cap * sizeof *c->keys);
    }
    c->keys[c->nkeys] = xstrdup(file);
    sg_map_put(&c->seen, c->keys[c->nkeys++], 0);
    /* opened as every input is (util.h): a FIFO or device is refused, not read */
    char why[256];
    int w, h, comp;
    FILE *f = splat_input_fopen(file, SPLAT_MAX_IMAGE_BYTES, why, sizeof why);
    if (!f) {
        sg_error(c->d, loc, SG_E_IO, file, why);
        c->ok = false;
        return;
    }
    if (!stbi_info_from_file(f, &w, &h, &comp)) {
        sg_error(c->d, loc, SG_E_IO, file, "not an image (PNG, JPEG, TGA or BMP)");
        c->ok = false;
    }
    fclose(f);
}

bool sg_check_texture_files(const sg_program *p, sg_diags *d)
{
    tex_check c = { d, { 0 }, NULL, 0, 0, true };
    each_texture_file(p, check_file, &c);
    sg_map_free(&c.seen);
    for (int i = 0; i < c.nkeys; i++)
        free(c.keys[i]);
    free(c.keys);
    return c.ok;
}
