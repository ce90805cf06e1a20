/* spirv_check.c — a pack's SPIR-V against what the runtime will bind it to,
 * before any of it reaches the driver.
 *
 * spirv-val (shader_compile.c) only says a module is well formed.  A well-formed
 * module of the wrong stage, or a fragment shader written for another
 * pipeline layout, still crashes drivers and the validation layer.  So
 * each module is reflected with SPIRV-Cross's C API (Debian
 * libspirv-cross-c-shared-dev) and compared with an rt_interface: its
 * entry point "main" and execution model; every descriptor it declares,
 * (set, binding), kind, image dimension / arrayness / component type,
 * array size and uniform block size, against one row of the binding table;
 * the push-constant block against splat_push; each specialization
 * constant against the ids the runtime supplies; the stage inputs and
 * outputs against the ABI's vertex attribute, varyings and colour targets.
 *
 * The table is the ABI's (compiler/abi.h); rt_interface_for builds the
 * interface of each pack shader role.  A new pipeline kind (compute
 * passes, shadow maps) adds its rows to rt_abi_bindings and, if it binds
 * pack shaders, a role. */
#include "rt_internal.h"

#include <stdarg.h>
#include <stdlib.h>
#include <string.h>

#include <spirv_cross/spirv_cross_c.h>

#define CS VK_SHADER_STAGE_COMPUTE_BIT
#define VF (VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT | CS)
#define FS (VK_SHADER_STAGE_FRAGMENT_BIT | CS)

/* Set 0 as pipelines.c lays it out (abi.h); set 1 depends on the pack and
 * is added by rt_interface_for.  One row per binding and painted format. */
const rt_binding_rule rt_abi_bindings[] = {
    /* set binding                       kind            dim  arr  type      bytes                stages painted */
    { 0, SPLAT_BIND_HEIGHTFIELD,         RT_RES_SAMPLED, RT_IMAGE_2D, false, RT_FLOAT, 0,                   VF, RT_PAINTED_ANY },
    { 0, SPLAT_BIND_FRAME,               RT_RES_UNIFORM, 0,           false, 0,        sizeof(splat_frame), VF, RT_PAINTED_ANY },
    { 0, SPLAT_BIND_PAINTED,             RT_RES_SAMPLED, RT_IMAGE_2D, true,  RT_FLOAT, 0,                   FS, RT_PAINTED_DENSE },
    { 0, SPLAT_BIND_PAINTED,             RT_RES_SAMPLED, RT_IMAGE_2D, false, RT_FLOAT, 0,                   FS, RT_PAINTED_SPARSE },
    { 0, SPLAT_BIND_DESTRUCTION_ATLAS,   RT_RES_SAMPLED, RT_IMAGE_2D, false, RT_FLOAT, 0,                   FS, RT_PAINTED_ANY },
    { 0, SPLAT_BIND_DESTRUCTION_INDEX,   RT_RES_SAMPLED, RT_IMAGE_2D, false, RT_FLOAT, 0,                   FS, RT_PAINTED_ANY },
    { 0, SPLAT_BIND_PAINTED_INDEX,       RT_RES_SAMPLED, RT_IMAGE_2D, true,  RT_UINT,  0,                   FS, RT_PAINTED_ANY },
    { 0, SPLAT_BIND_PAINTED_LEVEL,       RT_RES_SAMPLED, RT_IMAGE_2D, true,  RT_UINT,  0,                   FS, RT_PAINTED_ANY },
    { 0, SPLAT_BIND_SHADOW,              RT_RES_SAMPLED, RT_IMAGE_2D, false, RT_FLOAT, 0,                   FS, RT_PAINTED_ANY },
    { 0, SPLAT_BIND_HOLES,               RT_RES_SAMPLED, RT_IMAGE_2D, false, RT_FLOAT, 0,                   VK_SHADER_STAGE_VERTEX_BIT, RT_PAINTED_ANY },
    { 0, SPLAT_BIND_VECTORS,             RT_RES_STORAGE_BUFFER, 0,    false, 0,        0,                   FS, RT_PAINTED_ANY },
    /* compute stage (abi.h "compute stage"): depth, colour out, tiles; the
     * counters of the counting variant, fragment or compute */
    { 0, SPLAT_BIND_DEPTH,               RT_RES_SAMPLED, RT_IMAGE_2D, false, RT_FLOAT, 0,                   CS, RT_PAINTED_ANY },
    { 0, SPLAT_BIND_OUT,                 RT_RES_STORAGE_IMAGE, RT_IMAGE_2D, false, RT_FLOAT, 0,             CS, RT_PAINTED_ANY },
    { 0, SPLAT_BIND_TILES,               RT_RES_STORAGE_BUFFER, 0,    false, 0,        0,                   CS, RT_PAINTED_ANY },
    { 0, SPLAT_BIND_COUNTERS,            RT_RES_STORAGE_BUFFER, 0,    false, 0,        0,                   FS, RT_PAINTED_ANY },
};
const int rt_abi_nbindings = (int)(sizeof rt_abi_bindings / sizeof rt_abi_bindings[0]);

/* The varyings of abi.h, written by the vertex shader, read by fragment
 * shaders (a subset); the vertex attribute. */
static const rt_varying abi_varyings[] = { { 0, 3 }, { 1, 2 }, { 2, 3 } };
static const rt_varying abi_attributes[] = { { 0, 2 } };
static const uint32_t abi_spec_ids[] = { SPLAT_SPEC_VIEW, SPLAT_SPEC_LOD };

static const char *const role_names[RT_ROLE_COUNT] = {
    [RT_ROLE_VERTEX] = "the vertex shader",
    [RT_ROLE_COMPOSITE] = "a composite fragment shader",
    [RT_ROLE_REFERENCE] = "a multi-pass reference fragment shader",
    [RT_ROLE_COMPUTE] = "a compute shading shader",
    [RT_ROLE_UNDERGROWTH] = "an undergrowth mask shader",
    [RT_ROLE_FAR_BAKE] = "a far atlas bake shader",
    [RT_ROLE_FAR] = "the far atlas's compute shader",
};

bool rt_interface_for(const rt_pack *p, rt_shader_role role, rt_interface *out)
{
    memset(out, 0, sizeof *out);
    int n = rt_abi_nbindings + 4 + p->narrays;
    rt_binding_rule *b = calloc((size_t)n, sizeof *b);
    if (!b)
        return false;
    memcpy(b, rt_abi_bindings, sizeof rt_abi_bindings);
    int k = rt_abi_nbindings;
    b[k++] = (rt_binding_rule){ SPLAT_SET_MATERIAL, SPLAT_BIND_PARAMS, RT_RES_UNIFORM, 0, false,
                                0, p->params_size, FS, RT_PAINTED_ANY };
    for (int i = 0; i < p->narrays; i++)   /* the texture arrays: sampler2DArray */
        b[k++] = (rt_binding_rule){ SPLAT_SET_MATERIAL, (uint32_t)(SPLAT_BIND_TEXTURE0 + i),
                                    RT_RES_SAMPLED, RT_IMAGE_2D, true, RT_FLOAT, 0, FS, RT_PAINTED_ANY };
    /* abi.h "undergrowth masks" and "far atlas bake": the output */
    if (role == RT_ROLE_UNDERGROWTH || role == RT_ROLE_FAR_BAKE)
        b[k++] = (rt_binding_rule){ 2, 0, RT_RES_STORAGE_BUFFER, 0, false, 0, 0, CS,
                                    RT_PAINTED_ANY };
    /* the far atlas's albedo, normal and roughness (stand_in.h, screen.c) */
    for (uint32_t i = 0; role == RT_ROLE_FAR && i < 3; i++)
        b[k++] = (rt_binding_rule){ 2, 5 + i, RT_RES_SAMPLED, RT_IMAGE_2D, false, RT_FLOAT, 0, CS,
                                    RT_PAINTED_ANY };
    out->what = role_names[role];
    out->bindings = b;
    out->nbindings = k;
    out->painted = p->sparse ? RT_PAINTED_SPARSE : RT_PAINTED_DENSE;
    out->push_bytes = sizeof(splat_push);
    if (role == RT_ROLE_VERTEX) {
        out->stage = VK_SHADER_STAGE_VERTEX_BIT;
        out->inputs = abi_attributes;
        out->ninputs = 1;
        out->outputs = abi_varyings;
        out->noutputs = 3;
        out->outputs_exact = true;
    } else if (role == RT_ROLE_COMPUTE || role == RT_ROLE_UNDERGROWTH ||
               role == RT_ROLE_FAR_BAKE || role == RT_ROLE_FAR) {
        out->stage = VK_SHADER_STAGE_COMPUTE_BIT;   /* no stage inputs or outputs */
        out->spec_ids = abi_spec_ids;
        out->nspec = 2;
    } else {
        out->stage = VK_SHADER_STAGE_FRAGMENT_BIT;
        out->inputs = abi_varyings;
        out->ninputs = 3;
        out->colour_targets = role == RT_ROLE_REFERENCE ? 3 : 1;
        out->spec_ids = abi_spec_ids;
        out->nspec = 2;
    }
    return true;
}

void rt_interface_free(rt_interface *in)
{
    free((void *)in->bindings);
    memset(in, 0, sizeof *in);
}

/* ---- the check ------------------------------------------------------------ */

typedef struct checker {
    spvc_compiler c;
    const rt_interface *want;
    const char *path;
    rt_error *e;
} checker;

static bool bad(checker *k, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

static bool bad(checker *k, const char *fmt, ...)
{
    char msg[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    return rt_fail(k->e, RT_E_PACK_SHADER, k->path, k->want->what, msg);
}

static const char *model_name(SpvExecutionModel m)
{
    switch (m) {
    case SpvExecutionModelVertex: return "vertex";
    case SpvExecutionModelFragment: return "fragment";
    case SpvExecutionModelGLCompute: return "compute";
    case SpvExecutionModelGeometry: return "geometry";
    case SpvExecutionModelTessellationControl: return "tessellation control";
    case SpvExecutionModelTessellationEvaluation: return "tessellation evaluation";
    default: return "other";
    }
}

static SpvExecutionModel stage_model(VkShaderStageFlagBits s)
{
    return s == VK_SHADER_STAGE_VERTEX_BIT ? SpvExecutionModelVertex
         : s == VK_SHADER_STAGE_FRAGMENT_BIT ? SpvExecutionModelFragment
         : SpvExecutionModelGLCompute;
}

static const char *kind_name(rt_res r)
{
    switch (r) {
    case RT_RES_UNIFORM: return "a uniform block";
    case RT_RES_SAMPLED: return "a combined image sampler";
    case RT_RES_STORAGE_IMAGE: return "a storage image";
    case RT_RES_STORAGE_BUFFER: return "a storage buffer";
    }
    return "?";
}

static const char *dim_name(unsigned d)
{
    static const char *const names[] = { "1D", "2D", "3D", "cube", "rect", "buffer", "subpass" };
    return d < sizeof names / sizeof names[0] ? names[d] : "other";
}

static const char *comp_name(int t)
{
    return t == RT_FLOAT ? "float" : t == RT_UINT ? "uint" : t == RT_INT ? "int" : "other";
}

static int comp_of(spvc_basetype b)
{
    return b == SPVC_BASETYPE_FP32 ? RT_FLOAT : b == SPVC_BASETYPE_UINT32 ? RT_UINT
         : b == SPVC_BASETYPE_INT32 ? RT_INT : 0;
}

static bool entry_point(checker *k)
{
    const spvc_entry_point *eps;
    size_t n;
    if (spvc_compiler_get_entry_points(k->c, &eps, &n) != SPVC_SUCCESS)
        return bad(k, "its entry points cannot be read");
    SpvExecutionModel want = stage_model(k->want->stage);
    for (size_t i = 0; i < n; i++)
        if (eps[i].execution_model == want && !strcmp(eps[i].name, "main"))
            return spvc_compiler_set_entry_point(k->c, "main", want) == SPVC_SUCCESS ||
                   bad(k, "entry point 'main' cannot be selected");
    if (n == 0)
        return bad(k, "it has no entry point");
    return bad(k, "it has no %s entry point 'main' (its first: %s '%s')", model_name(want),
               model_name(eps[0].execution_model), eps[0].name);
}

/* One declared descriptor against its row of the table. */
static bool descriptor(checker *k, const spvc_reflected_resource *r, rt_res kind)
{
    uint32_t set = spvc_compiler_get_decoration(k->c, r->id, SpvDecorationDescriptorSet);
    uint32_t binding = spvc_compiler_get_decoration(k->c, r->id, SpvDecorationBinding);
    const rt_interface *w = k->want;
    const rt_binding_rule *row = NULL;
    for (int i = 0; i < w->nbindings && !row; i++) {
        const rt_binding_rule *b = &w->bindings[i];
        if (b->set == set && b->binding == binding &&
            (b->painted == RT_PAINTED_ANY || b->painted == w->painted))
            row = b;
    }
    if (!row)
        return bad(k, "'%s' is bound to set %u binding %u, which the pipeline layout does not have",
                   r->name, set, binding);
    if (row->kind != kind)
        return bad(k, "'%s' (set %u binding %u) is %s; the pipeline layout has %s there",
                   r->name, set, binding, kind_name(kind), kind_name(row->kind));
    if (!(row->stages & w->stage))
        return bad(k, "'%s' (set %u binding %u) is not visible to the %s stage",
                   r->name, set, binding, model_name(stage_model(w->stage)));
    spvc_type t = spvc_compiler_get_type_handle(k->c, r->type_id);
    if (spvc_type_get_num_array_dimensions(t) != 0)
        return bad(k, "'%s' (set %u binding %u) is an array; the pipeline layout binds one descriptor",
                   r->name, set, binding);
    if (kind == RT_RES_UNIFORM || kind == RT_RES_STORAGE_BUFFER) {
        spvc_type bt = spvc_compiler_get_type_handle(k->c, r->base_type_id);
        size_t size = 0;
        if (spvc_compiler_get_declared_struct_size(k->c, bt, &size) != SPVC_SUCCESS)
            return bad(k, "'%s': the size of its block cannot be read", r->name);
        if (row->bytes && size > row->bytes)
            return bad(k, "'%s' (set %u binding %u) declares %zu bytes; the runtime binds %u",
                       r->name, set, binding, size, row->bytes);
        return true;
    }
    /* images: dimension, arrayed, component type; storage images are
     * rgba32f (the ABI's only one, binding 8) */
    spvc_type it = spvc_compiler_get_type_handle(k->c, r->base_type_id);
    if (kind == RT_RES_STORAGE_IMAGE &&
        spvc_type_get_image_storage_format(it) != SpvImageFormatRgba32f)
        return bad(k, "'%s' (set %u binding %u) is a storage image of another format than "
                   "rgba32f, which the runtime binds", r->name, set, binding);
    unsigned dim = (unsigned)spvc_type_get_image_dimension(it);   /* SpvDim */
    bool arrayed = spvc_type_get_image_arrayed(it);
    spvc_type st = spvc_compiler_get_type_handle(k->c, spvc_type_get_image_sampled_type(it));
    int comp = comp_of(spvc_type_get_basetype(st));
    if (dim != row->dim || arrayed != row->arrayed || comp != row->comp ||
        spvc_type_get_image_multisampled(it))
        return bad(k, "'%s' (set %u binding %u) is a %s %s%s image; the runtime binds a %s %s%s "
                   "image there%s", r->name, set, binding, comp_name(comp), dim_name(dim),
                   arrayed ? " array" : "", comp_name(row->comp), dim_name(row->dim),
                   row->arrayed ? " array" : "",
                   set == 0 && binding == SPLAT_BIND_PAINTED
                       ? (w->painted == RT_PAINTED_SPARSE
                              ? " (the manifest's painted_format is sparse; the shader was built for dense)"
                              : " (the manifest's painted_format is dense; the shader was built for sparse)")
                       : "");
    return true;
}

static bool descriptors(checker *k, spvc_resources res)
{
    static const struct { spvc_resource_type t; rt_res kind; } kinds[] = {
        { SPVC_RESOURCE_TYPE_UNIFORM_BUFFER, RT_RES_UNIFORM },
        { SPVC_RESOURCE_TYPE_SAMPLED_IMAGE, RT_RES_SAMPLED },
        { SPVC_RESOURCE_TYPE_STORAGE_IMAGE, RT_RES_STORAGE_IMAGE },
        { SPVC_RESOURCE_TYPE_STORAGE_BUFFER, RT_RES_STORAGE_BUFFER },
    };
    for (size_t i = 0; i < sizeof kinds / sizeof kinds[0]; i++) {
        const spvc_reflected_resource *list;
        size_t n;
        if (spvc_resources_get_resource_list_for_type(res, kinds[i].t, &list, &n) != SPVC_SUCCESS)
            return bad(k, "its resources cannot be read");
        for (size_t j = 0; j < n; j++)
            if (!descriptor(k, &list[j], kinds[i].kind))
                return false;
    }
    /* kinds no pipeline layout of the runtime has */
    static const struct { spvc_resource_type t; const char *name; } never[] = {
        { SPVC_RESOURCE_TYPE_SUBPASS_INPUT, "a subpass input" },
        { SPVC_RESOURCE_TYPE_ATOMIC_COUNTER, "an atomic counter" },
        { SPVC_RESOURCE_TYPE_SEPARATE_IMAGE, "a separate image" },
        { SPVC_RESOURCE_TYPE_SEPARATE_SAMPLERS, "a separate sampler" },
        { SPVC_RESOURCE_TYPE_ACCELERATION_STRUCTURE, "an acceleration structure" },
        { SPVC_RESOURCE_TYPE_SHADER_RECORD_BUFFER, "a shader record buffer" },
    };
    for (size_t i = 0; i < sizeof never / sizeof never[0]; i++) {
        const spvc_reflected_resource *list;
        size_t n;
        if (spvc_resources_get_resource_list_for_type(res, never[i].t, &list, &n) != SPVC_SUCCESS)
            return bad(k, "its resources cannot be read");
        if (n)
            return bad(k, "'%s' is %s, which the runtime never binds", list[0].name, never[i].name);
    }
    return true;
}

static bool push_constants(checker *k, spvc_resources res)
{
    const spvc_reflected_resource *list;
    size_t n;
    if (spvc_resources_get_resource_list_for_type(res, SPVC_RESOURCE_TYPE_PUSH_CONSTANT, &list,
                                                  &n) != SPVC_SUCCESS)
        return bad(k, "its push constants cannot be read");
    for (size_t i = 0; i < n; i++) {
        spvc_type bt = spvc_compiler_get_type_handle(k->c, list[i].base_type_id);
        size_t size = 0;
        if (spvc_compiler_get_declared_struct_size(k->c, bt, &size) != SPVC_SUCCESS)
            return bad(k, "the size of its push-constant block cannot be read");
        if (size > k->want->push_bytes)
            return bad(k, "its push-constant block '%s' has %zu bytes; the runtime pushes %u",
                       list[i].name, size, k->want->push_bytes);
    }
    return true;
}

static bool spec_constants(checker *k)
{
    const spvc_specialization_constant *sc;
    size_t n;
    if (spvc_compiler_get_specialization_constants(k->c, &sc, &n) != SPVC_SUCCESS)
        return bad(k, "its specialization constants cannot be read");
    for (size_t i = 0; i < n; i++) {
        bool known = false;
        for (int j = 0; j < k->want->nspec; j++)
            known = known || k->want->spec_ids[j] == sc[i].constant_id;
        if (!known)
            return bad(k, "it declares specialization constant %u, which the runtime does not set",
                       sc[i].constant_id);
        spvc_constant c = spvc_compiler_get_constant_handle(k->c, sc[i].id);
        spvc_type t = spvc_compiler_get_type_handle(k->c, spvc_constant_get_type(c));
        spvc_basetype b = spvc_type_get_basetype(t);
        if ((b != SPVC_BASETYPE_UINT32 && b != SPVC_BASETYPE_INT32) ||
            spvc_type_get_vector_size(t) != 1)
            return bad(k, "its specialization constant %u is not a 32-bit integer; the runtime "
                       "sets a uint", sc[i].constant_id);
    }
    return true;
}

/* Stage inputs (or outputs) against the interface's list: every variable
 * at a listed location with a float vector of that size; `exact`: every
 * listed location present too. */
static bool stage_io(checker *k, spvc_resources res, bool input)
{
    const rt_interface *w = k->want;
    const rt_varying *list = input ? w->inputs : w->outputs;
    int nlist = input ? w->ninputs : w->noutputs;
    bool exact = !input && w->outputs_exact;
    const spvc_reflected_resource *vars;
    size_t n;
    if (spvc_resources_get_resource_list_for_type(
            res, input ? SPVC_RESOURCE_TYPE_STAGE_INPUT : SPVC_RESOURCE_TYPE_STAGE_OUTPUT,
            &vars, &n) != SPVC_SUCCESS)
        return bad(k, "its stage interface cannot be read");
    const char *io = input ? "input" : "output";
    unsigned seen = 0;
    for (size_t i = 0; i < n; i++) {
        uint32_t loc = spvc_compiler_get_decoration(k->c, vars[i].id, SpvDecorationLocation);
        spvc_type t = spvc_compiler_get_type_handle(k->c, vars[i].type_id);
        unsigned size = spvc_type_get_vector_size(t);
        bool fp = spvc_type_get_basetype(t) == SPVC_BASETYPE_FP32 &&
                  spvc_type_get_num_array_dimensions(t) == 0 && spvc_type_get_columns(t) == 1;
        if (!input && w->colour_targets) {
            if ((int)loc >= w->colour_targets || !fp)
                return bad(k, "%s '%s' at location %u is not one of the %d RGBA32F colour "
                           "target(s) of its render pass", io, vars[i].name, loc,
                           w->colour_targets);
            continue;
        }
        int at = -1;
        for (int j = 0; j < nlist; j++)
            if (list[j].location == loc)
                at = j;
        if (at < 0)
            return bad(k, "%s '%s' at location %u is not in the ABI's interface", io,
                       vars[i].name, loc);
        if (!fp || (int)size != list[at].components)
            return bad(k, "%s '%s' at location %u is not the ABI's vec%d", io, vars[i].name,
                       loc, list[at].components);
        seen |= 1u << at;
    }
    if (exact)
        for (int j = 0; j < nlist; j++)
            if (!(seen & 1u << j))
                return bad(k, "it writes no %s at location %u (vec%d), which fragment shaders read",
                           io, list[j].location, list[j].components);
    return true;
}

static void on_error(void *user, const char *msg)
{
    (void)user;
    (void)msg;   /* the call's result carries it (spvc_context_get_last_error_string) */
}

bool rt_spirv_check(const uint32_t *words, size_t nwords, const char *path,
                    const rt_interface *want, rt_error *e)
{
    spvc_context ctx = NULL;
    if (spvc_context_create(&ctx) != SPVC_SUCCESS)
        return rt_fail(e, RT_E_PACK_SHADER, path, want->what, "SPIRV-Cross cannot start");
    spvc_context_set_error_callback(ctx, on_error, NULL);
    checker k = { NULL, want, path, e };
    spvc_parsed_ir ir = NULL;
    spvc_resources res = NULL;
    bool ok;
    if (spvc_context_parse_spirv(ctx, words, nwords, &ir) != SPVC_SUCCESS ||
        spvc_context_create_compiler(ctx, SPVC_BACKEND_NONE, ir,
                                     SPVC_CAPTURE_MODE_TAKE_OWNERSHIP, &k.c) != SPVC_SUCCESS)
        ok = rt_fail(e, RT_E_PACK_SHADER, path, want->what, spvc_context_get_last_error_string(ctx));
    else
        ok = entry_point(&k) &&
             (spvc_compiler_create_shader_resources(k.c, &res) == SPVC_SUCCESS ||
              bad(&k, "its resources cannot be read")) &&
             descriptors(&k, res) && push_constants(&k, res) && spec_constants(&k) &&
             stage_io(&k, res, true) && stage_io(&k, res, false);
    spvc_context_destroy(ctx);
    return ok;
}
