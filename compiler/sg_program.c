/* sg_program.c — a loaded program's accessors (sg.h): its files, its
 * materials by index or name, its scene and undergrowth, and sg_free.
 * The resolver, the loader and the back ends read the program through
 * these; they call nothing but the arena and map (sg_util.c). */
#include "sg_internal.h"

#include <stdlib.h>
#include <string.h>

void sg_free(sg_program *p)
{
    if (!p)
        return;
    for (int i = 0; i < p->nshaders; i++)
        free(p->shaders[i]->order);
    sg_map_free(&p->globals);
    sg_arena_free(&p->arena);
    free(p);
}

int sg_file_count(const sg_program *p) { return p->nfiles; }
const char *sg_file_path(const sg_program *p, int i) { return p->files[i]->path; }
int sg_material_count(const sg_program *p) { return p->nmaterials; }
const char *sg_material_name(const sg_program *p, int i)
{
    return p->shaders[p->materials[i]]->name;
}
sg_loc sg_material_loc(const sg_program *p, int i)
{
    return p->shaders[p->materials[i]]->loc;
}

int sg_material_find(const sg_program *p, const char *name)
{
    for (int i = 0; i < p->nmaterials; i++)
        if (!strcmp(p->shaders[p->materials[i]]->name, name))
            return i;
    return -1;
}
const sg_scene *sg_program_scene(const sg_program *p) { return p->scene; }
int sg_undergrowth_count(const sg_program *p, int material)
{
    return p->shaders[p->materials[material]]->nug;
}
const sg_undergrowth *sg_undergrowth_get(const sg_program *p, int material, int k)
{
    return &p->shaders[p->materials[material]]->ug[k];
}

/* ---- shaders and their outputs ---------------------------------------- */

const char *const sg_output_names[SG_OUT_COUNT] = {
#define X(id, name, type) name,
    SG_OUTPUTS(X)
#undef X
};


int sg_shader_find(const sg_program *p, const char *name)
{
    int g = sg_map_get(&p->globals, name);
    if (g < 0 || (g & 1) != SG_G_SHADER || p->shaders[g >> 1]->is_material)
        return -1;
    return g >> 1;
}

ir_type sg_node_output_type(const sg_program *p, const sg_shader *s,
                            const sg_node *n, int index)
{
    switch (n->kind) {
    case SG_NODE_OP:
    case SG_NODE_INPUT:
    case SG_NODE_PAINTED:
        return index == 0 ? n->out_type : IR_T_ERROR;
    case SG_NODE_INSTANCE: {
        const sg_shader *c = p->shaders[n->shader];
        return index < c->nouts ? c->outs[index].type : IR_T_ERROR;
    }
    default:
        return IR_T_ERROR;
    }
}
