/* ir_dump.c — the IR as .sg-like text, for `splatc dump` and for tests.
 *
 *   param float cliff.wetness = 0.2 [0, 1]
 *   texture t0 { file = "rock.png", filter = linear, mip = linear, wrap = repeat, srgb = true, range = 0:1 }
 *   painted m0 { mask = "fields" }
 *   node n1 : terrain.slope                        # float
 *   node n3 : mix { a = n1.out, b = 0.5, t = n2.out }  # float
 *   out cliff.mask = n3.out
 *
 * Constants are written in place as literals (vec3(…) for vectors),
 * textures as their declaration's name; every other node gets a line, in
 * id order (operands first), with its type as a comment.  Deterministic:
 * the same IR always gives the same text.
 */
#include "ir.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static const char *const input_names[IR_IN_COUNT] = {
#define X(id, name, type) name,
    IR_INPUTS(X)
#undef X
};

static void print_num(FILE *out, double v)
{
    if (isnan(v)) {
        fputs("nan", out);
        return;
    }
    if (isinf(v)) {
        fputs(v < 0 ? "-inf" : "inf", out);
        return;
    }
    char buf[40];
    snprintf(buf, sizeof buf, "%.17g", v);
    /* shortest text that reads back to the same double */
    for (int prec = 1; prec <= 17; prec++) {
        snprintf(buf, sizeof buf, "%.*g", prec, v);
        if (strtod(buf, NULL) == v)
            break;
    }
    fputs(buf, out);
    if (!strpbrk(buf, ".en"))
        fputs(".0", out);
}

static void print_operand(FILE *out, const ir *ir, ir_ref r)
{
    const ir_node *n = ir_get(ir, r);
    if (n->op == IR_OP_CONST) {
        int w = ir_type_width((ir_type)n->type);
        if (w > 1)
            fprintf(out, "%s(", ir_type_name((ir_type)n->type));
        for (int c = 0; c < w; c++) {
            if (c)
                fputs(", ", out);
            print_num(out, n->val[c]);
        }
        if (w > 1)
            fputc(')', out);
    } else if (n->op == IR_OP_TEXTURE) {
        fprintf(out, "t%u", n->imm);
    } else {
        fprintf(out, "n%u.out", r.id);
    }
}

static const char *const filter_names[] = {"linear", "nearest"};
static const char *const wrap_names[] = {"repeat", "clamp", "mirror"};

static void dump_node(FILE *out, const ir *ir, uint32_t id)
{
    const ir_node *n = &ir->nodes[id];
    const ir_opinfo *info = ir_opinfo_get((ir_op)n->op);
    fprintf(out, "node n%u : ", id);
    switch (n->op) {
    case IR_OP_INPUT:
        fputs(input_names[n->imm], out);
        break;
    case IR_OP_PARAM:
        fprintf(out, "param { name = \"%s\" }", ir->params[n->imm].name);
        break;
    case IR_OP_PAINTED:
        fprintf(out, "painted { mask = \"%s\" }", ir->painted[n->imm].name);
        break;
    case IR_OP_SPLAT:
        fputs("splat { x = ", out);
        print_operand(out, ir, n->arg[0]);
        fputs(" }", out);
        break;
    case IR_OP_SWIZZLE:
        fputs("swizzle { x = ", out);
        print_operand(out, ir, n->arg[0]);
        fputs(", comps = \"", out);
        for (int i = 0; i < IR_SWZ_N(n->imm); i++)
            fputc("xyzw"[IR_SWZ_C(n->imm, i)], out);
        fputs("\" }", out);
        break;
    default: {
        static const char *const construct_ports[] = {"x", "y", "z", "w"};
        fprintf(out, "%s {", info->name ? info->name : "construct");
        for (int i = 0; i < n->nargs; i++) {
            const char *port = n->op == IR_OP_CONSTRUCT ? construct_ports[i] : info->ports[i];
            fprintf(out, "%s %s = ", i ? "," : "", port);
            print_operand(out, ir, n->arg[i]);
        }
        fputs(" }", out);
        break;
    }
    }
    fprintf(out, "  # %s\n", ir_type_name((ir_type)n->type));
}

void ir_dump(const ir *ir, FILE *out)
{
    for (int i = 0; i < ir->nparams; i++) {
        const ir_param *p = &ir->params[i];
        fprintf(out, "param %s %s = ", ir_type_name(p->type), p->name);
        int w = ir_type_width(p->type);
        if (w > 1)
            fprintf(out, "%s(", ir_type_name(p->type));
        for (int c = 0; c < w; c++) {
            if (c)
                fputs(", ", out);
            print_num(out, p->def[c]);
        }
        if (w > 1)
            fputc(')', out);
        fputs(" [", out);
        print_num(out, p->lo);
        fputs(", ", out);
        print_num(out, p->hi);
        fputs("]\n", out);
    }
    for (int i = 0; i < ir->ntextures; i++) {
        const ir_texture *t = &ir->textures[i];
        fprintf(out, "texture t%d { file = \"%s\", filter = %s, mip = %s, wrap = %s, srgb = %s, range = ",
                i, t->file, filter_names[t->filter], filter_names[t->mip], wrap_names[t->wrap],
                t->srgb ? "true" : "false");
        print_num(out, t->lo);
        fputc(':', out);
        print_num(out, t->hi);
        fputs(" }\n", out);
    }
    for (int i = 0; i < ir->npainted; i++)
        fprintf(out, "painted m%d { mask = \"%s\" }\n", i, ir->painted[i].name);
    for (uint32_t id = 1; id < ir->nnodes; id++) {
        uint8_t op = ir->nodes[id].op;
        if (op != IR_OP_CONST && op != IR_OP_TEXTURE)
            dump_node(out, ir, id);
    }
    for (int i = 0; i < ir->nroots; i++) {
        fprintf(out, "out %s = ", ir->roots[i].name);
        if (ir_ref_ok(ir->roots[i].ref))
            print_operand(out, ir, ir->roots[i].ref);
        else
            fputs("none", out);
        fputc('\n', out);
    }
}
