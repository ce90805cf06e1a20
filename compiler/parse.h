/* parse.h — the .sg parser's internals, shared by its files (sg_parse,
 * the entry point, is in sg_internal.h):
 *
 *   parse_base.c         the token cursor, errors and recovery, values,
 *                        binding lists, statement blocks
 *   parse.c              a file's top level: imports, textures, shaders,
 *                        materials
 *   parse_undergrowth.c  a material's undergrowth blocks
 *   parse_scene.c        the scene block
 */
#ifndef SPLAT_PARSE_H
#define SPLAT_PARSE_H

#include "sg_internal.h"

typedef struct parser {
    sg_program *p;
    sg_arena   *a;
    sg_file    *f;
    int         fi;
    sg_diags   *d;
    int         pos;          /* current token                          */
    sg_import **imports;
    int        *nimports;
    int         capimports;
} parser;

/* ---- tokens and errors (parse_base.c) ------------------------------------ */

sg_token *ps_cur(parser *ps);
sg_token *ps_peek_at(parser *ps, int k);
sg_token *ps_next(parser *ps);
sg_loc ps_loc_of(parser *ps, const sg_token *t);
bool ps_is_kw(const sg_token *t, const char *kw);
bool ps_line_start(parser *ps, const sg_token *t);
bool ps_top_keyword(const sg_token *t);
char *ps_tok_text(parser *ps, const sg_token *t);
/* "expected WHAT" at the current token (what was found, where) */
void ps_expected(parser *ps, const char *what);
/* "did you mean" for an unknown key among `keys` (NULL-ended) */
void ps_hint_key(parser *ps, const sg_token *key, const char *const *keys);
bool ps_accept(parser *ps, sg_tok_kind k);
bool ps_expect(parser *ps, sg_tok_kind k, const char *what);
ir_type ps_type_name(const sg_token *t);

/* ---- values, bindings, blocks (parse_base.c) ----------------------------- */

bool ps_path(parser *ps, sg_value *v);
bool ps_value(parser *ps, sg_value *v);
bool ps_number(parser *ps, double *x);
/* bindings = "{" { IDENT "=" value [","] } "}": each through `add`; false
 * if the list had errors */
typedef void (*binding_fn)(parser *ps, void *user, sg_token *key, sg_value *v);
bool ps_bindings(parser *ps, const char *what, binding_fn add, void *user);
/* A block `{ statement* }` whose statements `stmt` parses; returns when the
 * block is closed (or found unterminated).  in_material: a block inside a
 * material's, where a material statement starting a later line also means
 * it was not closed. */
typedef bool (*stmt_fn)(parser *ps, void *user);
void ps_block(parser *ps, const char *what, stmt_fn stmt, void *user);
void ps_block_in(parser *ps, const char *what, stmt_fn stmt, void *user, bool in_material);

/* ---- the rule files ------------------------------------------------------ */

bool ps_undergrowth(parser *ps, sg_shader *s);   /* parse_undergrowth.c */
bool ps_scene(parser *ps);                         /* parse_scene.c */

#endif
