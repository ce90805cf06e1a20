/* lsp.h — `splatc lsp`: a Language Server Protocol server on stdio for
 * .sg graph files, built on the front end (sg.h, sg_internal.h) and jansson.
 * Part of the splatc executable, not of libsplatc (compiler/CMakeLists.txt).
 *
 * What it answers (LSP 3.17): initialize / initialized / shutdown / exit;
 * textDocument/didOpen, didChange (full or ranged edits), didClose;
 * publishDiagnostics (the checks of `splatc check`, on the editor's
 * unsaved texts); completion; hover; definition; codeAction (the "did
 * you mean" of a diagnostic as a quick fix).
 *
 * Positions: the front end counts 1-based lines and 1-based byte columns;
 * LSP counts 0-based lines and, unless the client offers "utf-8" in
 * general.positionEncodings, UTF-16 code units.  lsp_text.c converts
 * exactly for well-formed UTF-8 (a 4-byte sequence is 2 units, the others
 * 1); a stray byte that is not UTF-8 counts as one unit.
 *
 * Sections: lsp.c (the loop, lifecycle, documents, dispatch), lsp_io.c
 * (Content-Length framing), lsp_text.c (URIs, paths, positions),
 * lsp_diag.c (analysis, diagnostics and their quick fixes),
 * lsp_complete.c (completion), lsp_nav.c (hover and definition).
 */
#ifndef SPLAT_LSP_H
#define SPLAT_LSP_H

#include <stdbool.h>
#include <stddef.h>
#include <stdio.h>

#include <jansson.h>

#include "sg_internal.h"

/* The largest message body read (a graph file may have 16 MiB, and JSON
 * escaping can make it longer); a larger Content-Length is skipped and
 * answered with an error. */
#define LSP_MAX_MESSAGE ((size_t)64 << 20)

/* JSON-RPC and LSP error codes. */
enum {
    LSP_PARSE_ERROR      = -32700,
    LSP_INVALID_REQUEST  = -32600,
    LSP_METHOD_NOT_FOUND = -32601,
    LSP_INVALID_PARAMS   = -32602,
    LSP_INTERNAL_ERROR   = -32603,
    LSP_NOT_INITIALIZED  = -32002,
};

/* One open document. */
typedef struct lsp_doc {
    char       *uri;        /* as the client spelt it (diagnostics go back to it) */
    char       *path;       /* lsp_canonical of the URI's path                */
    char       *text;       /* NUL-terminated                                 */
    size_t      len;
    bool        dirty;      /* changed since the last analysis                */
    sg_program *prog;       /* the last analysis (NULL before the first)      */
} lsp_doc;

typedef struct lsp_reader lsp_reader;

typedef struct lsp_server {
    lsp_doc     *docs;      int ndocs, capdocs;
    const char **include;   int ninclude;   /* -I folders                     */
    bool         initialized, shutdown;
    bool         utf8;      /* positions count bytes (negotiated), not UTF-16 */
    FILE        *out;
    lsp_reader  *in;
} lsp_server;

/* ---- lsp.c ------------------------------------------------------------- */

/* The command itself is splat_cli_lsp (cli.h). */
/* The open document of `path` (canonical), or NULL. */
lsp_doc *lsp_doc_by_path(lsp_server *s, const char *path);
/* Send a message (a response or a notification) and drop the reference. */
void lsp_send(lsp_server *s, json_t *msg);

/* ---- lsp_io.c: Content-Length framing ---------------------------------- */

/* Buffered reads from a file descriptor, so the server can ask whether
 * more is waiting (lsp_pending) before it analyses. */
lsp_reader *lsp_reader_new(int fd);
void        lsp_reader_free(lsp_reader *r);
/* The next message's body (malloc'd, NUL-terminated, *len bytes).
 * Returns 1 with a body, 0 at the end of input, -1 for a bad header
 * block or an over-long body (skipped; why in err): the caller answers
 * with an error and reads on.  Header lines may end in "\r\n" or "\n";
 * header names are case-insensitive; lines over 4 KiB are cut. */
int  lsp_read(lsp_reader *r, char **body, size_t *len, char *err, size_t n);
/* Input is waiting (buffered, or readable without blocking). */
bool lsp_pending(lsp_reader *r);
/* Write one message: "Content-Length: N\r\n\r\n" and the compact JSON. */
bool lsp_write(FILE *out, const json_t *msg);

/* ---- lsp_text.c: URIs, paths, positions -------------------------------- */

/* The path of a file:// URI (percent-decoded), malloc'd; other schemes
 * are returned whole (lsp_canonical then puts an untitled buffer in the
 * current folder, where its imports are looked for). */
char *lsp_uri_path(const char *uri);
/* file:// URI of a path (made absolute, percent-encoded), malloc'd. */
char *lsp_path_uri(const char *path);
/* realpath if the file exists, else the absolute path with `.`, `..` and
 * repeated slashes folded; malloc'd.  Documents and the loader's paths are
 * compared in this form. */
char *lsp_canonical(const char *path);
/* Byte offset in text of LSP position (line, character); clamped to the
 * line's end and the text's end. */
size_t lsp_offset(const lsp_server *s, const char *text, size_t len, int line, int character);
/* The LSP position {line, character} of byte `offset`. */
json_t *lsp_position_at(const lsp_server *s, const char *text, size_t len, size_t offset);
/* Byte offset of the front end's (line, col), clamped to the line. */
size_t lsp_loc_offset(const char *text, size_t len, int line, int col);
/* {start, end} over the word (name, number or string) at the front end's
 * (line, col): the span a diagnostic or a definition points at. */
json_t *lsp_range_at(const lsp_server *s, const char *text, size_t len, int line, int col);
/* {uri, range} of a front-end location in file f of a program. */
json_t *lsp_location(lsp_server *s, const sg_file *f, int line, int col);

/* ---- lsp_diag.c: analysis, diagnostics, quick fixes --------------------- */

/* Load doc (imports through the compiler's search path, open documents
 * over the files on disk), run `splatc check`'s checks, keep the program
 * in doc->prog and publish the diagnostics. */
void lsp_analyse(lsp_server *s, lsp_doc *doc);
/* An empty diagnostics list for doc (on close). */
void lsp_clear_diagnostics(lsp_server *s, const char *uri);
/* CodeAction[] for the client's `diagnostics` of doc: a quick fix for each
 * one with a "did you mean" (data.suggestion) that puts the name in. */
json_t *lsp_code_actions(lsp_server *s, lsp_doc *doc, json_t *diagnostics);

/* ---- lsp_complete.c ---------------------------------------------------- */

/* CompletionItem[] for byte offset `at` of doc (analysed). */
json_t *lsp_completion(lsp_server *s, lsp_doc *doc, size_t at);

/* ---- lsp_nav.c --------------------------------------------------------- */

/* Hover ({contents, range}) and definition (Location) at byte `at`;
 * json_null() when there is nothing there. */
json_t *lsp_hover(lsp_server *s, lsp_doc *doc, size_t at);
json_t *lsp_definition(lsp_server *s, lsp_doc *doc, size_t at);

/* Shared with completion: a port as declared ("in float lo = 0.3",
 * "param float line = 2400 range 0 4000"; role "in", "out" or "param"),
 * the types port k of built-in op `op` takes ("float | vec2 | vec3 |
 * vec4"), and a shader's or material's interface, one port a line. */
void lsp_port_text(const sg_port *port, const char *role, char *buf, size_t n);
void lsp_op_port_types(int op, int k, char *buf, size_t n);
void lsp_shader_text(const sg_program *p, int shader, char *buf, size_t n);

#endif
