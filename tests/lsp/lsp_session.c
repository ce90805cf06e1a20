/* lsp_session.c — `lsp_session SPLATC DIR`: an editing session with
 * `splatc lsp`, as an editor would drive it (DIR: tests/lsp, lib.sg).
 *
 * initialize; didOpen of a document (not on disk) with an unknown node
 * type: its diagnostic's range, severity, code, message and suggestion;
 * completion after `node c : ` (built-in ops, the imported shader),
 * `x = terrain.`, `view.`, inside a node's braces (the ports not bound
 * yet), `out ` in a material, in a scene (keys; materials in `[`); hover
 * on a port (type, default, doc comment) and on a terrain input;
 * definition of an imported shader (lib.sg's line), a scene's material, a
 * node and an import; quick fixes of "did you mean"s; an unsaved edit to the imported file (what the
 * document sees, an error in it shown on the import line); UTF-16 columns
 * after non-ASCII text; a clean document's empty list; shutdown (null)
 * and exit (status 0). */
#include "client.h"

static const char main_text[] =
    "import \"lib.sg\"\n"                              /* 0 */
    "import \"nodes/compositors.sg\"\n"
    "\n"
    "# m: the test material.\n"
    "material m {\n"                                   /* 4 */
    "    node a : edge { x = terrain.slope, lo = 0.3 }\n"
    "    node b : rampp { x = a.out }\n"               /* 6: the error */
    "    out mask = a.out\n"
    "}\n"
    "\n"
    "scene s {\n"                                      /* 10 */
    "    heightfield = \"hf.png\"\n"
    "    size = 100 100\n"
    "    max_height = 10\n"
    "    materials = [m]\n"                            /* 14 */
    "}\n";

/* The same, being edited: lines that stop where completion is asked. */
static const char edit_text[] =
    "import \"lib.sg\"\n"
    "import \"nodes/compositors.sg\"\n"
    "\n"
    "material m {\n"
    "    node a : edge { x = terrain.slope, lo = 0.3 }\n"
    "    node c : \n"
    "    node d : edge { x = terrain.\n"
    "    node v : mul { a = view.\n"
    "    node e : edge { lo = 0.3, \n"
    "    node f : mix { a = \n"
    "    out \n"
    "    out mask = a.\n"
    "}\n"
    "\n"
    "scene s {\n"
    "    \n"
    "    materials = [m, \n"
    "    compositor = \n"
    "}\n";

/* lib.sg as an unsaved buffer: a second shader, another default. */
static const char lib_edit[] =
    "import \"nodes/masks.sg\"\n"
    "shader edge {\n"
    "    in float x\n"
    "    in float lo = 0.4   # moved\n"
    "    in float hi = 0.75\n"
    "    node r : ramp { x = x, lo = lo, hi = hi }\n"
    "    out float out = r.out\n"
    "}\n"
    "shader edge2 {\n"
    "    in float x\n"
    "    node r : rampz { x = x }\n"                   /* 10: an error in the import */
    "    out float out = r.out\n"
    "}\n";

static const char clean_text[] =
    "import \"lib.sg\"\n"
    "material m {\n"
    "    node a : edge { x = terrain.slope }\n"
    "    out mask = a.out\n"
    "}\n";

/* U+00E9 (2 bytes, 1 UTF-16 unit) and U+1F600 (4 bytes, 2 units) before the error. */
static const char utf16_text[] =
    "material u {\n"
    "    node t : sample { tex = \"\xc3\xa9\xf0\x9f\x98\x80.png\", uv = nope }\n"
    "    out albedo = t.rgb\n"
    "    out roughness = terrain.slpe.x\n"                 /* 3: a quick fix of two parts */
    "}\n";

/* The diagnostic of `list` whose message contains `part`, or NULL. */
static json_t *find_diag(json_t *list, const char *part)
{
    size_t i;
    json_t *d;
    json_array_foreach(list, i, d) {
        const char *m = json_string_value(json_object_get(d, "message"));
        if (m && strstr(m, part))
            return d;
    }
    return NULL;
}

static void check_range(json_t *range, int l0, int c0, int l1, int c1, const char *what)
{
    json_int_t a, b, c, d;
    bool ok = !json_unpack(range, "{s:{s:I, s:I}, s:{s:I, s:I}}", "start", "line", &a,
                           "character", &b, "end", "line", &c, "character", &d);
    CHECK(ok && a == l0 && b == c0 && c == l1 && d == c1,
          "%s: range %d:%d-%d:%d, expected %d:%d-%d:%d", what, (int)a, (int)b, (int)c, (int)d,
          l0, c0, l1, c1);
}

/* The quick fix codeAction offers for diagnostic d of uri: its edit's
 * range is checked, its new text returned (malloc'd; "" if none). */
static char *quick_fix(server *s, const char *uri, json_t *d, int l0, int c0, int l1, int c1)
{
    json_t *r = request(s, "textDocument/codeAction",
                        json_pack("{s:{s:s}, s:O, s:{s:[O]}}", "textDocument", "uri", uri,
                                  "range", json_object_get(d, "range"), "context",
                                  "diagnostics", d));
    json_t *action = json_array_get(json_object_get(r, "result"), 0);
    json_t *edit = json_array_get(json_object_get(json_object_get(json_object_get(action, "edit"),
                                                                  "changes"), uri), 0);
    CHECK(edit, "no quick fix for '%s'", json_string_value(json_object_get(d, "message")));
    check_range(json_object_get(edit, "range"), l0, c0, l1, c1, "quick fix");
    char *text = strdup(json_string_value(json_object_get(edit, "newText")) ?: "");
    json_decref(r);
    return text;
}

static const char *hover_text(json_t *r)
{
    const char *v = json_string_value(json_object_get(
        json_object_get(json_object_get(r, "result"), "contents"), "value"));
    return v ? v : "";
}

static void diagnostics_and_initialize(server *s, const char *uri)
{
    json_t *r = request(s, "initialize", json_pack("{s:i, s:n, s:{}}", "processId", (int)getpid(),
                                                   "rootUri", "capabilities"));
    json_t *caps = json_object_get(json_object_get(r, "result"), "capabilities");
    CHECK(json_is_true(json_object_get(caps, "hoverProvider")) &&
          json_is_true(json_object_get(caps, "definitionProvider")) &&
          json_object_get(caps, "completionProvider"), "initialize: capabilities missing");
    CHECK(!strcmp(json_string_value(json_object_get(caps, "positionEncoding")) ?: "", "utf-16"),
          "initialize: a client offering nothing gets utf-16");
    json_decref(r);
    notify(s, "initialized", json_object());

    open_doc(s, uri, main_text);
    json_t *list = diagnostics(s, uri);
    json_t *d = find_diag(list, "unknown node type 'rampp'");
    CHECK(d, "didOpen: no diagnostic for rampp (%zu published)", json_array_size(list));
    if (d) {
        check_range(json_object_get(d, "range"), 6, 13, 6, 18, "rampp");
        CHECK(json_integer_value(json_object_get(d, "severity")) == 1, "rampp: not an error");
        CHECK(!strcmp(json_string_value(json_object_get(d, "code")) ?: "", "UNKNOWN_NODE"),
              "rampp: code");
        CHECK(strstr(json_string_value(json_object_get(d, "message")), "did you mean 'ramp'?"),
              "rampp: no suggestion in the message");
        CHECK(!strcmp(json_string_value(json_object_get(json_object_get(d, "data"),
                                                        "suggestion")) ?: "", "ramp"),
              "rampp: data.suggestion");
        char *fix = quick_fix(s, uri, d, 6, 13, 6, 18);
        CHECK(!strcmp(fix, "ramp"), "quick fix for rampp: '%s'", fix);
        free(fix);
    }
    CHECK(json_array_size(list) == 1, "didOpen: %zu diagnostics, expected only rampp's",
          json_array_size(list));
}

static void completions(server *s, const char *uri)
{
    change_doc(s, uri, 2, edit_text);
    struct { const char *after; const char *want[6]; const char *not[3]; } cases[] = {
        { "node c : ", { "ramp", "edge", "mix", "painted", "terrain.slope", "scale_contrast" },
          { "m", "slope" } },
        { "node d : edge { x = terrain.", { "slope", "height", "normal", "position", "uv", "destruction" },
          { "distance", "ramp" } },
        { "a = view.", { "distance", "direction" }, { "slope" } },
        { "node e : edge { lo = 0.3, ", { "x", "hi" }, { "lo", "ramp" } },
        { "node f : mix { a = ", { "a", "terrain", "view" }, { "mix" } },
        { "    out ", { "mask", "albedo", "normal", "roughness", "height" }, { "ramp" } },
        { "out mask = a.", { "out" }, { "slope" } },
        { "materials = [m, ", { "m" }, { "ramp", "heightfield" } },
        { "scene s {\n    ", { "heightfield", "max_height", "compositor", "light",
                                      "camera" }, { "m" } },
        { "compositor = ", { "linear_alpha", "ramp" }, { "m" } },
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        char *l = complete_after(s, uri, edit_text, cases[i].after);
        for (int k = 0; k < 6 && cases[i].want[k]; k++)
            CHECK(offers(l, cases[i].want[k]), "completion after '%s' lacks %s: %s",
                  cases[i].after, cases[i].want[k], l);
        for (int k = 0; k < 3 && cases[i].not[k]; k++)
            CHECK(!offers(l, cases[i].not[k]), "completion after '%s' offers %s", cases[i].after,
                  cases[i].not[k]);
        free(l);
    }
}

static void hover_and_definition(server *s, const char *uri, const char *lib_uri)
{
    change_doc(s, uri, 3, main_text);
    /* hover on the port `lo` of `node a : edge { … lo = 0.3 }` (line 5) */
    json_t *r = request(s, "textDocument/hover", at(uri, 5, 40));
    const char *h = hover_text(r);
    CHECK(strstr(h, "in float lo = 0.25"), "hover on lo: no type and default: %s", h);
    CHECK(strstr(h, "where the edge starts"), "hover on lo: no doc comment: %s", h);
    CHECK(strstr(h, "`edge`"), "hover on lo: the shader is not named: %s", h);
    check_range(json_object_get(json_object_get(r, "result"), "range"), 5, 39, 5, 41, "hover lo");
    json_decref(r);
    r = request(s, "textDocument/hover", at(uri, 5, 33));   /* terrain.sl|ope */
    h = hover_text(r);
    CHECK(strstr(h, "float terrain.slope") && strstr(h, "[0, 1]"), "hover on slope: %s", h);
    json_decref(r);
    r = request(s, "textDocument/hover", at(uri, 5, 15));   /* ed|ge: the shader */
    h = hover_text(r);
    CHECK(strstr(h, "shader edge") && strstr(h, "a soft step of x"), "hover on edge: %s", h);
    json_decref(r);

    struct { int line, ch; const char *uri; int dline, dch; } defs[] = {
        { 5, 15, lib_uri, 6, 7 },           /* node a : ed|ge -> lib.sg `shader edge` */
        { 14, 17, uri, 4, 9 },              /* materials = [|m] -> `material m` */
        { 7, 15, uri, 5, 9 },               /* out mask = |a.out -> `node a` */
        { 0, 10, lib_uri, 0, 0 },           /* import "li|b.sg" -> the file */
    };
    for (size_t i = 0; i < sizeof defs / sizeof defs[0]; i++) {
        r = request(s, "textDocument/definition", at(uri, defs[i].line, defs[i].ch));
        json_t *loc = json_object_get(r, "result");
        const char *got = json_string_value(json_object_get(loc, "uri"));
        CHECK(got && !strcmp(got, defs[i].uri), "definition at %d:%d: uri %s, expected %s",
              defs[i].line, defs[i].ch, got ? got : "(none)", defs[i].uri);
        json_int_t l = -1, c = -1;
        json_unpack(loc, "{s:{s:{s:I, s:I}}}", "range", "start", "line", &l, "character", &c);
        CHECK(l == defs[i].dline && c == defs[i].dch, "definition at %d:%d: %d:%d, expected "
              "%d:%d", defs[i].line, defs[i].ch, (int)l, (int)c, defs[i].dline, defs[i].dch);
        json_decref(r);
    }
    r = request(s, "textDocument/definition", at(uri, 2, 0));   /* a blank line */
    CHECK(r && json_is_null(json_object_get(r, "result")), "definition on nothing is null");
    json_decref(r);
}

/* lib.sg opened with unsaved edits: the document sees them, and their
 * error shows on its import line; closed, the disk counts again. */
static void unsaved_import(server *s, const char *uri, const char *lib_uri)
{
    open_doc(s, lib_uri, lib_edit);
    change_doc(s, uri, 4, edit_text);
    char *l = complete_after(s, uri, edit_text, "node c : ");
    CHECK(offers(l, "edge2"), "the unsaved shader edge2 is not offered: %s", l);
    free(l);
    change_doc(s, uri, 5, main_text);
    json_t *r = request(s, "textDocument/hover", at(uri, 5, 40));
    CHECK(strstr(hover_text(r), "lo = 0.4"), "hover does not see the unsaved default: %s",
          hover_text(r));
    json_decref(r);
    json_t *d = find_diag(diagnostics(s, uri), "rampz");
    CHECK(d, "the unsaved import's error is not shown");
    if (d) {
        check_range(json_object_get(d, "range"), 0, 7, 0, 15, "import line");
        CHECK(strstr(json_string_value(json_object_get(d, "message")), "in lib.sg:11:14: "),
              "imported error: %s", json_string_value(json_object_get(d, "message")));
        json_t *rel = json_array_get(json_object_get(d, "relatedInformation"), 0);
        const char *ru = json_string_value(json_object_get(json_object_get(rel, "location"), "uri"));
        CHECK(ru && !strcmp(ru, lib_uri), "related information: %s", ru ? ru : "(none)");
    }
    notify(s, "textDocument/didClose", json_pack("{s:{s:s}}", "textDocument", "uri", lib_uri));
    change_doc(s, uri, 6, edit_text);
    l = complete_after(s, uri, edit_text, "node c : ");
    CHECK(!offers(l, "edge2") && offers(l, "edge"), "after didClose the disk's lib.sg: %s", l);
    free(l);
}

static void utf16_and_clean(server *s, const char *uri, const char *u_uri)
{
    open_doc(s, u_uri, utf16_text);
    json_t *d = find_diag(diagnostics(s, u_uri), "unknown name 'nope'");
    CHECK(d, "no diagnostic for nope");
    const char *line = strstr(utf16_text, "    node t");
    int bytes = (int)(strstr(line, "nope") - line);
    if (d)   /* é: 2 bytes, 1 unit; the emoji: 4 bytes, 2 units */
        check_range(json_object_get(d, "range"), 1, bytes - 3, 1, bytes + 1, "after UTF-8");
    d = find_diag(json_object_get(s->diags, u_uri), "terrain.slpe");
    CHECK(d, "no diagnostic for terrain.slpe");
    if (d) {   /* terrain.slpe of terrain.slpe.x, not the swizzle */
        char *fix = quick_fix(s, u_uri, d, 3, 20, 3, 32);
        CHECK(!strcmp(fix, "terrain.slope"), "quick fix for terrain.slpe: '%s'", fix);
        free(fix);
    }
    change_doc(s, uri, 7, clean_text);
    json_t *list = diagnostics(s, uri);
    CHECK(json_is_array(list) && json_array_size(list) == 0,
          "a clean document still has %zu diagnostics", json_array_size(list));
}

int main(int argc, char **argv)
{
    if (argc != 3) {
        fprintf(stderr, "usage: lsp_session SPLATC DIR\n");
        return 2;
    }
    signal(SIGPIPE, SIG_IGN);
    char path[4096];
    snprintf(path, sizeof path, "%s/unsaved_main.sg", argv[2]);
    char *uri = file_uri(path);
    snprintf(path, sizeof path, "%s/lib.sg", argv[2]);
    char *lib_uri = file_uri(path);
    snprintf(path, sizeof path, "%s/unsaved_utf16.sg", argv[2]);
    char *u_uri = file_uri(path);
    server s;
    start(&s, argv[1]);
    diagnostics_and_initialize(&s, uri);
    completions(&s, uri);
    hover_and_definition(&s, uri, lib_uri);
    unsaved_import(&s, uri, lib_uri);
    utf16_and_clean(&s, uri, u_uri);
    json_t *r = request(&s, "shutdown", NULL);
    CHECK(r && json_is_null(json_object_get(r, "result")) && !json_object_get(r, "error"),
          "shutdown: result null");
    json_decref(r);
    int st = finish(&s, true);
    CHECK(st == 0, "exit after shutdown: status %d, expected 0", st);
    free(uri);
    free(lib_uri);
    free(u_uri);
    if (failures)
        fprintf(stderr, "%d check%s failed\n", failures, failures == 1 ? "" : "s");
    else
        printf("lsp session: ok\n");
    return failures ? 1 : 0;
}
