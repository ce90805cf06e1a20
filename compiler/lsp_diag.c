/* lsp_diag.c — analysis of a document and its diagnostics.
 *
 * A document is loaded as `splatc check FILE` loads a file (the same
 * search path, sg_load then sg_check), except that every file the loader
 * reads is first looked up among the open documents (sg_overlay): an
 * unsaved edit to an imported file counts.
 *
 * Each diagnostic becomes an LSP Diagnostic over the word at its
 * file:line:col (severity error 1, warning 2, note 3; code: the SG_ERRORS
 * id; data.suggestion: a "did you mean" name).  One in an imported file is
 * shown on this document's `import` line that leads to it, with the
 * original place as related information:
 *
 *     import "lib.sg"     <- in lib.sg:4:17: unknown node type 'rampp'
 */
#include "lsp.h"
#include "scene_load.h"
#include "util.h"

#include <stdlib.h>
#include <string.h>

/* sg_overlay: an open document's text for a path the loader would read. */
static const char *overlay_text(void *user, const char *path, size_t *len)
{
    lsp_server *s = user;
    char *canon = lsp_canonical(path);
    lsp_doc *d = lsp_doc_by_path(s, canon);
    free(canon);
    if (!d)
        return NULL;
    *len = d->len;
    return d->text;
}

/* The index of the program's file at `path`, or -1. */
static int file_index(const sg_program *p, const char *path)
{
    for (int i = 0; path && i < p->nfiles; i++)
        if (!strcmp(p->files[i]->path, path))
            return i;
    return -1;
}

static json_t *zero_range(void)
{
    return json_pack("{s:{s:i, s:i}, s:{s:i, s:i}}", "start", "line", 0, "character", 0,
                     "end", "line", 0, "character", 0);
}

/* One diagnostic of doc's analysis as an LSP Diagnostic. */
static json_t *diagnostic(lsp_server *s, lsp_doc *doc, const sg_diag *g)
{
    const sg_program *p = doc->prog;
    json_t *range = NULL, *related = NULL;
    char *msg = NULL;
    int k = p ? file_index(p, g->loc.file) : -1;
    if (k == 0 && g->loc.line > 0) {
        range = lsp_range_at(s, doc->text, doc->len, g->loc.line, g->loc.col);
    } else if (k > 0) {
        /* up the chain of imports to the root file's import line */
        sg_loc at = g->loc;
        for (int guard = 0; k > 0 && guard <= SG_MAX_DEPTH; guard++) {
            at = p->files[k]->from;
            k = file_index(p, at.file);
        }
        char *abs = splat_path_absolute(g->loc.file);
        char *dir = splat_path_dir(doc->path);
        char *rel = splat_path_relative(dir, abs);
        if (g->loc.line > 0)
            msg = xasprintf("in %s:%d:%d: %s", rel, g->loc.line, g->loc.col, g->msg);
        else
            msg = xasprintf("in %s: %s", rel, g->msg);
        free(rel);
        free(dir);
        free(abs);
        if (k == 0 && at.line > 0)
            range = lsp_range_at(s, doc->text, doc->len, at.line, at.col);
        const sg_file *f = p->files[file_index(p, g->loc.file)];
        related = json_pack("[{s:o, s:s}]", "location",
                            lsp_location(s, f, g->loc.line > 0 ? g->loc.line : 1,
                                         g->loc.line > 0 ? g->loc.col : 1),
                            "message", g->msg);
    }
    if (!range)
        range = zero_range();
    json_t *out = json_pack("{s:o, s:i, s:s, s:s}", "range", range, "severity",
                            g->severity == SG_ERROR ? 1 : g->severity == SG_WARNING ? 2 : 3,
                            "source", "splatc", "message", msg ? msg : g->msg);
    if (g->severity != SG_NOTE)
        json_object_set_new(out, "code", json_string(sg_error_name(g->id)));
    if (g->suggestion)
        json_object_set_new(out, "data", json_pack("{s:s}", "suggestion", g->suggestion));
    if (related)
        json_object_set_new(out, "relatedInformation", related);
    free(msg);
    return out;
}

static void publish(lsp_server *s, const char *uri, json_t *diagnostics)
{
    lsp_send(s, json_pack("{s:s, s:s, s:{s:s, s:o}}", "jsonrpc", "2.0", "method",
                          "textDocument/publishDiagnostics", "params", "uri", uri,
                          "diagnostics", diagnostics));
}

void lsp_clear_diagnostics(lsp_server *s, const char *uri)
{
    publish(s, uri, json_array());
}

void lsp_analyse(lsp_server *s, lsp_doc *doc)
{
    sg_free(doc->prog);
    sg_diags d;
    sg_diags_init(&d);
    char **paths = splat_search_path(s->include, s->ninclude, doc->path);
    sg_overlay ov = { overlay_text, s };
    doc->prog = sg_load_overlay(doc->path, (const char *const *)paths, &ov, &d);
    splat_search_path_free(paths);
    sg_check(doc->prog, &d);

    json_t *list = json_array();
    for (int i = 0; i < d.n; i++)
        json_array_append_new(list, diagnostic(s, doc, &d.items[i]));
    if (d.ndropped) {
        char msg[96];
        snprintf(msg, sizeof msg, "%d more diagnostic%s not shown", d.ndropped,
                 d.ndropped == 1 ? "" : "s");
        json_array_append_new(list, json_pack("{s:o, s:i, s:s, s:s}", "range", zero_range(),
                                              "severity", 3, "source", "splatc",
                                              "message", msg));
    }
    publish(s, doc->uri, list);
    sg_diags_free(&d);
}
