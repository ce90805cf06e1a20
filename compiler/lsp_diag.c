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

/* ---- quick fixes ------------------------------------------------------------ */

static bool name_char(char c)
{
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
}

/* The replacement of "did you mean" `word` for the name at byte a: the
 * first parts of the dotted name there if word has as many dots
 * (terrain.positon -> terrain.position), else the one part nearest to it
 * (n.outt -> n.out).  False if there is no name at a. */
static bool fix_span(const lsp_doc *doc, size_t a, const char *word, size_t *from, size_t *to)
{
    size_t starts[8], ends[8];
    int n = 0;
    size_t p = a;
    while (n < 8 && p < doc->len && name_char(doc->text[p])) {
        starts[n] = p;
        while (p < doc->len && name_char(doc->text[p]))
            p++;
        ends[n++] = p;
        if (p + 1 < doc->len && doc->text[p] == '.' && name_char(doc->text[p + 1]))
            p++;
        else
            break;
    }
    if (!n)
        return false;
    int dots = 0;
    for (const char *c = word; *c; c++)
        dots += *c == '.';
    if (dots > 0) {
        if (dots >= n)
            return false;
        *from = starts[0];
        *to = ends[dots];
        return true;
    }
    int best = 0, best_d = 1 << 30;
    for (int i = 0; i < n; i++) {
        char part[128];
        snprintf(part, sizeof part, "%.*s", (int)(ends[i] - starts[i]), doc->text + starts[i]);
        int d = sg_edit_distance(part, word);
        if (d < best_d)
            best_d = d, best = i;
    }
    *from = starts[best];
    *to = ends[best];
    return true;
}

json_t *lsp_code_actions(lsp_server *s, lsp_doc *doc, json_t *diagnostics)
{
    json_t *out = json_array();
    size_t i;
    json_t *d;
    json_array_foreach(diagnostics, i, d) {
        const char *word = json_string_value(json_object_get(json_object_get(d, "data"),
                                                             "suggestion"));
        json_int_t line, ch;
        if (!word || json_unpack(d, "{s:{s:{s:I, s:I}}}", "range", "start", "line", &line,
                                 "character", &ch) ||
            line < 0 || ch < 0 || line > INT32_MAX || ch > INT32_MAX)
            continue;
        size_t a = lsp_offset(s, doc->text, doc->len, (int)line, (int)ch), from, to;
        if (!fix_span(doc, a, word, &from, &to))
            continue;
        if (to - from == strlen(word) && !memcmp(doc->text + from, word, to - from))
            continue;                       /* already fixed */
        char title[160];
        snprintf(title, sizeof title, "Change to '%s'", word);
        json_t *edit = json_pack("{s:{s:o, s:o}, s:s}", "range", "start",
                                 lsp_position_at(s, doc->text, doc->len, from), "end",
                                 lsp_position_at(s, doc->text, doc->len, to), "newText", word);
        json_t *changes = json_object();
        json_object_set_new(changes, doc->uri, json_pack("[o]", edit));
        json_array_append_new(out, json_pack("{s:s, s:s, s:[O], s:b, s:{s:o}}", "title", title,
                                             "kind", "quickfix", "diagnostics", d,
                                             "isPreferred", 1, "edit", "changes", changes));
    }
    return out;
}
