/* client.h — a scripted Language Server Protocol client for `splatc lsp`,
 * shared by the LSP tests (lsp_session.c, lsp_garbage.c; tests/lsp/suite.cmake):
 * it starts the server on two pipes, sends requests and notifications,
 * reads the answers (keeping the published diagnostics per document) and
 * waits for the server's exit status.  CHECK counts a failure and goes on;
 * every wait for the server has a timeout. */
#ifndef SPLAT_TESTS_LSP_CLIENT_H
#define SPLAT_TESTS_LSP_CLIENT_H

#define _GNU_SOURCE   /* asprintf, strndup */

#include <jansson.h>

#include <errno.h>
#include <poll.h>
#include <signal.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#define TIMEOUT_MS 30000

static int failures;

#define CHECK(cond, ...)                                                    \
    do {                                                                    \
        if (!(cond)) {                                                      \
            failures++;                                                     \
            fprintf(stderr, "FAIL %s:%d: %s: ", __FILE__, __LINE__, #cond); \
            fprintf(stderr, __VA_ARGS__);                                   \
            fputc('\n', stderr);                                            \
        }                                                                   \
    } while (0)

/* ---- the server ------------------------------------------------------------ */

typedef struct server {
    pid_t   pid;
    int     to, from;       /* its stdin, its stdout */
    char    buf[1 << 16];
    size_t  pos, end;
    json_t *diags;          /* uri -> the latest publishDiagnostics list */
    int     next_id;
} server;

static inline void start(server *s, const char *splatc)
{
    int in[2], out[2];
    if (pipe(in) || pipe(out)) {
        perror("pipe");
        exit(2);
    }
    s->pid = fork();
    if (s->pid < 0) {
        perror("fork");
        exit(2);
    }
    if (s->pid == 0) {
        dup2(in[0], 0);
        dup2(out[1], 1);
        close(in[0]); close(in[1]); close(out[0]); close(out[1]);
        execl(splatc, splatc, "lsp", (char *)NULL);
        perror("exec");
        _exit(127);
    }
    close(in[0]);
    close(out[1]);
    s->to = in[1];
    s->from = out[0];
    s->pos = s->end = 0;
    s->diags = json_object();
    s->next_id = 1;
}

static inline void send_raw(server *s, const void *data, size_t n)
{
    const char *p = data;
    while (n) {
        ssize_t k = write(s->to, p, n);
        if (k < 0 && errno == EINTR)
            continue;
        if (k <= 0) {
            CHECK(false, "cannot write to the server: %s", strerror(errno));
            return;
        }
        p += k;
        n -= (size_t)k;
    }
}

static inline void send_body(server *s, const char *body, size_t n)
{
    char head[64];
    int k = snprintf(head, sizeof head, "Content-Length: %zu\r\n\r\n", n);
    send_raw(s, head, (size_t)k);
    send_raw(s, body, n);
}

static inline void send_json(server *s, json_t *msg)
{
    char *text = json_dumps(msg, JSON_COMPACT);
    send_body(s, text, strlen(text));
    free(text);
    json_decref(msg);
}

/* One byte from the server; -1 at its end or after the timeout. */
static inline int get_byte(server *s)
{
    if (s->pos == s->end) {
        struct pollfd p = { .fd = s->from, .events = POLLIN };
        if (poll(&p, 1, TIMEOUT_MS) <= 0)
            return -1;
        ssize_t n = read(s->from, s->buf, sizeof s->buf);
        if (n <= 0)
            return -1;
        s->pos = 0;
        s->end = (size_t)n;
    }
    return (unsigned char)s->buf[s->pos++];
}

/* The next message, or NULL (framing broken, end, timeout: a failure). */
static inline json_t *receive(server *s)
{
    char line[256];
    long length = -1;
    for (;;) {
        size_t n = 0;
        int c;
        while ((c = get_byte(s)) >= 0 && c != '\n')
            if (n < sizeof line - 1)
                line[n++] = (char)c;
        if (c < 0) {
            CHECK(false, "no message from the server (end of output or %d ms)", TIMEOUT_MS);
            return NULL;
        }
        if (n && line[n - 1] == '\r')
            n--;
        line[n] = 0;
        if (n == 0)
            break;
        if (!strncmp(line, "Content-Length: ", 16))
            length = strtol(line + 16, NULL, 10);
    }
    CHECK(length >= 0, "a message without Content-Length");
    if (length < 0)
        return NULL;
    char *body = malloc((size_t)length + 1);
    for (long i = 0; i < length; i++) {
        int c = get_byte(s);
        if (c < 0) {
            CHECK(false, "a message cut short");
            free(body);
            return NULL;
        }
        body[i] = (char)c;
    }
    json_error_t je;
    json_t *msg = json_loadb(body, (size_t)length, 0, &je);
    CHECK(msg, "the server sent bad JSON: %s", je.text);
    free(body);
    return msg;
}

/* Keep a notification (publishDiagnostics) aside. */
static inline void note(server *s, json_t *msg)
{
    const char *m = json_string_value(json_object_get(msg, "method"));
    if (m && !strcmp(m, "textDocument/publishDiagnostics")) {
        json_t *params = json_object_get(msg, "params");
        const char *uri = json_string_value(json_object_get(params, "uri"));
        if (uri)
            json_object_set(s->diags, uri, json_object_get(params, "diagnostics"));
    }
}

/* The response to request `id` (notifications before it are noted). */
static inline json_t *response(server *s, json_t *id)
{
    for (;;) {
        json_t *msg = receive(s);
        if (!msg)
            return NULL;
        if (json_object_get(msg, "method")) {
            note(s, msg);
            json_decref(msg);
            continue;
        }
        if (json_equal(json_object_get(msg, "id"), id))
            return msg;
        CHECK(false, "an answer to an id not asked (or asked before)");
        json_decref(msg);
    }
}

/* Send request `method` and return its whole response (decref it). */
static inline json_t *request(server *s, const char *method, json_t *params)
{
    int id = s->next_id++;
    send_json(s, json_pack("{s:s, s:i, s:s, s:o}", "jsonrpc", "2.0", "id", id, "method",
                           method, "params", params ? params : json_object()));
    json_t *jid = json_integer(id);
    json_t *r = response(s, jid);
    json_decref(jid);
    return r;
}

static inline void notify(server *s, const char *method, json_t *params)
{
    send_json(s, json_pack("{s:s, s:s, s:o}", "jsonrpc", "2.0", "method", method, "params",
                           params ? params : json_object()));
}

/* Send exit, close the pipe and return the server's exit status. */
static inline int finish(server *s, bool send_exit)
{
    if (send_exit)
        notify(s, "exit", NULL);
    close(s->to);
    int st = -1;
    for (int waited = 0; waited < TIMEOUT_MS; waited += 10) {
        pid_t r = waitpid(s->pid, &st, WNOHANG);
        if (r == s->pid)
            break;
        usleep(10000);
        if (waited + 10 >= TIMEOUT_MS) {
            kill(s->pid, SIGKILL);
            waitpid(s->pid, &st, 0);
            CHECK(false, "the server did not end after exit");
            st = -1;
        }
    }
    close(s->from);
    json_decref(s->diags);
    return st >= 0 && WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

/* ---- documents ------------------------------------------------------------------- */

static inline char *file_uri(const char *path)
{
    char *abs = realpath(path, NULL);
    char *uri = NULL;
    if (!abs) {                             /* a document not on disk: its folder is */
        const char *slash = strrchr(path, '/');
        char *dir = strndup(path, slash ? (size_t)(slash - path) : 0);
        char *rdir = realpath(*dir ? dir : ".", NULL);
        if (asprintf(&uri, "file://%s/%s", rdir, slash ? slash + 1 : path) < 0)
            uri = NULL;
        free(rdir);
        free(dir);
        return uri;
    }
    if (asprintf(&uri, "file://%s", abs) < 0)
        uri = NULL;
    free(abs);
    return uri;
}

static inline void open_doc(server *s, const char *uri, const char *text)
{
    notify(s, "textDocument/didOpen",
           json_pack("{s:{s:s, s:s, s:i, s:s}}", "textDocument", "uri", uri, "languageId", "sg",
                     "version", 1, "text", text));
}

static inline void change_doc(server *s, const char *uri, int version, const char *text)
{
    notify(s, "textDocument/didChange",
           json_pack("{s:{s:s, s:i}, s:[{s:s}]}", "textDocument", "uri", uri, "version",
                     version, "contentChanges", "text", text));
}

static inline json_t *at(const char *uri, int line, int character)
{
    return json_pack("{s:{s:s}, s:{s:i, s:i}}", "textDocument", "uri", uri, "position", "line",
                     line, "character", character);
}

/* The (line, character) just after the first `needle` in text. */
static inline void position_after(const char *text, const char *needle, int *line, int *character)
{
    const char *hit = strstr(text, needle);
    *line = *character = 0;
    if (!hit) {
        CHECK(false, "'%s' is not in the document", needle);
        return;
    }
    hit += strlen(needle);
    for (const char *c = text; c < hit; c++) {
        if (*c == '\n') {
            (*line)++;
            *character = 0;
        } else {
            (*character)++;                 /* ASCII documents */
        }
    }
}

/* The diagnostics the server published last for uri; synchronised by a
 * request on that document (a changed document is analysed, and its
 * diagnostics sent, before a request on it is answered). */
static inline json_t *diagnostics(server *s, const char *uri)
{
    json_decref(request(s, "textDocument/hover", at(uri, 0, 0)));
    return json_object_get(s->diags, uri);
}

/* The labels of a completion response, one string "|a|b|c|". */
static inline char *labels(json_t *resp)
{
    json_t *result = json_object_get(resp, "result");
    json_t *items = json_is_array(result) ? result : json_object_get(result, "items");
    size_t n = 2, i;
    json_t *it;
    json_array_foreach(items, i, it)
        n += strlen(json_string_value(json_object_get(it, "label"))) + 1;
    char *out = malloc(n + 1);
    strcpy(out, "|");
    json_array_foreach(items, i, it) {
        strcat(out, json_string_value(json_object_get(it, "label")));
        strcat(out, "|");
    }
    return out;
}

static inline bool offers(const char *list, const char *label)
{
    char want[128];
    snprintf(want, sizeof want, "|%s|", label);
    return strstr(list, want) != NULL;
}

/* Completion at the end of the first `needle` of text (the document at uri). */
static inline char *complete_after(server *s, const char *uri, const char *text, const char *needle)
{
    int line, ch;
    position_after(text, needle, &line, &ch);
    json_t *r = request(s, "textDocument/completion", at(uri, line, ch));
    CHECK(r && json_is_array(json_object_get(r, "result")), "completion after '%s' gave no list",
          needle);
    char *l = r ? labels(r) : strdup("|");
    json_decref(r);
    return l;
}

#endif
