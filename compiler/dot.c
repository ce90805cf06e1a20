/* dot.c — Graphviz DOT of a program's graphs (`splatc dot`).
 *
 * One cluster per shader or material: inputs and params as ellipses on
 * the left, nodes as boxes ("name : type", constant inputs listed inside),
 * outputs as ellipses on the right, one edge per wire labelled with the
 * ports it joins.  A node whose type is a shader (an instance) is a 3-D box
 * naming the node, the shader and the ports its wires feed:
 *
 *     mk : overlay      (shader)
 *     wired: base, blend
 *     opacity = 0.9
 *
 * With a material, only that material is drawn, its instances collapsed
 * into those boxes; with `expand` too, every shader it instantiates
 * (transitively) is drawn as a cluster of its own, as without a material.
 * Clusters follow the program's shader order and nodes their source order,
 * so the same program gives the same bytes.  `dot -Tsvg` draws it. */
#include "sg_internal.h"

#include <stdlib.h>
#include <string.h>

/* Print `s` escaped for a DOT string. */
static void esc(FILE *out, const char *s)
{
    for (; *s; s++) {
        if (*s == '"' || *s == '\\')
            fputc('\\', out);
        if (*s == '\n')
            fputs("\\n", out);
        else
            fputc(*s, out);
    }
}

static void value_text(FILE *out, const sg_value *v)
{
    switch (v->kind) {
    case SG_V_NUMBER:
        fprintf(out, "%g", v->num[0]);
        break;
    case SG_V_VEC:
        fprintf(out, "vec%d(", v->width);
        for (int i = 0; i < v->width; i++)
            fprintf(out, "%s%g", i ? ", " : "", v->num[i]);
        fputc(')', out);
        break;
    case SG_V_STRING:
        fputs("\\\"", out);
        esc(out, v->str);
        fputs("\\\"", out);
        break;
    case SG_V_PATH:
        for (int i = 0; i < v->nparts; i++)
            fprintf(out, "%s%s", i ? "." : "", v->parts[i]);
        break;
    default:
        break;
    }
}

/* The DOT id of whatever a value wire comes from, or false if it is a
 * constant (listed inside the node instead). */
static bool has_source(const sg_value *v)
{
    return v->kind == SG_V_PATH &&
           (v->ref == SG_REF_NODE || v->ref == SG_REF_IN || v->ref == SG_REF_PARAM);
}

static bool source_id(FILE *out, const sg_shader *s, const sg_value *v)
{
    if (!has_source(v))
        return false;
    switch (v->ref) {
    case SG_REF_NODE:  fprintf(out, "\"%s/%s\"", s->name, s->nodes[v->node].name); return true;
    case SG_REF_IN:    fprintf(out, "\"%s/in/%s\"", s->name, s->ins[v->index].name); return true;
    case SG_REF_PARAM: fprintf(out, "\"%s/param/%s\"", s->name, s->params[v->index].name); return true;
    default:           return false;
    }
}

static void wire_label(FILE *out, const sg_value *v, const char *to)
{
    fputs(" [label=\"", out);
    if (v->kind == SG_V_PATH && v->ref == SG_REF_NODE && v->nparts > 1) {
        for (int i = 1; i < v->nparts; i++)
            fprintf(out, "%s%s", i > 1 ? "." : "", v->parts[i]);
        fputs(" → ", out);
    }
    esc(out, to);
    fputs("\"];\n", out);
}

static void write_shader(const sg_program *p, int si, FILE *out)
{
    const sg_shader *s = p->shaders[si];
    fprintf(out, "  subgraph \"cluster_%s\" {\n    label=\"%s %s\";\n", s->name,
            s->is_material ? "material" : "shader", s->name);
    for (int i = 0; i < s->nins; i++) {
        const sg_port *in = &s->ins[i];
        fprintf(out, "    \"%s/in/%s\" [shape=ellipse, label=\"in %s %s", s->name, in->name,
                ir_type_name(in->type), in->name);
        if (in->has_value) {
            fputs(" = ", out);
            value_text(out, &in->value);
        }
        fputs("\"];\n", out);
    }
    for (int i = 0; i < s->nparams; i++) {
        const sg_port *pa = &s->params[i];
        fprintf(out, "    \"%s/param/%s\" [shape=ellipse, style=dashed, label=\"param %s %s = ",
                s->name, pa->name, ir_type_name(pa->type), pa->name);
        value_text(out, &pa->value);
        fputs("\"];\n", out);
    }
    for (int i = 0; i < s->nnodes; i++) {
        const sg_node *n = &s->nodes[i];
        bool inst = n->kind == SG_NODE_INSTANCE;
        fprintf(out, "    \"%s/%s\" [%slabel=\"%s : ", s->name, n->name,
                inst ? "shape=box3d, style=filled, fillcolor=\"#eef2ff\", " : "", n->name);
        esc(out, n->type);
        if (inst) {
            fputs("  (shader)", out);
            int wired = 0;
            for (int j = 0; j < n->nargs; j++)
                if (has_source(&n->args[j].val)) {
                    fputs(wired++ ? ", " : "\\nwired: ", out);
                    esc(out, n->args[j].port);
                }
        }
        for (int j = 0; j < n->nargs; j++) {
            const sg_value *v = &n->args[j].val;
            if (v->kind == SG_V_PATH && v->ref != SG_REF_TEXTURE && v->ref != SG_REF_INPUT)
                continue;
            fprintf(out, "\\n%s = ", n->args[j].port);
            value_text(out, v);
        }
        fputs("\"];\n", out);
    }
    for (int i = 0; i < s->nnodes; i++) {
        const sg_node *n = &s->nodes[i];
        for (int j = 0; j < n->nargs; j++) {
            const sg_value *v = &n->args[j].val;
            if (!has_source(v))
                continue;
            fputs("    ", out);
            source_id(out, s, v);
            fprintf(out, " -> \"%s/%s\"", s->name, n->name);
            wire_label(out, v, n->args[j].port);
        }
    }
    for (int i = 0; i < s->nouts; i++) {
        const sg_port *o = &s->outs[i];
        fprintf(out, "    \"%s/out/%s\" [shape=ellipse, style=bold, label=\"out %s",
                s->name, o->name, o->name);
        if (o->value.kind != SG_V_PATH || o->value.ref == SG_REF_TEXTURE ||
            o->value.ref == SG_REF_INPUT) {
            fputs(" = ", out);
            value_text(out, &o->value);
        }
        fputs("\"];\n", out);
        if (has_source(&o->value)) {
            fputs("    ", out);
            source_id(out, s, &o->value);
            fprintf(out, " -> \"%s/out/%s\"", s->name, o->name);
            wire_label(out, &o->value, o->name);
        }
    }
    fputs("  }\n", out);
}

void sg_write_dot(const sg_program *p, const char *material, bool expand, FILE *out)
{
    bool *show = calloc((size_t)p->nshaders + 1, sizeof *show);
    int *stack = malloc(((size_t)p->nshaders + 1) * sizeof *stack);
    if (!show || !stack)
        abort();
    if (material) {
        int mi = sg_material_find(p, material);
        int sp = 0;
        if (mi >= 0) {
            stack[sp++] = p->materials[mi];
            show[p->materials[mi]] = true;
        }
        while (expand && sp) {
            const sg_shader *s = p->shaders[stack[--sp]];
            for (int i = 0; i < s->nnodes; i++)
                if (s->nodes[i].kind == SG_NODE_INSTANCE && !show[s->nodes[i].shader]) {
                    show[s->nodes[i].shader] = true;
                    stack[sp++] = s->nodes[i].shader;
                }
        }
    } else {
        for (int i = 0; i < p->nshaders; i++)
            show[i] = true;
    }
    fputs("digraph splat {\n  rankdir=LR;\n  node [shape=box, fontname=\"Helvetica\"];\n"
          "  edge [fontname=\"Helvetica\", fontsize=10];\n", out);
    for (int i = 0; i < p->nshaders; i++)
        if (show[i])
            write_shader(p, i, out);
    fputs("}\n", out);
    free(show);
    free(stack);
}
