/* lsp.c — `splatc lsp [-I DIR]...`: the server's loop, its lifecycle, the
 * open documents and the dispatch of messages to the handlers (lsp.h).
 *
 * The loop reads one message, handles it, and when no further input is
 * waiting analyses the documents that changed (so a burst of keystrokes is
 * analysed once) and publishes their diagnostics.  A request on a changed
 * document analyses it first.  A change to any document marks every open
 * document changed: they may import it.
 *
 * Lifecycle (LSP 3.17 "Server lifecycle"): before `initialize`, requests
 * are answered ServerNotInitialized and notifications dropped; after
 * `shutdown`, requests are InvalidRequest; `exit` ends the process with 0
 * after a shutdown, else 1; the end of input without `exit` ends it with 1
 * (0 after a shutdown).  Nothing the client sends stops the loop otherwise:
 * bad framing and bad JSON are answered with an error whose id is null. */
#include "cli.h"
#include "lsp.h"
#include "util.h"

#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* ---- documents ------------------------------------------------------------ */

static lsp_doc *doc_by_uri(lsp_server *s, const char *uri)
{
    char *path = lsp_uri_path(uri);
    char *canon = lsp_canonical(path);
    lsp_doc *d = lsp_doc_by_path(s, canon);
    free(canon);
    free(path);
    return d;
}

static void all_dirty(lsp_server *s)
{
    for (int i = 0; i < s->ndocs; i++)
        s->docs[i].dirty = true;
}

static void doc_free(lsp_doc *d)
{
    free(d->uri);
    free(d->path);
    free(d->text);
    sg_free(d->prog);
}

static void set_text(lsp_doc *d, const char *text, size_t len)
{
    free(d->text);
    d->text = xmalloc(len + 1);
    memcpy(d->text, text, len);
    d->text[len] = 0;
    d->len = len;
}

/* The analysis of doc, brought up to date. */
static void fresh(lsp_server *s, lsp_doc *d)
{
    if (d->dirty || !d->prog) {
        d->dirty = false;
        lsp_analyse(s, d);
    }
}

/* ---- messages ------------------------------------------------------------- */

static void respond(lsp_server *s, json_t *id, json_t *result)
{
    lsp_send(s, json_pack("{s:s, s:O, s:o}", "jsonrpc", "2.0", "id", id ? id : json_null(),
                          "result", result ? result : json_null()));
}

static void respond_error(lsp_server *s, json_t *id, int code, const char *why)
{
    lsp_send(s, json_pack("{s:s, s:O, s:{s:i, s:s}}", "jsonrpc", "2.0", "id",
                          id ? id : json_null(), "error", "code", code, "message", why));
}

/* A handler's failure: an error code and why. */
typedef struct failure { int code; char why[160]; } failure;

static json_t *fail(failure *f, int code, const char *why)
{
    f->code = code;
    snprintf(f->why, sizeof f->why, "%s", why);
    return NULL;
}

/* params.textDocument.uri's open document, and params.position's byte
 * offset in it; NULL (not an error) if the document is not open. */
static lsp_doc *doc_at(lsp_server *s, json_t *params, size_t *at, failure *f)
{
    const char *uri = NULL;
    json_int_t line = -1, character = -1;
    if (json_unpack(params, "{s:{s:s}, s:{s:I, s:I}}", "textDocument", "uri", &uri,
                    "position", "line", &line, "character", &character) ||
        line < 0 || character < 0 || line > INT32_MAX || character > INT32_MAX) {
        fail(f, LSP_INVALID_PARAMS, "expected textDocument.uri and position {line, character}");
        return NULL;
    }
    lsp_doc *d = doc_by_uri(s, uri);
    if (d) {
        fresh(s, d);
        *at = lsp_offset(s, d->text, d->len, (int)line, (int)character);
    }
    return d;
}

/* ---- lifecycle -------------------------------------------------------------- */

static json_t *on_initialize(lsp_server *s, json_t *params, failure *f)
{
    if (s->initialized)
        return fail(f, LSP_INVALID_REQUEST, "initialize was already sent");
    /* bytes as columns if the client can (LSP 3.17 positionEncodings) */
    json_t *enc = json_object_get(json_object_get(json_object_get(params, "capabilities"),
                                                  "general"), "positionEncodings");
    size_t i;
    json_t *e;
    json_array_foreach(enc, i, e)
        if (json_is_string(e) && !strcmp(json_string_value(e), "utf-8"))
            s->utf8 = true;
    s->initialized = true;
    return json_pack("{s:{s:s, s:{s:b, s:i}, s:{s:[s, s, s, s], s:b}, s:b, s:b, s:b},"
                     " s:{s:s, s:s}}",
                     "capabilities",
                     "positionEncoding", s->utf8 ? "utf-8" : "utf-16",
                     "textDocumentSync", "openClose", 1, "change", 1 /* full */,
                     "completionProvider", "triggerCharacters", ".", ":", "{", "[",
                     "resolveProvider", 0,
                     "hoverProvider", 1,
                     "definitionProvider", 1,
                     "codeActionProvider", 1,
                     "serverInfo", "name", "splatc", "version", SPLATC_VERSION);
}

static json_t *on_shutdown(lsp_server *s, json_t *params, failure *f)
{
    (void)params;
    (void)f;
    s->shutdown = true;
    return json_null();
}

/* ---- text synchronisation ------------------------------------------------------ */

static void on_did_open(lsp_server *s, json_t *params)
{
    const char *uri = NULL, *text = NULL;
    size_t len = 0;
    if (json_unpack(params, "{s:{s:s, s:s%}}", "textDocument", "uri", &uri, "text", &text, &len))
        return;
    lsp_doc *d = doc_by_uri(s, uri);
    if (!d) {
        if (s->ndocs == s->capdocs) {
            s->capdocs = s->capdocs ? 2 * s->capdocs : 8;
            s->docs = xrealloc(s->docs, (size_t)s->capdocs * sizeof *s->docs);
        }
        d = &s->docs[s->ndocs++];
        memset(d, 0, sizeof *d);
        char *path = lsp_uri_path(uri);
        d->path = lsp_canonical(path);
        free(path);
    }
    free(d->uri);
    d->uri = xstrdup(uri);
    set_text(d, text, len);
    all_dirty(s);
}

/* Replace [range.start, range.end) of d's text by `text`. */
static void apply_edit(lsp_server *s, lsp_doc *d, json_t *range, const char *text, size_t n)
{
    json_int_t l0, c0, l1, c1;
    if (json_unpack(range, "{s:{s:I, s:I}, s:{s:I, s:I}}", "start", "line", &l0, "character",
                    &c0, "end", "line", &l1, "character", &c1) ||
        l0 < 0 || c0 < 0 || l1 < 0 || c1 < 0 || l0 > INT32_MAX || c0 > INT32_MAX ||
        l1 > INT32_MAX || c1 > INT32_MAX)
        return;
    size_t a = lsp_offset(s, d->text, d->len, (int)l0, (int)c0);
    size_t b = lsp_offset(s, d->text, d->len, (int)l1, (int)c1);
    if (b < a)
        b = a;
    size_t len = d->len - (b - a) + n;
    char *t = xmalloc(len + 1);
    memcpy(t, d->text, a);
    memcpy(t + a, text, n);
    memcpy(t + a + n, d->text + b, d->len - b);
    t[len] = 0;
    free(d->text);
    d->text = t;
    d->len = len;
}

static void on_did_change(lsp_server *s, json_t *params)
{
    const char *uri = NULL;
    json_t *changes = NULL;
    if (json_unpack(params, "{s:{s:s}, s:o}", "textDocument", "uri", &uri, "contentChanges",
                    &changes) || !json_is_array(changes))
        return;
    lsp_doc *d = doc_by_uri(s, uri);
    if (!d)
        return;
    size_t i;
    json_t *c;
    json_array_foreach(changes, i, c) {
        json_t *text = json_object_get(c, "text");
        if (!json_is_string(text))
            continue;
        json_t *range = json_object_get(c, "range");
        if (range)
            apply_edit(s, d, range, json_string_value(text), json_string_length(text));
        else
            set_text(d, json_string_value(text), json_string_length(text));
    }
    all_dirty(s);
}

static void on_did_close(lsp_server *s, json_t *params)
{
    const char *uri = NULL;
    if (json_unpack(params, "{s:{s:s}}", "textDocument", "uri", &uri))
        return;
    lsp_doc *d = doc_by_uri(s, uri);
    if (!d)
        return;
    lsp_clear_diagnostics(s, d->uri);
    doc_free(d);
    *d = s->docs[--s->ndocs];
    all_dirty(s);          /* their imports of it now read the disk */
}

/* ---- language features ------------------------------------------------------------ */

static json_t *on_completion(lsp_server *s, json_t *params, failure *f)
{
    size_t at = 0;
    lsp_doc *d = doc_at(s, params, &at, f);
    return d ? lsp_completion(s, d, at) : f->code ? NULL : json_null();
}

static json_t *on_hover(lsp_server *s, json_t *params, failure *f)
{
    size_t at = 0;
    lsp_doc *d = doc_at(s, params, &at, f);
    return d ? lsp_hover(s, d, at) : f->code ? NULL : json_null();
}

static json_t *on_definition(lsp_server *s, json_t *params, failure *f)
{
    size_t at = 0;
    lsp_doc *d = doc_at(s, params, &at, f);
    return d ? lsp_definition(s, d, at) : f->code ? NULL : json_null();
}

static json_t *on_code_action(lsp_server *s, json_t *params, failure *f)
{
    const char *uri = NULL;
    json_t *diags = NULL;
    if (json_unpack(params, "{s:{s:s}, s:{s:o}}", "textDocument", "uri", &uri, "context",
                    "diagnostics", &diags) || !json_is_array(diags))
        return fail(f, LSP_INVALID_PARAMS, "expected textDocument.uri and context.diagnostics");
    lsp_doc *d = doc_by_uri(s, uri);
    if (!d)
        return json_array();
    fresh(s, d);
    return lsp_code_actions(s, d, diags);
}

/* ---- dispatch ----------------------------------------------------------------------- */

typedef json_t *(*request_fn)(lsp_server *s, json_t *params, failure *f);
typedef void (*notification_fn)(lsp_server *s, json_t *params);

static const struct { const char *method; request_fn run; } requests[] = {
    { "initialize",              on_initialize },
    { "shutdown",                on_shutdown },
    { "textDocument/completion", on_completion },
    { "textDocument/hover",      on_hover },
    { "textDocument/definition", on_definition },
    { "textDocument/codeAction", on_code_action },
};

static const struct { const char *method; notification_fn run; } notifications[] = {
    { "textDocument/didOpen",   on_did_open },
    { "textDocument/didChange", on_did_change },
    { "textDocument/didClose",  on_did_close },
};

/* Handle one message; the exit status if it was `exit`, else -1. */
static int handle(lsp_server *s, json_t *msg)
{
    if (!json_is_object(msg)) {
        respond_error(s, NULL, LSP_INVALID_REQUEST, "a message must be a JSON object");
        return -1;
    }
    json_t *id = json_object_get(msg, "id");
    json_t *method = json_object_get(msg, "method");
    json_t *params = json_object_get(msg, "params");
    if (json_is_null(params))
        params = NULL;                      /* some clients send null for none */
    if (id && !json_is_integer(id) && !json_is_string(id)) {
        respond_error(s, NULL, LSP_INVALID_REQUEST, "an id must be a number or a string");
        return -1;
    }
    if (!method) {
        if (!id || (!json_object_get(msg, "result") && !json_object_get(msg, "error")))
            respond_error(s, id, LSP_INVALID_REQUEST, "a message needs a method");
        return -1;                          /* else a response: none is awaited */
    }
    if (!json_is_string(method) || (params && !json_is_object(params) && !json_is_array(params))) {
        if (id)
            respond_error(s, id, LSP_INVALID_REQUEST, "method must be a string and params "
                          "an object or an array");
        return -1;
    }
    const char *m = json_string_value(method);
    json_t *empty = NULL;
    if (!json_is_object(params))
        params = empty = json_object();     /* every handler takes an object */
    if (!id) {
        if (!strcmp(m, "exit")) {
            json_decref(empty);
            return s->shutdown ? 0 : 1;
        }
        for (size_t i = 0; s->initialized && !s->shutdown &&
                           i < sizeof notifications / sizeof *notifications; i++)
            if (!strcmp(m, notifications[i].method))
                notifications[i].run(s, params);
        json_decref(empty);                 /* others ($/cancelRequest, …) are dropped */
        return -1;
    }
    size_t i = 0, n = sizeof requests / sizeof *requests;
    while (i < n && strcmp(m, requests[i].method))
        i++;
    if (!s->initialized && strcmp(m, "initialize"))
        respond_error(s, id, LSP_NOT_INITIALIZED, "the server is not initialized");
    else if (s->shutdown)
        respond_error(s, id, LSP_INVALID_REQUEST, "the server is shut down");
    else if (i == n)
        respond_error(s, id, LSP_METHOD_NOT_FOUND, "method not found");
    else {
        failure f = { 0, "" };
        json_t *result = requests[i].run(s, params, &f);
        if (f.code)
            respond_error(s, id, f.code, f.why);
        else
            respond(s, id, result);
    }
    json_decref(empty);
    return -1;
}

static const char help[] =
    "usage: splatc lsp [-I DIR]...\n"
    "  a Language Server Protocol server on standard input and output, for editors\n"
    "  (docs/editors.md): diagnostics as `splatc check` gives them, completion,\n"
    "  hover and go-to-definition.  Imports are searched as the compiler searches\n"
    "  them: next to the file, then -I folders, SPLATC_PATH, the current folder,\n"
    "  the project root and the node library.  --stdio is accepted and ignored.\n";

int splat_cli_lsp(int argc, char **argv)
{
    lsp_server s = { 0 };
    s.include = xcalloc((size_t)argc + 1, sizeof *s.include);
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "-I") && i + 1 < argc) {
            s.include[s.ninclude++] = argv[++i];
        } else if (!strcmp(argv[i], "--help") || !strcmp(argv[i], "-h")) {
            fputs(help, stdout);
            free(s.include);
            return 0;
        } else if (!strcmp(argv[i], "--stdio") || !strncmp(argv[i], "--clientProcessId", 17)) {
            continue;                       /* what editors' launchers add */
        } else {
            fprintf(stderr, "splatc lsp: unknown argument '%s' (splatc lsp --help)\n", argv[i]);
            free(s.include);
            return 2;
        }
    }
    s.out = stdout;
    s.in = lsp_reader_new(STDIN_FILENO);
    signal(SIGPIPE, SIG_IGN);   /* a client gone: a failed write, then the end of input */
    int status = -1;
    while (status < 0) {
        char *body = NULL, err[160];
        size_t len = 0;
        int r = lsp_read(s.in, &body, &len, err, sizeof err);
        if (r == 0) {
            status = s.shutdown ? 0 : 1;    /* the client went away */
            break;
        }
        if (r < 0) {
            respond_error(&s, NULL, LSP_PARSE_ERROR, err);
            continue;
        }
        json_error_t je;
        json_t *msg = json_loadb(body, len, JSON_ALLOW_NUL | JSON_DECODE_ANY, &je);
        free(body);
        if (!msg) {
            char why[256];
            snprintf(why, sizeof why, "not JSON (line %d, column %d: %s)", je.line, je.column,
                     je.text);
            respond_error(&s, NULL, LSP_PARSE_ERROR, why);
            continue;
        }
        status = handle(&s, msg);
        json_decref(msg);
        for (int i = 0; status < 0 && !lsp_pending(s.in) && i < s.ndocs; i++)
            fresh(&s, &s.docs[i]);
    }
    for (int i = 0; i < s.ndocs; i++)
        doc_free(&s.docs[i]);
    free(s.docs);
    free(s.include);
    lsp_reader_free(s.in);
    return status;
}
