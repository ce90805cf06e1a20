/* precision.c — shading far from the origin (large worlds).
 *
 * Materials read terrain.position, terrain-local metres, in fp32: past a
 * few hundred kilometres a texture repeating every metre loses its texels.
 * Patches are drawn camera-relative (splat_offset(): surface - camera,
 * precise), so this pass rewrites the uses of position that are periodic:
 *
 *   a "site" is X = position.AB / S or position.AB * S (two components,
 *   S a constant or a float param, the same every frame); with the camera
 *   c in double on the CPU, X = C + F where C = floor(c.AB / S) (whole
 *   cells) and F = frac(c.AB / S) + offset.AB / S (small, precise);
 *   the runtime passes (C, frac(c.AB / S)) per site in u_frame.world[k]
 *   (abi.h), and
 *     sample(tex, X)  with a repeating texture  ->  texture(tex, F)
 *     fract(X)                                  ->  fract(F)
 *     floor(X)        (hash / ALU noise cells)  ->  C + floor(F)
 *   all exact modulo the texture's period (C is whole), and C exact while
 *   it is below 2^24 cells (16,777 km for 1 m cells).
 *
 * A site is rewritten only where every use of it in the shader is one of
 * those three; the rest of position (other ops, a rotated projection, a
 * clamped texture) stays absolute fp32, and `splatc build` warns, per
 * material, with the distance from the origin at which fp32's rounding of
 * position passes a quarter of the texel (or noise cell, or metre) it
 * feeds: 2^22 times that size (fp32 keeps 24 bits; half an ulp at
 * distance D is about D / 2^24), but only where the scene's terrain
 * reaches that distance (a 2 km terrain never meets a 12 000 km limit),
 * and at the node that reads position.
 *
 * Sites are collected once from every material (splat_sites_find, on the
 * layout's source ir), in node order, so their numbers are the same in
 * every shader of the pack and the manifest lists them (PACK.md).
 */
#include "compose.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <stb_image.h>

#include "abi.h"
#include "util.h"

/* Maps of a composite's emission copy (compose.c): its params to layout
 * slots, and to the terrain input a param stands for (composites read
 * inputs once into locals, as params); NULL maps: the layout's source. */
typedef struct maps {
    const int *param_of;   /* -1: no layout slot */
    const int *input_of;   /* -1: a real param   */
} maps;

static bool is_position(const ir_node *in, const maps *mp)
{
    if (in->op == IR_OP_INPUT)
        return in->imm == IR_IN_POSITION;
    return in->op == IR_OP_PARAM && mp && mp->input_of &&
           mp->input_of[in->imm] == IR_IN_POSITION;
}

/* The site of node n, if it is one. */
static bool site_of(const ir *ir, const ir_node *n, const maps *mp, splat_site *s)
{
    const int *param_of = mp ? mp->param_of : NULL;
    if (n->op == IR_OP_SWIZZLE && IR_SWZ_N(n->imm) == 2 &&
        is_position(ir_get(ir, n->arg[0]), mp)) {   /* position.AB / 1 */
        memset(s, 0, sizeof *s);
        s->swz = n->imm;
        s->param = -1;
        s->value[0] = s->value[1] = 1.0;
        return true;
    }
    if ((n->op != IR_OP_DIV && n->op != IR_OP_MUL) || n->type != IR_T_VEC2)
        return false;
    for (int k = 0; k < 2; k++) {
        if (n->op == IR_OP_DIV && k == 1)
            break;
        const ir_node *a = ir_get(ir, n->arg[k]), *b = ir_get(ir, n->arg[1 - k]);
        if (a->op != IR_OP_SWIZZLE || IR_SWZ_N(a->imm) != 2)
            continue;
        if (!is_position(ir_get(ir, a->arg[0]), mp))
            continue;
        memset(s, 0, sizeof *s);
        s->swz = a->imm;
        s->mul = n->op == IR_OP_MUL;
        s->param = -1;
        if (b->op == IR_OP_CONST) {
            s->value[0] = b->val[0];
            s->value[1] = b->val[1];
        } else if (b->op == IR_OP_SPLAT && ir_get(ir, b->arg[0])->op == IR_OP_CONST) {
            s->value[0] = s->value[1] = ir_get(ir, b->arg[0])->val[0];
        } else if (b->op == IR_OP_SPLAT && ir_get(ir, b->arg[0])->op == IR_OP_PARAM &&
                   ir_typeof(ir, b->arg[0]) == IR_T_FLOAT) {
            int p = (int)ir_get(ir, b->arg[0])->imm;
            s->param = param_of ? param_of[p] : p;
            if (s->param < 0)
                return false;
        } else {
            continue;
        }
        if (s->param < 0 && (!(s->value[0] != 0) || !(s->value[1] != 0) ||
                             !isfinite(s->value[0]) || !isfinite(s->value[1])))
            return false;
        return true;
    }
    return false;
}

static bool site_eq(const splat_site *a, const splat_site *b)
{
    return a->swz == b->swz && a->mul == b->mul && a->param == b->param &&
           (a->param >= 0 || ((float)a->value[0] == (float)b->value[0] &&
                              (float)a->value[1] == (float)b->value[1]));
}

/* Whether node u's use of site node x (operand `arg`) can be rewritten. */
static bool use_ok(const ir *ir, const ir_node *u, int arg)
{
    if (u->op == IR_OP_FLOOR || u->op == IR_OP_FRACT)
        return true;
    if ((u->op == IR_OP_SAMPLE || u->op == IR_OP_SAMPLE_GRAD) && arg == 1) {
        const ir_node *t = ir_get(ir, u->arg[0]);
        return t->op == IR_OP_TEXTURE && ir->textures[t->imm].wrap == IR_WRAP_REPEAT;
    }
    return false;
}

/* useful[id]: a site node with at least one rewritable use among `live`
 * nodes (NULL: all).  Each such use is rewritten on its own; the site's
 * other uses keep the absolute value (and splatc build warns). */
static uint8_t *useful_sites(const ir *ir, const maps *mp, const uint8_t *live)
{
    uint8_t *site = calloc(ir->nnodes ? ir->nnodes : 1, 1);
    uint8_t *st = calloc(ir->nnodes ? ir->nnodes : 1, 1);
    if (!site || !st) {
        free(site);
        free(st);
        return NULL;
    }
    splat_site s;
    for (uint32_t i = 1; i < ir->nnodes; i++)
        if ((!live || live[i]) && site_of(ir, &ir->nodes[i], mp, &s))
            site[i] = 1;
    for (uint32_t i = 1; i < ir->nnodes; i++) {
        if (live && !live[i]) continue;
        const ir_node *u = &ir->nodes[i];
        for (int k = 0; k < u->nargs; k++)
            if (site[u->arg[k].id] && use_ok(ir, u, k))
                st[u->arg[k].id] = 1;
    }
    free(site);
    return st;
}

bool splat_sites_find(splat_layout *L)
{
    const ir *ir = L->src;
    uint8_t *ok = useful_sites(ir, NULL, NULL);
    if (!ok) return false;
    for (uint32_t i = 1; i < ir->nnodes; i++) {
        splat_site s;
        if (!ok[i] || !site_of(ir, &ir->nodes[i], NULL, &s))
            continue;
        bool have = false;
        for (int k = 0; k < L->nsites && !have; k++)
            have = site_eq(&L->sites[k], &s);
        if (have || L->nsites == SPLAT_WORLD_SITES)
            continue;
        L->sites[L->nsites++] = s;
    }
    free(ok);
    return true;
}

/* ---- emission ----------------------------------------------------------- */

static const char *const axis = "xyzw";

/* F of site k: frac(c / S) + offset / S (or * S). */
static void site_f(ir_buf *b, int k, const splat_site *s, const char *scale)
{
    ir_buf_printf(b, "(u_frame.world[%d].zw + splat_offset().%c%c %s %s)", k,
                  axis[IR_SWZ_C(s->swz, 0)], axis[IR_SWZ_C(s->swz, 1)],
                  s->mul ? "*" : "/", scale);
}

char **splat_sites_overrides(const splat_layout *L, const ir *ir,
                             const int *param_of, const int *input_of,
                             const glsl_names *names)
{
    maps mp = { param_of, input_of };
    char **ov = calloc(ir->nnodes ? ir->nnodes : 1, sizeof *ov);
    uint8_t *ok = ov ? useful_sites(ir, &mp, NULL) : NULL;
    if (!ok) {
        free(ov);
        return NULL;
    }
    for (uint32_t i = 1; i < ir->nnodes; i++) {
        const ir_node *u = &ir->nodes[i];
        for (int a = 0; a < u->nargs; a++) {
            uint32_t x = u->arg[a].id;
            splat_site s;
            if (!ok[x] || !use_ok(ir, u, a) || !site_of(ir, &ir->nodes[x], &mp, &s))
                continue;
            int k = -1;
            for (int j = 0; j < L->nsites && k < 0; j++)
                if (site_eq(&L->sites[j], &s))
                    k = j;
            if (k < 0)
                continue;       /* beyond SPLAT_WORLD_SITES: stays absolute */
            /* the scale as the shader reads it */
            const ir_node *xn = &ir->nodes[x];
            int si = ir_get(ir, xn->arg[0])->op == IR_OP_SWIZZLE ? 1 : 0;
            const ir_node *sn = xn->op == IR_OP_SWIZZLE ? xn : ir_get(ir, xn->arg[si]);
            ir_buf scale = {0};
            if (sn->op == IR_OP_SPLAT && ir_get(ir, sn->arg[0])->op == IR_OP_PARAM)
                ir_buf_printf(&scale, "%s", names->param[ir_get(ir, sn->arg[0])->imm]);
            else {
                double v[2] = { s.value[0], s.value[1] };
                glsl_literal(&scale, IR_T_VEC2, v);
            }
            ir_buf f = {0};
            site_f(&f, k, &s, scale.s);
            ir_buf e = {0};
            if (u->op == IR_OP_FLOOR)
                ir_buf_printf(&e, "(u_frame.world[%d].xy + floor(%s))", k, f.s);
            else if (u->op == IR_OP_FRACT)
                ir_buf_printf(&e, "fract(%s)", f.s);
            else {
                /* a texture array's layer goes with the uv (abi.h set 1) */
                uint32_t t = ir_get(ir, u->arg[0])->imm;
                ir_buf uv = {0};
                if (names->texture_layer)
                    ir_buf_printf(&uv, "vec3(%s, %d.0)", f.s, names->texture_layer[t]);
                else
                    ir_buf_printf(&uv, "%s", f.s);
                if (u->op == IR_OP_SAMPLE_GRAD)   /* the gradients as they are */
                    ir_buf_printf(&e, "splat_texture_grad(%s, %s, $2, $3)", names->texture[t],
                                  uv.s);
                else
                    ir_buf_printf(&e, "texture(%s, %s)", names->texture[t], uv.s);
                ir_buf_free(&uv);
            }
            ov[i] = e.s;
            ir_buf_free(&f);
            ir_buf_free(&scale);
        }
    }
    free(ok);
    return ov;
}

void splat_sites_overrides_free(const ir *ir, char **ov)
{
    if (!ov) return;
    for (uint32_t i = 0; i < ir->nnodes; i++)
        free(ov[i]);
    free(ov);
}

/* ---- warnings ----------------------------------------------------------- */

/* Size in metres of what node u resolves when it reads site s: a texel of
 * a sampled texture (its width read from the file; 256 if unreadable), a
 * cell of the site otherwise (a param scale counts as 1 m). */
static double feature_size(const ir *ir, const ir_node *u, const splat_site *s)
{
    double cell = 1.0;
    if (s->param < 0) {
        double lo = fmin(fabs(s->value[0]), fabs(s->value[1]));
        double hi = fmax(fabs(s->value[0]), fabs(s->value[1]));
        cell = s->mul ? 1.0 / hi : lo;
    }
    if (u->op == IR_OP_SAMPLE || u->op == IR_OP_SAMPLE_GRAD) {
        long long w = 256, h = 0;
        int c = 0;
        bool is16;
        const char *file = ir->textures[ir_get(ir, u->arg[0])->imm].file;
        char why[256];
        FILE *f = splat_input_fopen(file, SPLAT_MAX_IMAGE_BYTES, why, sizeof why);
        if (!f || !splat_image_info(f, &w, &h, &c, &is16) || w < 1)
            w = 256;
        if (f)
            fclose(f);
        cell /= w;
    }
    return cell;
}

void splat_sites_warn(const splat_scene *s, sg_diags *d)
{
    const ir *ir = &s->ir;
    uint8_t *live = calloc(ir->nnodes ? ir->nnodes : 1, 1);
    uint32_t *stack = calloc(ir->nnodes ? ir->nnodes : 1, sizeof *stack);
    if (!live || !stack) {
        free(live);
        free(stack);
        return;
    }
    const sg_scene *sc = s->desc;
    /* the farthest a point of this terrain is from the origin */
    ir_ienv region;
    memset(&region, 0, sizeof region);
    splat_terrain_ranges(&s->terrain, 0, 0, s->terrain.width, s->terrain.height, &region);
    double reach = 0;
    for (int c = 0; c < 3; c++) {
        double far = fmax(fabs(region.position[c].lo), fabs(region.position[c].hi));
        reach += far * far;
    }
    reach = sqrt(reach);
    for (int m = 0; m < sc->nmaterials; m++) {
        memset(live, 0, ir->nnodes);
        size_t plen = strlen(sc->materials[m]);
        int n = 0;
        for (int r = 0; r < ir->nroots; r++) {
            const char *name = ir->roots[r].name;
            if (strncmp(name, sc->materials[m], plen) == 0 && name[plen] == '.' &&
                !live[ir->roots[r].ref.id]) {
                live[ir->roots[r].ref.id] = 1;
                stack[n++] = ir->roots[r].ref.id;
            }
        }
        while (n > 0) {
            const ir_node *u = &ir->nodes[stack[--n]];
            for (int k = 0; k < u->nargs; k++)
                if (!live[u->arg[k].id]) {
                    live[u->arg[k].id] = 1;
                    stack[n++] = u->arg[k].id;
                }
        }
        /* Each use of position that is not rewritten: the size of what
         * it resolves (a site's texel or cell, else a metre) */
        double worst = INFINITY;
        const char *what = NULL;
        for (uint32_t i = 1; i < ir->nnodes; i++) {
            if (!live[i]) continue;
            const ir_node *u = &ir->nodes[i];
            splat_site us;
            bool u_site = site_of(ir, u, NULL, &us);
            for (int k = 0; k < u->nargs; k++) {
                const ir_node *a = ir_get(ir, u->arg[k]);
                bool raw = a->op == IR_OP_INPUT && a->imm == IR_IN_POSITION;
                if (raw && (u->op == IR_OP_SWIZZLE || u_site))
                    continue;            /* looked at through its users */
                splat_site st;
                bool a_site = site_of(ir, a, NULL, &st);
                bool pos_swz = a->op == IR_OP_SWIZZLE &&
                               ir_get(ir, a->arg[0])->op == IR_OP_INPUT &&
                               ir_get(ir, a->arg[0])->imm == IR_IN_POSITION;
                if (!raw && !a_site && !pos_swz)
                    continue;
                if (a_site && (use_ok(ir, u, k) || u_site))
                    continue;            /* rewritten, or a site of a site */
                double size = a_site ? feature_size(ir, u, &st) : 1.0;
                double dist = size * 4194304.0;  /* 2^22 */
                if (dist < worst) {
                    worst = dist;
                    const ir_opinfo *oi = ir_opinfo_get((ir_op)u->op);
                    what = oi->name ? oi->name : "an internal op";
                }
            }
        }
        /* only where this scene's terrain reaches that far from the origin */
        if (what && worst <= reach) {
            int mi = sg_material_find(s->prog, sc->materials[m]);
            sg_loc loc = mi >= 0 ? sg_material_loc(s->prog, mi) : sc->loc;
            char node[256] = "";
            const char *op = strcmp(what, "an internal op") ? what : NULL;
            if (sg_node_reading_input(s->prog, sc->materials[m], op, IR_IN_POSITION, &loc,
                                      node, sizeof node))
                sg_warning_id(d, loc, SG_E_W_PRECISION, "%s of material '%s' reads terrain.position through "
                           "'%s', which splatc cannot make camera-relative: its fp32 "
                           "rounding passes a quarter texel about %.0f km from the origin, "
                           "and this terrain reaches %.0f km", node, sc->materials[m], what,
                           worst / 1000.0, reach / 1000.0);
            else
                sg_warning_id(d, loc, SG_E_W_PRECISION, "material '%s' reads terrain.position through '%s', "
                           "which splatc cannot make camera-relative: its fp32 rounding "
                           "passes a quarter texel about %.0f km from the origin, and this "
                           "terrain reaches %.0f km", sc->materials[m], what, worst / 1000.0,
                           reach / 1000.0);
        }
    }
    free(live);
    free(stack);
}
