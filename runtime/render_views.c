/* render_views.c — cameras (the default one, the view-projection, the
 * ray through a pixel), the frame block the shaders read, and the debug
 * views' table (abi.h SPLAT_VIEWS). */
#include "render_int.h"
#include "util.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

void rt_default_camera(const rt_pack *p, rt_camera *c)
{
    memset(c, 0, sizeof *c);
    /* The scene's own overview: its preset named "overview", else its first
     * preset (the scene's author knows where the terrain is worth seeing). */
    int k = rt_pack_camera_find(p, "overview");
    if (k < 0 && p->ncameras > 0)
        k = 0;
    if (k >= 0) {
        memcpy(c->position, p->cameras[k].position, sizeof c->position);
        memcpy(c->look, p->cameras[k].look, sizeof c->look);
        return;
    }
    /* Else from the south (z large: row 0 is north), 30 degrees down onto
     * the centre from a quarter of the extent: the default fog without
     * presets (1.5 / extent, rt_light_fog_default) hides about 31 % there
     * and less in front, where a camera seeing the whole terrain would see
     * mostly fog.
     * Never below the highest point. */
    double sx = p->size[0], sz = p->size[1], ext = sx > sz ? sx : sz;
    double top = p->height_offset + p->max_height, d = 0.25 * ext;
    c->look[0] = 0.5 * sx;
    c->look[1] = p->height_offset + 0.5 * p->max_height;
    c->look[2] = 0.5 * sz;
    c->position[0] = c->look[0];
    c->position[1] = c->look[1] + 0.5 * d;            /* sin 30 */
    c->position[2] = c->look[2] + 0.8660254037844386 * d;
    if (c->position[1] < top + 0.02 * ext)
        c->position[1] = top + 0.02 * ext;
}


const rt_image *rt_renderer_target(const rt_renderer *r)
{
    return r->scale > 1 ? &r->out : &r->color;
}

/* Camera-relative view-projection: rotation only (positions reach the GPU
 * relative to the camera), perspective with reversed infinite Z and
 * Vulkan's downward y.  Column-major. */
double rt_camera_fovy(const rt_camera *c)
{
    return c->fovy > 0 ? c->fovy : M_PI / 3.0;
}

static void camera_matrix(const rt_camera *c, double aspect, double m[16])
{
    double f[3], len = 0;
    for (int i = 0; i < 3; i++) {
        f[i] = c->look[i] - c->position[i];
        len += f[i] * f[i];
    }
    len = sqrt(len);
    if (len <= 0) {
        f[0] = 0; f[1] = 0; f[2] = -1; len = 1;
    }
    for (int i = 0; i < 3; i++)
        f[i] /= len;
    double up[3] = { 0, 1, 0 };
    if (fabs(f[1]) > 0.999) {
        up[1] = 0;
        up[2] = -1;
    }
    double s[3] = { f[1] * up[2] - f[2] * up[1], f[2] * up[0] - f[0] * up[2], f[0] * up[1] - f[1] * up[0] };
    double sl = sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
    for (int i = 0; i < 3; i++)
        s[i] /= sl;
    double u[3] = { s[1] * f[2] - s[2] * f[1], s[2] * f[0] - s[0] * f[2], s[0] * f[1] - s[1] * f[0] };
    double fovy = rt_camera_fovy(c);
    double znear = c->znear > 0 ? c->znear : 0.25;
    double t = 1.0 / tan(fovy / 2.0);
    /* rows of view: s, u, -f; clip = P * view */
    double v[3][3] = { { s[0], s[1], s[2] }, { u[0], u[1], u[2] }, { -f[0], -f[1], -f[2] } };
    memset(m, 0, 16 * sizeof *m);
    for (int col = 0; col < 3; col++) {
        m[col * 4 + 0] = t / aspect * v[0][col];
        m[col * 4 + 1] = -t * v[1][col];
        m[col * 4 + 2] = 0.0;
        m[col * 4 + 3] = -v[2][col];
    }
    m[3 * 4 + 2] = znear;
}

/* Gauss-Jordan with partial pivoting, column-major 4x4, in double. */
static void invert4(const double m[16], double out[16])
{
    double a[4][8];
    for (int r = 0; r < 4; r++)
        for (int c = 0; c < 4; c++) {
            a[r][c] = m[c * 4 + r];
            a[r][4 + c] = r == c;
        }
    for (int c = 0; c < 4; c++) {
        int piv = c;
        for (int r = c + 1; r < 4; r++)
            if (fabs(a[r][c]) > fabs(a[piv][c]))
                piv = r;
        for (int k = 0; k < 8; k++) {
            double t = a[c][k];
            a[c][k] = a[piv][k];
            a[piv][k] = t;
        }
        double d = a[c][c];
        for (int k = 0; k < 8; k++)
            a[c][k] /= d;
        for (int r = 0; r < 4; r++)
            if (r != c) {
                double f = a[r][c];
                for (int k = 0; k < 8; k++)
                    a[r][k] -= f * a[c][k];
            }
    }
    for (int r = 0; r < 4; r++)
        for (int c = 0; c < 4; c++)
            out[c * 4 + r] = a[r][4 + c];
}

/* The analytic sky (abi.c splat_sky) is the background of the final view
 * unless the caller gave a background colour. */
bool rt_render_sky_drawn(const rt_renderer *r)
{
    return r->default_clear && r->view == SPLAT_VIEW_FINAL && !r->wireframe;
}

void rt_render_fill_frame(rt_renderer *r, const rt_camera *c, splat_frame *fr)
{
    const rt_pack *p = r->p;
    memset(fr, 0, sizeof *fr);
    double vp[16], inv[16];
    /* the output's aspect: with a preview scale the internal size is
     * rounded up and its pixels are not quite square */
    camera_matrix(c, (double)r->out_w / r->out_h, vp);
    invert4(vp, inv);
    for (int i = 0; i < 16; i++) {
        fr->view_proj[i] = (float)vp[i];
        fr->inv_view_proj[i] = (float)inv[i];
    }
    fr->screen[0] = (float)r->desc.width;
    fr->screen[1] = (float)r->desc.height;
    fr->screen[2] = 0.0f;   /* the depth clear value (reversed Z) */
    fr->screen[3] = (float)(2.0 * tan(rt_camera_fovy(c) / 2.0) / r->desc.height);
    for (int i = 0; i < 3; i++)
        fr->camera[i] = (float)c->position[i];
    rt_light_frame(&r->light, p, r->desc.clear, fr);
    fr->light[3] = r->desc.no_shadows ? 0.0f : 1.0f;
    fr->sky_color[3] = rt_render_sky_drawn(r) ? 1.0f : 0.0f;
    fr->terrain[0] = (float)p->size[0];
    fr->terrain[1] = (float)p->size[1];
    fr->terrain[2] = (float)p->max_height;
    fr->terrain[3] = (float)p->height_offset;
    fr->texel[0] = (float)p->hf_width;
    fr->texel[1] = (float)p->hf_height;
    fr->texel[2] = 1.0f / (float)p->hf_width;
    fr->texel[3] = 1.0f / (float)p->hf_height;
    fr->destruction_atlas[0] = 64.0f;
    fr->destruction_atlas[1] = 1.0f;
    fr->destruction_atlas[2] = 1.0f;
    /* the crater table: the destruction upload pass (render_record.c) */
    /* precision far from the origin (compiler/precision.c): per site, the
     * camera's whole cells and fraction in double; the scale as the
     * shader reads it (float) */
    for (int k = 0; k < p->nsites; k++) {
        const rt_pack_site *st = &p->sites[k];
        for (int a = 0; a < 2; a++) {
            double s = st->param >= 0
                ? (double)*(const float *)((const uint8_t *)r->params_ubo.map +
                                           p->params[st->param].offset)
                : (double)(float)st->scale[a];
            double v = st->mul ? c->position[st->axes[a]] * s : c->position[st->axes[a]] / s;
            double cell = floor(v);
            fr->world[4 * k + a] = (float)cell;
            fr->world[4 * k + 2 + a] = (float)(v - cell);
        }
    }
    fr->view[0] = (uint32_t)r->view;
    fr->view[1] = (uint32_t)(r->view_material > 0 ? r->view_material : 0);
}

/* A patch's push constants: its corner and side on the vertex lattice
 * and the camera's lattice point and offset from it (abi.h splat_push),
 * all in double here.  Every lattice index is whole, so neighbouring
 * patches compute their shared vertices from the same numbers. */
static const struct view_row {
    const char *name;
    int         key;
    rt_tonemap  tonemap;
} view_rows[SPLAT_VIEW_COUNT] = {
#define X(id, num, name, key, tm, where, glsl) [num] = { name, key, RT_TONEMAP_##tm },
    SPLAT_VIEWS(X)
#undef X
};

const char *rt_view_name(splat_view v)
{
    return (unsigned)v < SPLAT_VIEW_COUNT ? view_rows[v].name : "?";
}

rt_tonemap rt_view_tonemap(splat_view v)
{
    return (unsigned)v < SPLAT_VIEW_COUNT ? view_rows[v].tonemap : RT_TONEMAP_NONE;
}

int rt_view_by_key(int key)
{
    for (int v = 0; v < SPLAT_VIEW_COUNT; v++)
        if (view_rows[v].key == key)
            return v;
    return -1;
}

void rt_view_list(char *buf, size_t n)
{
    size_t len = 0;
    if (n)
        buf[0] = 0;
    for (int v = 0; v < SPLAT_VIEW_COUNT && len < n; v++)
        len += (size_t)snprintf(buf + len, n - len, "%s%s%s", v ? "|" : "", view_rows[v].name,
                                v == SPLAT_VIEW_MASK ? ":MATERIAL" : "");
}

bool rt_parse_view(const char *s, const rt_pack *p, splat_view *view, int *material, rt_error *e)
{
    *material = 0;
    if (!strncmp(s, "mask:", 5)) {
        int m = rt_pack_material_find(p, s + 5);
        if (m < 0) {
            char what[256];
            snprintf(what, sizeof what, "--view %s: the pack has no material '%s'", s, s + 5);
            return rt_fail(e, RT_E_PACK_FIELD, p->dir, what);
        }
        *view = SPLAT_VIEW_MASK;
        *material = m;
        return true;
    }
    for (int v = 0; v < SPLAT_VIEW_COUNT; v++)
        if (v != SPLAT_VIEW_MASK && !strcmp(s, rt_view_name((splat_view)v))) {
            *view = (splat_view)v;
            return true;
        }
    char what[512], list[256];
    rt_view_list(list, sizeof list);
    snprintf(what, sizeof what, "unknown view '%s' (%s)", s, list);
    return rt_fail(e, RT_E_PACK_FIELD, "--view", what);
}

/* The direction through normalised window position (nx, ny) in -1..1
 * (y down) of camera_matrix's camera: rows s (right), u (up), f (forward). */
void rt_camera_ray(const rt_camera *c, double aspect, double nx, double ny, double dir[3])
{
    double f[3], len = 0;
    for (int i = 0; i < 3; i++) {
        f[i] = c->look[i] - c->position[i];
        len += f[i] * f[i];
    }
    len = len > 0 ? sqrt(len) : 1;
    for (int i = 0; i < 3; i++)
        f[i] /= len;
    double up[3] = { 0, 1, 0 };
    if (fabs(f[1]) > 0.999) {
        up[1] = 0;
        up[2] = -1;
    }
    double s[3] = { f[1] * up[2] - f[2] * up[1], f[2] * up[0] - f[0] * up[2],
                    f[0] * up[1] - f[1] * up[0] };
    double sl = sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
    for (int i = 0; i < 3; i++)
        s[i] /= sl;
    double u[3] = { s[1] * f[2] - s[2] * f[1], s[2] * f[0] - s[0] * f[2],
                    s[0] * f[1] - s[1] * f[0] };
    double t = tan(rt_camera_fovy(c) / 2.0);
    for (int i = 0; i < 3; i++)
        dir[i] = f[i] + s[i] * nx * t * aspect - u[i] * ny * t;
}
