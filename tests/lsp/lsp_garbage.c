/* lsp_garbage.c — `lsp_garbage SPLATC DIR`: `splatc lsp` fed bad input.
 *
 * Each bad header block (no Content-Length, a bad or conflicting one, an
 * over-long line, binary bytes) and each body that is not JSON is answered
 * with a ParseError whose id is null; a JSON value that is not a request
 * with InvalidRequest; a body over the limit is skipped and answered; a
 * request before initialize is ServerNotInitialized, an unknown one
 * MethodNotFound, one with bad params InvalidParams; negotiated utf-8
 * positions count bytes.  Then, from a fixed seed, random documents
 * (tokens of the language, stray bytes, unclosed blocks) opened and edited
 * with random ranged edits, with completion, hover and definition at
 * random places; and valid messages with random bytes changed.  The server
 * must answer every request and, after shutdown, exit with 0.  Last, two
 * servers whose input ends without `exit` (one inside a body) must end
 * with status 1. */
#include "client.h"

#include <stdint.h>

/* The next message that is a response (notifications are noted). */
static json_t *next_response(server *s)
{
    for (;;) {
        json_t *m = receive(s);
        if (!m || !json_object_get(m, "method"))
            return m;
        note(s, m);
        json_decref(m);
    }
}

/* Expect an error response with `code` (and, if null_id, a null id: a
 * message whose id could not be read), its message containing `says`. */
static void expect_error_says(server *s, int code, bool null_id, const char *says,
                              const char *what)
{
    json_t *r = next_response(s);
    json_t *err = json_object_get(r, "error");
    int got = (int)json_integer_value(json_object_get(err, "code"));
    CHECK(r && got == code, "%s: error code %d, expected %d", what, got, code);
    const char *msg = json_string_value(json_object_get(err, "message"));
    CHECK(!says || (msg && strstr(msg, says)), "%s: the message '%s' does not say '%s'", what,
          msg ? msg : "", says ? says : "");
    if (null_id)
        CHECK(r && json_is_null(json_object_get(r, "id")), "%s: the id is not null", what);
    json_decref(r);
}

static void expect_error(server *s, int code, bool null_id, const char *what)
{
    expect_error_says(s, code, null_id, NULL, what);
}

/* Read until the response to sync request `id` (others are dropped). */
static bool sync_on(server *s, int id)
{
    notify(s, "$/sync", NULL);              /* an unknown notification: ignored */
    send_json(s, json_pack("{s:s, s:i, s:s, s:{s:{s:s}, s:{s:i, s:i}}}", "jsonrpc", "2.0",
                           "id", id, "method", "textDocument/hover", "params", "textDocument",
                           "uri", "file:///nonexistent/x.sg", "position", "line", 0,
                           "character", 0));
    for (;;) {
        json_t *m = receive(s);
        if (!m)
            return false;
        bool done = json_integer_value(json_object_get(m, "id")) == id &&
                    !json_object_get(m, "method");
        json_decref(m);
        if (done)
            return true;
    }
}

static void framing(server *s)
{
    static const char *const blocks[] = {
        "this is not a header\r\n\r\n",
        "Content-Length: abc\r\n\r\n",
        "Content-Length: 99999999999999999999\r\n\r\n",
        "Content-Length: 2\r\nContent-Length: 3\r\n\r\n",
        "Content-Type: application/vscode-jsonrpc\r\n\r\n",
    };
    static const char binary[] = "\x01\x02\xff\xfe:\x00garbage\n\n";
    for (size_t i = 0; i <= sizeof blocks / sizeof blocks[0]; i++) {
        if (i < sizeof blocks / sizeof blocks[0])
            send_raw(s, blocks[i], strlen(blocks[i]));
        else
            send_raw(s, binary, sizeof binary - 1);
        char what[32];
        snprintf(what, sizeof what, "header block %zu", i);
        expect_error(s, -32700, true, what);
    }
    /* a header line of 10 KiB, no Content-Length */
    char *big = malloc(10240 + 5);
    memset(big, 'x', 10240);
    memcpy(big + 10240, "\r\n\r\n", 4);
    send_raw(s, big, 10244);
    free(big);
    expect_error_says(s, -32700, true, "without Content-Length", "an over-long header line");
    /* a body over the 64 MiB limit: skipped, answered */
    size_t over = ((size_t)64 << 20) + 1;
    char head[64];
    int k = snprintf(head, sizeof head, "Content-Length: %zu\r\n\r\n", over);
    send_raw(s, head, (size_t)k);
    char *chunk = malloc(1 << 20);
    memset(chunk, '{', 1 << 20);
    for (size_t sent = 0; sent < over; sent += 1 << 20)
        send_raw(s, chunk, over - sent < (1 << 20) ? over - sent : (1 << 20));
    free(chunk);
    expect_error_says(s, -32700, true, "at most", "a body over the limit");

    static const char *const bodies[] = { "{not json", "[1, 2]", "\"text\"",
                                          "{\"jsonrpc\":\"2.0\",\"id\":{},\"method\":\"x\"}",
                                          "{\"jsonrpc\":\"2.0\",\"id\":5}" };
    static const int codes[] = { -32700, -32600, -32600, -32600, -32600 };
    for (size_t i = 0; i < sizeof bodies / sizeof bodies[0]; i++) {
        send_body(s, bodies[i], strlen(bodies[i]));
        char what[64];
        snprintf(what, sizeof what, "body '%s'", bodies[i]);
        expect_error(s, codes[i], i != 4, what);
    }
    /* the same framing with bare "\n" line ends is read */
    const char *lf = "Content-Length: 8\n\n[1, 2.5]";
    send_raw(s, lf, strlen(lf));
    expect_error(s, -32600, true, "a message with \\n line ends");
}

/* Negotiated utf-8: columns are bytes (after a 2-byte and a 4-byte character). */
static void utf8_columns(server *s, const char *dir)
{
    static const char text[] =
        "material u {\n"
        "    node t : sample { tex = \"\xc3\xa9\xf0\x9f\x98\x80.png\", uv = nope }\n"
        "}\n";
    char path[4096];
    snprintf(path, sizeof path, "%s/unsaved_utf8.sg", dir);
    char *uri = file_uri(path);
    open_doc(s, uri, text);
    json_t *list = diagnostics(s, uri), *d;
    size_t i;
    int bytes = (int)(strstr(text, "nope") - strstr(text, "    node")), got = -1;
    json_array_foreach(list, i, d)
        if (strstr(json_string_value(json_object_get(d, "message")) ?: "", "'nope'"))
            got = (int)json_integer_value(json_object_get(json_object_get(
                json_object_get(d, "range"), "start"), "character"));
    CHECK(got == bytes, "utf-8 columns: 'nope' at %d, expected byte %d", got, bytes);
    notify(s, "textDocument/didClose", json_pack("{s:{s:s}}", "textDocument", "uri", uri));
    free(uri);
}

static void requests(server *s)
{
    json_t *r = request(s, "textDocument/hover", NULL);
    CHECK(json_integer_value(json_object_get(json_object_get(r, "error"), "code")) == -32002,
          "a request before initialize");
    json_decref(r);
    notify(s, "textDocument/didOpen", json_object());   /* dropped before initialize */
    r = request(s, "initialize", json_pack("{s:{s:{s:[s]}}}", "capabilities", "general",
                                           "positionEncodings", "utf-8"));
    CHECK(!strcmp(json_string_value(json_object_get(json_object_get(
                      json_object_get(r, "result"), "capabilities"), "positionEncoding")) ?: "",
                  "utf-8"), "a client offering utf-8 gets it");
    json_decref(r);
    struct { const char *method; json_t *params; int code; } bad[] = {
        { "initialize", json_object(), -32600 },
        { "no/such/method", json_object(), -32601 },
        { "textDocument/hover", json_object(), -32602 },
        { "textDocument/completion", json_pack("{s:{s:s}, s:{s:i, s:i}}", "textDocument", "uri",
                                               "file:///x.sg", "position", "line", -1,
                                               "character", 0), -32602 },
        { "textDocument/definition", json_pack("{s:{s:i}}", "textDocument", "uri", 7), -32602 },
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        r = request(s, bad[i].method, bad[i].params);
        int code = (int)json_integer_value(json_object_get(json_object_get(r, "error"), "code"));
        CHECK(code == bad[i].code, "%s: code %d, expected %d", bad[i].method, code, bad[i].code);
        json_decref(r);
    }
    /* notifications with the wrong shapes are ignored */
    notify(s, "textDocument/didOpen", json_pack("{s:i}", "textDocument", 3));
    notify(s, "textDocument/didChange", json_pack("{s:{s:s}, s:s}", "textDocument", "uri",
                                                  "file:///x.sg", "contentChanges", "x"));
    notify(s, "textDocument/didClose", json_pack("{s:[]}", "textDocument"));
    r = request(s, "textDocument/hover", at("file:///not/open.sg", 0, 0));
    CHECK(r && json_is_null(json_object_get(r, "result")), "hover on a document not open");
    json_decref(r);
}

/* ---- random documents ------------------------------------------------------------ */

static uint64_t rng = 0x9E3779B97F4A7C15ull;
static uint32_t rnd(uint32_t n)
{
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return n ? (uint32_t)(rng % n) : 0;
}

static char *random_doc(void)
{
    static const char *const words[] = {
        "import \"lib.sg\"", "import \"nodes/masks.sg\"", "import \"nope.sg\"", "material",
        "shader", "scene", "texture", "node", "in", "out", "param", "undergrowth", "grass",
        "float", "vec3", "vec3(1, 0, 0)", "m", "a", "b", "edge", "ramp", "mix", "painted",
        "terrain", "terrain.slope", "view.", ".", ":", "=", "{", "}", "[", "]", "(", ")", ",",
        "0.5", "-1e9", "1.2.3", "\"tex.png\"", "\"unclosed", "# comment", "\n", "\n", "\n",
        "x", "lo", "hi", "mask", "albedo", "materials", "compositor", "light", "camera",
        "heightfield", "range", "\xc3\xa9", "\xf0\x9f\x98\x80", "\xff", "\t", "\r\n", "#",
    };
    size_t n = 1 + rnd(300), cap = 16;
    char *out = malloc(cap);
    size_t len = 0;
    for (size_t i = 0; i < n; i++) {
        const char *w = words[rnd(sizeof words / sizeof words[0])];
        size_t wl = strlen(w);
        if (len + wl + 2 > cap) {
            cap = 2 * (len + wl + 2);
            out = realloc(out, cap);
        }
        memcpy(out + len, w, wl);
        len += wl;
        out[len++] = rnd(3) ? ' ' : '\n';
    }
    out[len] = 0;
    return out;
}

static void random_session(server *s, const char *dir)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/unsaved_random.sg", dir);
    char *uri = file_uri(path);
    static const char *const methods[] = { "textDocument/completion", "textDocument/hover",
                                           "textDocument/definition" };
    /* LSP_GARBAGE_ROUNDS and LSP_GARBAGE_SEED (environment) for a longer run */
    int rounds = getenv("LSP_GARBAGE_ROUNDS") ? atoi(getenv("LSP_GARBAGE_ROUNDS")) : 60;
    if (getenv("LSP_GARBAGE_SEED"))
        rng ^= strtoull(getenv("LSP_GARBAGE_SEED"), NULL, 0) * 0x9E3779B97F4A7C15ull + 1;
    for (int round = 0; round < rounds; round++) {
        char *text = random_doc();
        if (round == 0)
            open_doc(s, uri, text);
        else
            change_doc(s, uri, round + 1, text);
        free(text);
        for (int k = 0; k < 3; k++) {
            /* a ranged edit somewhere, possibly past the end */
            char *ins = random_doc();
            ins[rnd((uint32_t)strlen(ins) + 1)] = 0;
            notify(s, "textDocument/didChange",
                   json_pack("{s:{s:s, s:i}, s:[{s:{s:{s:i, s:i}, s:{s:i, s:i}}, s:s}]}",
                             "textDocument", "uri", uri, "version", 1000 + round,
                             "contentChanges", "range", "start", "line", (int)rnd(40),
                             "character", (int)rnd(60), "end", "line", (int)rnd(40),
                             "character", (int)rnd(60), "text", ins));
            free(ins);
        }
        for (int k = 0; k < 12; k++) {
            json_t *r = request(s, methods[rnd(3)], at(uri, (int)rnd(40), (int)rnd(90)));
            CHECK(r && (json_object_get(r, "result") || json_object_get(r, "error")),
                  "round %d: a request got no answer", round);
            json_decref(r);
            if (!r)
                return;
        }
    }
    free(uri);
}

/* Valid messages with random bytes changed, each followed by a request
 * that must be answered. */
static void mutations(server *s)
{
    static const char *const seeds[] = {
        "{\"jsonrpc\":\"2.0\",\"id\":1,\"method\":\"textDocument/completion\",\"params\":"
        "{\"textDocument\":{\"uri\":\"file:///tmp/m.sg\"},\"position\":{\"line\":2,\"character\":9}}}",
        "{\"jsonrpc\":\"2.0\",\"method\":\"textDocument/didOpen\",\"params\":{\"textDocument\":"
        "{\"uri\":\"file:///tmp/m.sg\",\"languageId\":\"sg\",\"version\":1,\"text\":"
        "\"material m {\\n node a : ramp { x = terrain.slope }\\n out mask = a.out\\n}\\n\"}}}",
        "{\"jsonrpc\":\"2.0\",\"id\":\"s\",\"method\":\"textDocument/hover\",\"params\":"
        "{\"textDocument\":{\"uri\":\"file:///tmp/m.sg\"},\"position\":{\"line\":1,\"character\":12}}}",
    };
    for (int i = 0; i < 300; i++) {
        const char *seed = seeds[rnd(3)];
        size_t n = strlen(seed);
        char *m = strdup(seed);
        for (int k = 0, flips = 1 + (int)rnd(4); k < flips; k++)
            m[rnd((uint32_t)n)] = (char)rnd(256);
        send_body(s, m, n);
        free(m);
        if (!sync_on(s, 100000 + i)) {
            CHECK(false, "mutation %d: the server stopped answering", i);
            return;
        }
    }
}

int main(int argc, char **argv)
{
    if (argc != 3) {
        fprintf(stderr, "usage: lsp_garbage SPLATC DIR\n");
        return 2;
    }
    signal(SIGPIPE, SIG_IGN);
    server s;
    start(&s, argv[1]);
    framing(&s);
    requests(&s);
    utf8_columns(&s, argv[2]);
    random_session(&s, argv[2]);
    mutations(&s);
    /* "params": null, as some clients send it, is no params */
    send_json(&s, json_pack("{s:s, s:i, s:s, s:n}", "jsonrpc", "2.0", "id", 7, "method",
                            "shutdown", "params"));
    json_t *id = json_integer(7);
    json_t *r = response(&s, id);
    json_decref(id);
    CHECK(r && json_is_null(json_object_get(r, "result")) && !json_object_get(r, "error"),
          "shutdown (params null) after the garbage");
    json_decref(r);
    int st = finish(&s, true);
    CHECK(st == 0, "exit after shutdown: status %d", st);

    /* the input ends without exit: status 1 */
    start(&s, argv[1]);
    json_decref(request(&s, "initialize", json_pack("{s:{}}", "capabilities")));
    st = finish(&s, false);
    CHECK(st == 1, "end of input without exit: status %d, expected 1", st);
    start(&s, argv[1]);
    send_raw(&s, "Content-Length: 100\r\n\r\n{\"jsonrpc\"", 33);
    st = finish(&s, false);
    CHECK(st == 1, "end of input inside a body: status %d, expected 1", st);

    if (failures)
        fprintf(stderr, "%d check%s failed\n", failures, failures == 1 ? "" : "s");
    else
        printf("lsp garbage: ok\n");
    return failures ? 1 : 0;
}
