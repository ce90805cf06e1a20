/* sg_internal.h — the graph language front end's internals: arena and
 * name maps, tokens, the AST, the loaded program, and the phases
 * (lex -> parse -> resolve -> lower).  Public API: sg.h.
 *
 * Sections: sg_util.c (arena, string map, paths), diag.c (diagnostics),
 * lex.c, parse.c (and loading with imports), resolve.c (names, types,
 * cycles), lower.c (AST -> IR), dot.c (Graphviz), sg_query.c (doc comments).
 */
#ifndef SPLAT_SG_INTERNAL_H
#define SPLAT_SG_INTERNAL_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "ir.h"
#include "sg.h"
#include "util.h"    /* paths: splat_path_join, splat_path_dir */

/* Deepest nesting of instance shaders (and of imports).  Deeper graphs are
 * TOO_DEEP errors, never a stack overflow. */
#define SG_MAX_DEPTH 256
/* Diagnostics kept per sg_diags; later ones are counted, not stored. */
#define SG_MAX_STORED_DIAGS 100

/* ---- sg_util.c: arena, string map, paths ------------------------------ */

/* Bump allocator for everything with the program's lifetime. */
typedef struct sg_arena_block sg_arena_block;
typedef struct sg_arena { sg_arena_block *head; } sg_arena;

void *sg_alloc(sg_arena *a, size_t n);               /* zeroed           */
char *sg_strndup(sg_arena *a, const char *s, size_t n);
char *sg_strdup(sg_arena *a, const char *s);
void  sg_arena_free(sg_arena *a);
/* Append one zeroed element to an arena-backed growable array; returns it. */
void *sg_push(sg_arena *a, void *items_ptr, int *n, int *cap, size_t elem);
#define SG_PUSH(a, arr, n, cap) \
    ((__typeof__(arr))sg_push((a), &(arr), &(n), &(cap), sizeof *(arr)))

/* String -> int map (open addressing, malloc'd; keys are not copied). */
typedef struct sg_map {
    const char **keys;
    int         *vals;
    uint32_t     cap, n;
} sg_map;

void sg_map_free(sg_map *m);
/* The value for `key`, or -1. */
int  sg_map_get(const sg_map *m, const char *key);
/* Insert if absent; returns the existing value, or -1 if inserted. */
int  sg_map_put(sg_map *m, const char *key, int val);

/* ---- lex.c ------------------------------------------------------------- */

typedef enum sg_tok_kind {
    SG_TK_EOF,
    SG_TK_IDENT,
    SG_TK_NUMBER,
    SG_TK_STRING,
    SG_TK_LBRACE, SG_TK_RBRACE,
    SG_TK_LPAREN, SG_TK_RPAREN,
    SG_TK_LBRACK, SG_TK_RBRACK,
    SG_TK_COMMA, SG_TK_COLON, SG_TK_EQ, SG_TK_DOT,
} sg_tok_kind;

typedef struct sg_token {
    sg_tok_kind kind;
    const char *start;   /* into the file's text                     */
    int         len;
    int         line, col;
    double      num;     /* SG_TK_NUMBER (0 for a bad literal)       */
    char       *str;     /* SG_TK_STRING: unescaped (arena)          */
} sg_token;

/* One source file: its text and tokens. */
typedef struct sg_file {
    char     *path;      /* as resolved (relative to the CWD, as given) */
    char     *dir;       /* splat_path_dir(path)                         */
    char     *key;       /* realpath for import dedup, else path         */
    sg_loc    from;      /* the `import` that first loaded it (line 0 for
                            the root file)                               */
    char     *text;      /* NUL-terminated copy                          */
    size_t    len;
    sg_token *toks;      /* ends with SG_TK_EOF                          */
    int       ntoks, captoks;
} sg_file;

/* Tokenise f->text into f->toks; errors (BAD_CHAR, BAD_LITERAL,
 * UNTERMINATED string) go to d and the bad token is skipped or kept as a
 * number 0, so parsing can go on.  Linear in the text length. */
void sg_lex(sg_arena *a, sg_file *f, sg_diags *d);
/* "'foo'", "number 1.5", "end of file" … for "found %s" messages. */
const char *sg_tok_describe(const sg_token *t, char *buf, size_t n);

/* ---- AST (parse.c) ------------------------------------------------------ */

typedef enum sg_value_kind {
    SG_V_NONE,
    SG_V_NUMBER,         /* 1.5                                         */
    SG_V_VEC,            /* vec3(1, 2, 3)                               */
    SG_V_STRING,         /* "textures/rock.png", "fields"               */
    SG_V_PATH,           /* name, node.port.swizzle, terrain.position.xz */
} sg_value_kind;

/* What a path names, after resolve. */
typedef enum sg_ref_kind {
    SG_REF_NONE,
    SG_REF_NODE,         /* output `index` of node `node` in this scope  */
    SG_REF_IN,           /* input `index` of the enclosing shader         */
    SG_REF_PARAM,        /* param `index` of the enclosing material       */
    SG_REF_TEXTURE,      /* top-level texture `index` (program.textures)  */
    SG_REF_INPUT,        /* terrain input `index` (ir_input)              */
    SG_REF_VECTOR,       /* vector.NAME (index 0: the mask) or
                            vector.NAME.across (index 1), NAME = parts[1] */
} sg_ref_kind;

typedef struct sg_value {
    sg_value_kind kind;
    sg_loc        loc;
    double        num[4];   /* NUMBER: num[0]; VEC: num[0..width-1]     */
    int           width;    /* NUMBER 1, VEC 2..4                       */
    char         *str;      /* STRING                                   */
    char        **parts;    /* PATH: the dotted names                   */
    int           nparts;
    /* resolved */
    sg_ref_kind   ref;
    int           node, index;
    char         *swizzle;  /* "xz" or NULL                              */
    ir_type       type;     /* after the swizzle; IR_T_ERROR if unknown  */
} sg_value;

/* `port = value` inside a node's braces. */
typedef struct sg_binding {
    char    *port;
    sg_loc   loc;
    sg_value val;
    int      slot;          /* resolved: op arg index or callee input     */
    ir_type  splat;         /* resolved: splat the value to this type, or
                               IR_T_ERROR for none                         */
} sg_binding;

typedef enum sg_node_kind {
    SG_NODE_UNRESOLVED,
    SG_NODE_OP,             /* a built-in op of the IR op table          */
    SG_NODE_INSTANCE,       /* an instance shader                          */
    SG_NODE_INPUT,          /* terrain.slope …                             */
    SG_NODE_PAINTED,        /* painted { mask = "fields" }                 */
} sg_node_kind;

/* An SG_NODE_INPUT's op for terrain.X.dx (axis 0) or .dy (1): the input
 * in the low byte, axis + 1 above it. */
#define SG_INPUT_DERIVATIVE(input, axis) ((input) | ((axis) + 1) << 8)
#define SG_INPUT_OF(op)                  ((op) & 0xff)
#define SG_INPUT_AXIS(op)                (((op) >> 8) - 1)   /* -1: the value */

typedef struct sg_node {
    char       *name;
    sg_loc      loc;
    char       *type;       /* "sub", "ramp", "terrain.slope"              */
    sg_loc      type_loc;
    sg_binding *args;
    int         nargs, capargs;
    bool        incomplete; /* its `{ … }` had syntax errors: do not
                               report the inputs they lost as missing   */
    /* resolved */
    sg_node_kind kind;
    int          op;        /* ir_op, or ir_input for SG_NODE_INPUT (its
                               derivative: SG_INPUT_DERIVATIVE)           */
    int          shader;    /* callee index (program.shaders)             */
    ir_type      out_type;  /* OP, INPUT, PAINTED: the one output          */
} sg_node;

/* `in`, `out` and `param` declarations. */
typedef struct sg_port {
    char    *name;
    sg_loc   loc;
    ir_type  type;          /* IR_T_ERROR if not written (material outs)  */
    bool     has_value;
    sg_value value;         /* default (in, param) or wire (out)          */
    bool     has_range;     /* param … range lo hi                        */
    double   lo, hi;
    int      output;        /* material outs: sg_output                   */
} sg_port;

/* A `shader` or a `material`. */
typedef struct sg_shader {
    char    *name;
    sg_loc   loc;
    bool     is_material;
    int      file;
    sg_port *ins;    int nins, capins;
    sg_port *outs;   int nouts, capouts;
    sg_port *params; int nparams, capparams;
    sg_node *nodes;  int nnodes, capnodes;
    sg_undergrowth *ug; int nug, capug;  /* materials: undergrowth blocks */
    /* resolved */
    int     *order;         /* node indices, dependencies first          */
    int      norder;
    int      depth;         /* instance nesting below this shader         */
    bool     ok;            /* resolved without errors                    */
} sg_shader;

/* A top-level `texture`. */
typedef struct sg_texdecl {
    char      *name;
    sg_loc     loc;
    char      *file;        /* resolved relative to the declaring file    */
    sg_loc     file_loc;    /* the `file = "…"` string (else loc)          */
    ir_filter  filter, mip;
    ir_wrap    wrap;
    bool       srgb;
} sg_texdecl;

/* ---- the program -------------------------------------------------------- */

typedef enum sg_global_kind { SG_G_SHADER, SG_G_TEXTURE } sg_global_kind;

struct sg_program {
    sg_arena    arena;
    sg_file   **files;   int nfiles, capfiles;   /* [0] = the root file  */
    sg_shader **shaders; int nshaders, capshaders; /* and materials       */
    sg_texdecl **textures; int ntextures, captextures;
    int        *materials; int nmaterials, capmaterials; /* shader idx  */
    sg_map      globals; /* name -> (index << 1) | sg_global_kind       */
    sg_scene   *scene;   /* the root file's scene, or NULL              */
    char      **search;  int nsearch;
    int         load_errors; /* errors while loading and checking       */
    int         nug_materials; /* materials with undergrowth blocks     */
    int         failed_imports; /* imports not found: resolve leaves out the
                                   unknown names that follow from them   */
};

/* ---- parse.c ------------------------------------------------------------ */

/* Parse one lexed file, appending its declarations to the program;
 * import paths are appended to `imports` (with their locations). */
typedef struct sg_import { char *path; sg_loc loc; } sg_import;
void sg_parse(sg_program *p, int file, sg_import **imports, int *nimports,
              sg_diags *d);

/* The keys of each settings block, NULL-ended, as the parser accepts them
 * (its "did you mean" lists; an editor's completion, lsp_complete.c). */
extern const char *const sg_scene_keys[];       /* scene NAME { … }           */
extern const char *const sg_texture_keys[];     /* texture NAME { … }         */
extern const char *const sg_painted_keys[];     /* painted NAME = "f" { … }   */
extern const char *const sg_camera_keys[];      /* camera NAME { … }          */
extern const char *const sg_destruction_keys[]; /* destruction { … }          */
extern const char *const sg_ug_keys[];          /* undergrowth MESH { … }     */

/* Inline texture declaration for a string literal on a texture port. */
void sg_texdecl_defaults(sg_texdecl *t);

/* ---- resolve.c ---------------------------------------------------------- */

/* Names, ports, types, cycles and nesting depth of the whole program. */
void sg_resolve(sg_program *p, sg_diags *d);
/* The shader (not material) called `name`, or -1. */
int  sg_shader_find(const sg_program *p, const char *name);
/* Type of node output `index` of node n in shader s (IR_T_ERROR if bad). */
ir_type sg_node_output_type(const sg_program *p, const sg_shader *s,
                            const sg_node *n, int index);

/* ---- sg_query.c: what tools ask of a loaded program ----------------------- */

/* The comment documenting the declaration on line `line` of f: with
 * `trailing`, the `#` comment after the line's last token if there is one;
 * else the run of `#` lines right above the line (indented or not), joined
 * by spaces, each without its '#' and the blanks around.  Written to buf
 * (NUL-terminated, cut at n); returns its length, 0 if none. */
size_t sg_doc_comment(const sg_file *f, int line, bool trailing, char *buf, size_t n);
/* A value as written: 0.5, vec3(1, 0, 0), "rock.png", terrain.slope. */
void sg_value_text(const sg_value *v, char *buf, size_t n);

#endif
