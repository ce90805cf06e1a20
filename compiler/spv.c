/* spv.c — GLSL to SPIR-V through glslang's C API, validation through
 * SPIRV-Tools, atomic writes (see spv.h).  spv_optimize is in spv_opt.cpp. */
#include "spv.h"
#include "util.h"

#include <errno.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <glslang/Include/glslang_c_interface.h>
#include <glslang/Public/resource_limits_c.h>
#include <spirv-tools/libspirv.h>
#include <xxhash.h>

/* ---- a growable message ------------------------------------------------ */

typedef struct msgbuf { char *s; size_t len, cap; } msgbuf;

__attribute__((format(printf, 2, 3)))
static void msg_printf(msgbuf *b, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(NULL, 0, fmt, ap);
    va_end(ap);
    if (n < 0)
        return;
    if (b->len + (size_t)n + 1 > b->cap) {
        size_t cap = b->cap ? b->cap : 256;
        while (cap < b->len + (size_t)n + 1)
            cap *= 2;
        char *s = realloc(b->s, cap);
        if (!s)
            return;
        b->s = s;
        b->cap = cap;
    }
    va_start(ap, fmt);
    vsnprintf(b->s + b->len, b->cap - b->len, fmt, ap);
    va_end(ap);
    b->len += (size_t)n;
}

/* Hand the message to the caller's log (or drop it). */
static void msg_give(msgbuf *b, char **log)
{
    if (log)
        *log = b->s;
    else
        free(b->s);
    b->s = NULL;
    b->len = b->cap = 0;
}

/* ---- glslang ----------------------------------------------------------- */

static pthread_once_t glslang_once = PTHREAD_ONCE_INIT;
static int glslang_ready;

/* glslang's process-wide tables, built once and kept for the process's
 * lifetime (glslang_finalize_process would race with other threads). */
static void glslang_init(void)
{
    glslang_ready = glslang_initialize_process();
}

/* Copy line `lineno` (1-based) of `text` into `out`, without the newline. */
static void source_line(msgbuf *out, const char *text, int lineno)
{
    const char *p = text;
    for (int l = 1; l < lineno && p; l++) {
        p = strchr(p, '\n');
        if (p)
            p++;
    }
    if (!p || !*p) {
        msg_printf(out, "   %d | (no such line)\n", lineno);
        return;
    }
    const char *e = strchr(p, '\n');
    int len = e ? (int)(e - p) : (int)strlen(p);
    msg_printf(out, "%5d | %.*s\n", lineno, len, p);
}

/* Parse glslang's "ERROR: 0:42: message" (the "0" is the source string; it
 * may also be a name).  Returns the line and points *msg at the message, or
 * returns 0 when the entry has no location. */
static int parse_location(const char *entry, const char **msg)
{
    const char *c1 = strchr(entry, ':');
    if (!c1)
        return 0;
    char *end;
    long line = strtol(c1 + 1, &end, 10);
    if (end == c1 + 1 || *end != ':' || line <= 0 || line > 1L << 30)
        return 0;
    *msg = end + 1;
    while (**msg == ' ')
        (*msg)++;
    return (int)line;
}

/* Map a glslang info log onto the generated text: one entry per error with
 * the offending line.  Unlocated errors are copied as they are. */
static void map_glslang_log(msgbuf *out, const char *name, const char *glsl,
                            const char *log)
{
    int mapped = 0;
    const char *p = log ? log : "";
    while (*p) {
        const char *e = strchr(p, '\n');
        size_t len = e ? (size_t)(e - p) : strlen(p);
        char *entry = strndup(p, len);
        p += len + (e ? 1 : 0);
        if (!entry)
            break;
        const char *body = NULL;
        if (strncmp(entry, "ERROR: ", 7) == 0)
            body = entry + 7;
        if (body) {
            const char *msg;
            int line = parse_location(body, &msg);
            if (strstr(body, "compilation terminated")) {
                /* glslang's note that it stopped: not an error of its own */
            } else if (line > 0) {
                size_t n = strlen(msg);
                while (n > 0 && msg[n - 1] == ' ')
                    n--;
                msg_printf(out, "%s:%d: error: %.*s\n", name, line, (int)n, msg);
                source_line(out, glsl, line);
                mapped++;
            } else if (!strstr(body, "compilation errors")) {
                msg_printf(out, "%s: error: %s\n", name, body);
                mapped++;
            }
        }
        free(entry);
    }
    if (!mapped)
        msg_printf(out, "%s: error: %s\n", name,
                   log && *log ? log : "(glslang gave no message)");
}

static glslang_stage_t glslang_stage(int stage)
{
    switch (stage) {
    case SPV_STAGE_VERTEX:   return GLSLANG_STAGE_VERTEX;
    case SPV_STAGE_FRAGMENT: return GLSLANG_STAGE_FRAGMENT;
    default:                 return GLSLANG_STAGE_COMPUTE;
    }
}

bool spv_compile(const char *glsl, int stage, const char *name,
                 uint32_t **words, size_t *nwords, char **log)
{
    msgbuf m = {0};
    *words = NULL;
    *nwords = 0;
    if (log)
        *log = NULL;
    if (!name)
        name = "shader";
    if (stage < SPV_STAGE_VERTEX || stage > SPV_STAGE_COMPUTE) {
        msg_printf(&m, "internal compiler error: bad shader stage %d for '%s'\n",
                   stage, name);
        msg_give(&m, log);
        return false;
    }
    pthread_once(&glslang_once, glslang_init);
    if (!glslang_ready) {
        msg_printf(&m, "internal compiler error: glslang failed to initialise\n");
        msg_give(&m, log);
        return false;
    }

    const glslang_stage_t st = glslang_stage(stage);
    /* Cascading errors: report every error, not only the first. */
    const int messages = GLSLANG_MSG_SPV_RULES_BIT | GLSLANG_MSG_VULKAN_RULES_BIT |
                         GLSLANG_MSG_CASCADING_ERRORS_BIT;
    const glslang_input_t input = {
        .language = GLSLANG_SOURCE_GLSL,
        .stage = st,
        .client = GLSLANG_CLIENT_VULKAN,
        .client_version = GLSLANG_TARGET_VULKAN_1_2,
        .target_language = GLSLANG_TARGET_SPV,
        .target_language_version = GLSLANG_TARGET_SPV_1_5,
        .code = glsl,
        .default_version = 450,
        .default_profile = GLSLANG_NO_PROFILE,
        .force_default_version_and_profile = 0,
        .forward_compatible = 0,
        .messages = (glslang_messages_t)messages,
        .resource = glslang_default_resource(),
    };

    bool ok = false;
    glslang_program_t *prog = NULL;
    glslang_shader_t *sh = glslang_shader_create(&input);
    if (!sh) {
        msg_printf(&m, "internal compiler error: glslang could not create a shader for '%s'\n",
                   name);
        goto done;
    }
    if (!glslang_shader_preprocess(sh, &input) || !glslang_shader_parse(sh, &input)) {
        msg_printf(&m, "internal compiler error: generated GLSL for '%s' failed to compile:\n",
                   name);
        map_glslang_log(&m, name, glsl, glslang_shader_get_info_log(sh));
        goto done;
    }
    prog = glslang_program_create();
    if (!prog) {
        msg_printf(&m, "internal compiler error: glslang could not create a program for '%s'\n",
                   name);
        goto done;
    }
    glslang_program_add_shader(prog, sh);
    if (!glslang_program_link(prog, messages)) {
        msg_printf(&m, "internal compiler error: generated GLSL for '%s' failed to link:\n",
                   name);
        map_glslang_log(&m, name, glsl, glslang_program_get_info_log(prog));
        goto done;
    }
    /* glslang_program_SPIRV_generate would also run SPIRV-Tools' validator
     * (its default options set validate), and only as messages: callers
     * validate once with spv_validate, which fails on an invalid module. */
    glslang_spv_options_t spv_opts = {
        .disable_optimizer = true,
        .validate = false,
    };
    glslang_program_SPIRV_generate_with_options(prog, st, &spv_opts);
    size_t n = glslang_program_SPIRV_get_size(prog);
    const char *spv_msgs = glslang_program_SPIRV_get_messages(prog);
    if (n == 0) {
        msg_printf(&m, "internal compiler error: glslang generated no SPIR-V for '%s': %s\n",
                   name, spv_msgs ? spv_msgs : "");
        goto done;
    }
    uint32_t *w = malloc(n * sizeof *w);
    if (!w) {
        msg_printf(&m, "out of memory compiling '%s'\n", name);
        goto done;
    }
    glslang_program_SPIRV_get(prog, w);
    *words = w;
    *nwords = n;
    ok = true;
    if (spv_msgs && *spv_msgs)
        msg_printf(&m, "%s: %s", name, spv_msgs);

done:
    if (prog)
        glslang_program_delete(prog);
    if (sh)
        glslang_shader_delete(sh);
    if (m.s)
        msg_give(&m, log);
    return ok;
}

/* ---- SPIRV-Tools ------------------------------------------------------- */

bool spv_validate(const uint32_t *words, size_t nwords, char **log)
{
    msgbuf m = {0};
    if (log)
        *log = NULL;
    if (!words || nwords < 5) {
        msg_printf(&m, "spirv-val: module too short (%zu words)\n", nwords);
        msg_give(&m, log);
        return false;
    }
    spv_context ctx = spvContextCreate(SPV_ENV_VULKAN_1_2);
    spv_validator_options opts = spvValidatorOptionsCreate();
    if (!ctx || !opts) {
        msg_printf(&m, "spirv-val: cannot create a SPIRV-Tools context\n");
        if (opts)
            spvValidatorOptionsDestroy(opts);
        if (ctx)
            spvContextDestroy(ctx);
        msg_give(&m, log);
        return false;
    }
    spv_const_binary_t bin = { words, nwords };
    spv_diagnostic diag = NULL;
    spv_result_t r = spvValidateWithOptions(ctx, opts, &bin, &diag);
    if (r != SPV_SUCCESS) {
        if (diag && diag->error)
            msg_printf(&m, "spirv-val: %s (word %zu)\n", diag->error,
                       diag->position.index);
        else
            msg_printf(&m, "spirv-val: invalid module (result %d)\n", (int)r);
        msg_give(&m, log);
    }
    spvDiagnosticDestroy(diag);
    spvValidatorOptionsDestroy(opts);
    spvContextDestroy(ctx);
    return r == SPV_SUCCESS;
}

/* ---- the shape of a module (spv_shape) ---------------------------------- */

enum { OP_TYPE_FLOAT = 22, OP_TYPE_VECTOR = 23, OP_TYPE_MATRIX = 24, OP_CONSTANT = 43,
       OP_CONSTANT_COMPOSITE = 44 };

typedef struct shape_st {
    uint32_t      bound;
    uint32_t     *canon;     /* id -> its number in order of first use, 0: none */
    uint32_t     *fconst;    /* id -> 1 + canon of its type where the id is a
                                float-valued constant, else 0            */
    uint8_t      *ftype;     /* id is a float scalar, vector or matrix type  */
    uint32_t      next;
    XXH3_state_t *h;
} shape_st;

static uint32_t shape_canon(shape_st *s, uint32_t id)
{
    if (id >= s->bound)
        return 0xfffffffeu;
    if (!s->canon[id])
        s->canon[id] = ++s->next;
    return s->canon[id];
}

static spv_result_t shape_header(void *user, spv_endianness_t e, uint32_t magic,
                                 uint32_t version, uint32_t generator, uint32_t bound,
                                 uint32_t schema)
{
    (void)e, (void)magic, (void)generator, (void)schema;
    shape_st *s = user;
    if (bound == 0 || bound > (1u << 24))
        return SPV_ERROR_INVALID_BINARY;
    s->bound = bound;
    s->canon = xcalloc(bound, sizeof *s->canon);
    s->fconst = xcalloc(bound, sizeof *s->fconst);
    s->ftype = xcalloc(bound, 1);
    XXH3_128bits_update(s->h, &version, sizeof version);
    return SPV_SUCCESS;
}

static bool is_id_operand(spv_operand_type_t t)
{
    return t >= SPV_OPERAND_TYPE_ID && t <= SPV_OPERAND_TYPE_SCOPE_ID;
}

static spv_result_t shape_inst(void *user, const spv_parsed_instruction_t *in)
{
    shape_st *s = user;
    const uint32_t *w = in->words;
    uint32_t op = in->opcode, res = in->result_id, ty = in->type_id;
    if (!s->bound || res >= s->bound || ty >= s->bound)
        return SPV_ERROR_INVALID_BINARY;
    if (op == OP_TYPE_FLOAT ||
        ((op == OP_TYPE_VECTOR || op == OP_TYPE_MATRIX) && in->num_words >= 3 &&
         w[2] < s->bound && s->ftype[w[2]]))
        s->ftype[res] = 1;
    bool fc = false;
    if (op == OP_CONSTANT && s->ftype[ty])
        fc = true;
    else if (op == OP_CONSTANT_COMPOSITE && s->ftype[ty]) {
        fc = true;
        for (int k = 3; k < in->num_words; k++)
            fc = fc && w[k] < s->bound && s->fconst[w[k]];
    }
    if (fc) {   /* its value is left out, and its identity: uses name its type */
        s->fconst[res] = 1 + shape_canon(s, ty);
        return SPV_SUCCESS;
    }
    /* debug information (OpSourceContinued, OpSource, OpSourceExtension,
     * OpName, OpMemberName, OpString, OpLine, OpNoLine, OpModuleProcessed):
     * the generated GLSL's value names follow the compiler's numbering,
     * which a constant's value can shift; spirv-val's verdict does not
     * depend on them */
    if ((op >= 2 && op <= 8) || op == 317 || op == 330)
        return SPV_SUCCESS;
    uint32_t head[2] = { op, in->num_operands };
    XXH3_128bits_update(s->h, head, sizeof head);
    for (int k = 0; k < in->num_operands; k++) {
        const spv_parsed_operand_t *o = &in->operands[k];
        if (o->offset + o->num_words > in->num_words)
            return SPV_ERROR_INVALID_BINARY;
        if (is_id_operand(o->type) && o->num_words == 1) {
            uint32_t id = w[o->offset];
            uint32_t v[2] = { 0, 0 };
            if (id < s->bound && s->fconst[id])
                v[0] = 0xffffffffu, v[1] = s->fconst[id];
            else
                v[0] = shape_canon(s, id);
            XXH3_128bits_update(s->h, v, sizeof v);
        } else {
            uint32_t t = (uint32_t)o->type;
            XXH3_128bits_update(s->h, &t, sizeof t);
            XXH3_128bits_update(s->h, &w[o->offset], 4 * (size_t)o->num_words);
        }
    }
    return SPV_SUCCESS;
}

bool spv_shape(const uint32_t *words, size_t nwords, uint64_t hash[2])
{
    spv_context ctx = spvContextCreate(SPV_ENV_VULKAN_1_2);
    shape_st s = {0};
    s.h = XXH3_createState();
    if (!ctx || !s.h) {
        if (ctx)
            spvContextDestroy(ctx);
        XXH3_freeState(s.h);
        return false;
    }
    XXH3_128bits_reset(s.h);
    spv_diagnostic diag = NULL;
    spv_result_t r = spvBinaryParse(ctx, &s, words, nwords, shape_header, shape_inst, &diag);
    spvDiagnosticDestroy(diag);
    XXH128_hash_t h = XXH3_128bits_digest(s.h);
    hash[0] = h.high64;
    hash[1] = h.low64;
    XXH3_freeState(s.h);
    free(s.canon);
    free(s.fconst);
    free(s.ftype);
    spvContextDestroy(ctx);
    return r == SPV_SUCCESS && s.bound;
}

bool spv_write_file(const char *path, const uint32_t *words, size_t nwords)
{
    return splat_write_atomic(path, words, nwords * sizeof *words);
}
