/* lsp_text.c — where things are, in the client's terms: file:// URIs and
 * paths, and LSP positions (0-based line, column in UTF-16 code units or,
 * when negotiated, bytes) against the front end's locations (1-based line,
 * 1-based byte column).
 *
 * Columns: a UTF-8 sequence of 1 to 3 bytes is one UTF-16 unit, one of 4
 * bytes (outside the BMP) two; a byte that starts no well-formed sequence
 * counts as one.  A client position inside a surrogate pair lands on the
 * pair's character.  Lines end at "\n" (a "\r" before it is not counted
 * by the client and so never reached); a lone "\r" does not end a line,
 * as it does not for the lexer. */
#include "lsp.h"
#include "util.h"

#include <limits.h>
#include <stdlib.h>
#include <string.h>

/* ---- URIs and paths ------------------------------------------------------- */

static int hex(int c)
{
    return c >= '0' && c <= '9' ? c - '0'
         : c >= 'a' && c <= 'f' ? c - 'a' + 10
         : c >= 'A' && c <= 'F' ? c - 'A' + 10 : -1;
}

char *lsp_uri_path(const char *uri)
{
    if (strncmp(uri, "file://", 7))
        return xstrdup(uri);
    const char *s = uri + 7;
    if (*s != '/') {                        /* file://host/path */
        s = strchr(s, '/');
        if (!s)
            return xstrdup("/");
    }
    char *out = xmalloc(strlen(s) + 1), *o = out;
    for (; *s && *s != '?' && *s != '#'; s++) {
        if (*s == '%' && hex(s[1]) >= 0 && hex(s[2]) >= 0) {
            char c = (char)(hex(s[1]) * 16 + hex(s[2]));
            s += 2;
            *o++ = c ? c : '_';             /* no NUL inside a path */
        } else {
            *o++ = *s;
        }
    }
    *o = 0;
    return out;
}

char *lsp_path_uri(const char *path)
{
    char *abs = splat_path_absolute(path);
    size_t n = strlen(abs);
    char *out = xmalloc(7 + 3 * n + 1), *o = out;
    memcpy(o, "file://", 7);
    o += 7;
    for (const unsigned char *c = (const unsigned char *)abs; *c; c++) {
        if ((*c >= 'A' && *c <= 'Z') || (*c >= 'a' && *c <= 'z') ||
            (*c >= '0' && *c <= '9') || strchr("-._~/", *c))
            *o++ = (char)*c;
        else
            o += sprintf(o, "%%%02X", *c);
    }
    *o = 0;
    free(abs);
    return out;
}

char *lsp_canonical(const char *path)
{
    char *real = realpath(path, NULL);
    if (real)
        return real;
    /* not on disk (an unsaved document): its folder resolved, if it is */
    char *abs = splat_path_absolute(path);
    char *dir = splat_path_dir(abs);
    char *rdir = realpath(dir, NULL);
    char *out = abs;
    if (rdir) {
        const char *base = strrchr(abs, '/');
        out = xasprintf("%s%s", strcmp(rdir, "/") ? rdir : "", base ? base : "/");
        free(abs);
    }
    free(rdir);
    free(dir);
    return out;
}

/* ---- positions -------------------------------------------------------------- */

/* Bytes in the UTF-8 sequence at s (1 if it is not well formed). */
static int seq_len(const unsigned char *s, const unsigned char *end)
{
    int n = s[0] < 0x80 ? 1 : s[0] >= 0xC2 && s[0] <= 0xDF ? 2
          : s[0] >= 0xE0 && s[0] <= 0xEF ? 3 : s[0] >= 0xF0 && s[0] <= 0xF4 ? 4 : 1;
    if (end - s < n)
        return 1;
    for (int i = 1; i < n; i++)
        if ((s[i] & 0xC0) != 0x80)
            return 1;
    return n;
}

/* Columns one character takes: bytes (utf8) or UTF-16 units. */
static int units(const lsp_server *s, int bytes)
{
    return s->utf8 ? bytes : bytes == 4 ? 2 : 1;
}

/* Offset of the start of 0-based `line` (len if past the end). */
static size_t line_offset(const char *text, size_t len, int line)
{
    size_t o = 0;
    for (int l = 0; l < line; l++) {
        const char *nl = memchr(text + o, '\n', len - o);
        if (!nl)
            return len;
        o = (size_t)(nl - text) + 1;
    }
    return o;
}

size_t lsp_offset(const lsp_server *s, const char *text, size_t len, int line, int character)
{
    if (line < 0)
        return 0;
    size_t o = line_offset(text, len, line);
    const unsigned char *p = (const unsigned char *)text + o, *end = (const unsigned char *)text + len;
    int col = 0;
    while (p < end && *p != '\n' && col < character) {
        int b = seq_len(p, end);
        if (col + units(s, b) > character)
            break;                          /* inside a surrogate pair */
        col += units(s, b);
        p += b;
    }
    return (size_t)((const char *)p - text);
}

json_t *lsp_position_at(const lsp_server *s, const char *text, size_t len, size_t offset)
{
    if (offset > len)
        offset = len;
    int line = 0;
    size_t start = 0;
    for (const char *c = text; c < text + offset; c++)
        if (*c == '\n') {
            line++;
            start = (size_t)(c - text) + 1;
        }
    const unsigned char *p = (const unsigned char *)text + start;
    const unsigned char *at = (const unsigned char *)text + offset;
    const unsigned char *end = (const unsigned char *)text + len;
    int col = 0;
    while (p < at) {
        int b = seq_len(p, end);
        col += units(s, b);
        p += b;
    }
    return json_pack("{s:i, s:i}", "line", line, "character", col);
}

size_t lsp_loc_offset(const char *text, size_t len, int line, int col)
{
    if (line < 1)
        return 0;
    size_t o = line_offset(text, len, line - 1);
    const char *nl = memchr(text + o, '\n', len - o);
    size_t eol = nl ? (size_t)(nl - text) : len;
    size_t at = o + (size_t)(col > 1 ? col - 1 : 0);
    return at < eol ? at : eol;
}

static bool word_char(int c)
{
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
           c == '_';
}

json_t *lsp_range_at(const lsp_server *s, const char *text, size_t len, int line, int col)
{
    size_t a = lsp_loc_offset(text, len, line, col), b = a;
    if (line >= 1 && a < len) {
        char c = text[a];
        bool number = (c >= '0' && c <= '9') || c == '-' || c == '.';
        if (word_char((unsigned char)c) || number) {
            b = a + 1;                      /* a name, or a number with its dot */
            while (b < len && (word_char((unsigned char)text[b]) ||
                               (number && text[b] == '.')))
                b++;
        } else if (c == '"') {
            b = a + 1;                      /* a string, to its quote */
            while (b < len && text[b] != '\n' && text[b] != '"')
                b += text[b] == '\\' && b + 1 < len && text[b + 1] != '\n' ? 2 : 1;
            if (b < len && text[b] == '"')
                b++;
        } else if (c != '\n') {
            b = a + (size_t)seq_len((const unsigned char *)text + a,
                                    (const unsigned char *)text + len);
        }
    }
    return json_pack("{s:o, s:o}", "start", lsp_position_at(s, text, len, a),
                     "end", lsp_position_at(s, text, len, b));
}

json_t *lsp_location(lsp_server *s, const sg_file *f, int line, int col)
{
    char *path = lsp_canonical(f->path);
    lsp_doc *doc = lsp_doc_by_path(s, path);
    char *uri = doc ? xstrdup(doc->uri) : lsp_path_uri(path);
    json_t *loc = json_pack("{s:s, s:o}", "uri", uri,
                            "range", lsp_range_at(s, f->text, f->len, line, col));
    free(uri);
    free(path);
    return loc;
}

/* ---- documents ------------------------------------------------------------ */

/* The open document at canonical `path`, or NULL. */
lsp_doc *lsp_doc_by_path(lsp_server *s, const char *path)
{
    for (int i = 0; i < s->ndocs; i++)
        if (!strcmp(s->docs[i].path, path))
            return &s->docs[i];
    return NULL;
}
