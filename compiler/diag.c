/* diag.c — diagnostics: a list of user errors with stable ids (sg.h's
 * SG_ERRORS), printed GCC style with the source line and a caret:
 *
 *   graphs/cliff.sg:12:22: error: unknown node type 'rampp'
 *      12 |     node m  : rampp { x = s.out }
 *         |               ^
 *
 * Each diagnostic copies its file name and source line, so it stays
 * printable after the program that produced it is freed.  At most
 * SG_MAX_STORED_DIAGS are stored; later ones are only counted, so garbage
 * input cannot make the list (or the printout) grow without bound. */
#include "sg_internal.h"
#include "util.h"

#include <stdarg.h>
#include <stdlib.h>
#include <string.h>

/* Widest source excerpt printed under a diagnostic. */
#define EXCERPT_MAX 160

static const char *const formats[SG_E_COUNT] = {
#define X(id, fmt) fmt,
    SG_ERRORS(X)
#undef X
};

typedef struct source {
    char   *path;
    char   *text;
    size_t  len;
    size_t *lines;      /* start offset of each line, built on first use */
    int     nlines;
} source;

struct sg_sources {
    source *items;
    int     n, cap;
};

void sg_diags_init(sg_diags *d)
{
    memset(d, 0, sizeof *d);
}

void sg_diags_free(sg_diags *d)
{
    for (int i = 0; i < d->n; i++) {
        free(d->items[i].msg);
        free(d->items[i].src_line);
        free(d->items[i].suggestion);
        free((char *)d->items[i].loc.file);
    }
    free(d->items);
    if (d->sources) {
        for (int i = 0; i < d->sources->n; i++) {
            free(d->sources->items[i].path);
            free(d->sources->items[i].text);
            free(d->sources->items[i].lines);
        }
        free(d->sources->items);
        free(d->sources);
    }
    memset(d, 0, sizeof *d);
}

void sg_diags_add_source(sg_diags *d, const char *path, const char *text,
                         size_t len)
{
    if (!d->sources) {
        d->sources = xcalloc(1, sizeof *d->sources);
    }
    struct sg_sources *s = d->sources;
    if (s->n == s->cap) {
        s->cap = s->cap ? s->cap * 2 : 8;
        s->items = xrealloc(s->items, (size_t)s->cap * sizeof *s->items);
    }
    source *src = &s->items[s->n++];
    src->path = xstrdup(path);
    src->text = xmalloc(len + 1);
    memcpy(src->text, text, len);
    src->text[len] = 0;
    src->len = len;
    src->lines = NULL;
    src->nlines = 0;
}

/* The text of line `line` of `file` (not NUL-terminated), or NULL. */
static const char *find_line(sg_diags *d, const char *file, int line, size_t *n)
{
    if (!d->sources || !file || line < 1)
        return NULL;
    source *src = NULL;
    for (int i = d->sources->n - 1; i >= 0; i--)   /* latest wins */
        if (!strcmp(d->sources->items[i].path, file)) {
            src = &d->sources->items[i];
            break;
        }
    if (!src)
        return NULL;
    if (!src->lines) {
        int cap = 64;
        src->lines = xmalloc((size_t)cap * sizeof *src->lines);
        src->lines[src->nlines++] = 0;
        for (size_t i = 0; i < src->len; i++)
            if (src->text[i] == '\n') {
                if (src->nlines == cap) {
                    cap *= 2;
                    src->lines = xrealloc(src->lines, (size_t)cap * sizeof *src->lines);
                }
                src->lines[src->nlines++] = i + 1;
            }
    }
    if (line > src->nlines)
        return NULL;
    size_t start = src->lines[line - 1];
    size_t end = line < src->nlines ? src->lines[line] - 1 : src->len;
    if (end > start && src->text[end - 1] == '\r')
        end--;
    *n = end - start;
    return src->text + start;
}

/* A stored diagnostic equal to this one (its message perhaps with a hint
 * appended), for sg_diags.unique. */
static bool stored(const sg_diags *d, sg_loc loc, sg_severity sev, const char *msg)
{
    size_t n = strlen(msg);
    for (int i = 0; i < d->n; i++) {
        const sg_diag *g = &d->items[i];
        if (g->severity == sev && g->loc.line == loc.line && g->loc.col == loc.col &&
            (g->loc.file == loc.file || (g->loc.file && loc.file &&
                                         !strcmp(g->loc.file, loc.file))) &&
            !strncmp(g->msg, msg, n) && (g->msg[n] == 0 || g->msg[n] == ';'))
            return true;
    }
    return false;
}

static void add(sg_diags *d, sg_loc loc, sg_severity sev, sg_error_id id,
                const char *fmt, va_list ap)
{
    if (d->unique) {
        va_list ap3;
        va_copy(ap3, ap);
        int len = vsnprintf(NULL, 0, fmt, ap3);
        va_end(ap3);
        char *msg = xmalloc((size_t)(len > 0 ? len : 0) + 1);
        va_copy(ap3, ap);
        vsnprintf(msg, (size_t)(len > 0 ? len : 0) + 1, fmt, ap3);
        va_end(ap3);
        bool dup = stored(d, loc, sev, msg);
        free(msg);
        if (dup) {
            if (sev == SG_ERROR)
                d->nerrors++;   /* still an error of this load */
            d->last_dropped = true;
            return;
        }
    }
    if (sev == SG_ERROR)
        d->nerrors++;
    if (d->n >= SG_MAX_STORED_DIAGS) {
        d->ndropped++;
        d->last_dropped = true;
        return;
    }
    d->last_dropped = false;
    if (d->n == d->cap) {
        d->cap = d->cap ? d->cap * 2 : 16;
        d->items = xrealloc(d->items, (size_t)d->cap * sizeof *d->items);
    }
    va_list ap2;
    va_copy(ap2, ap);
    int len = vsnprintf(NULL, 0, fmt, ap);
    char *msg = xmalloc((size_t)(len > 0 ? len : 0) + 1);
    vsnprintf(msg, (size_t)(len > 0 ? len : 0) + 1, fmt, ap2);
    va_end(ap2);

    sg_diag *g = &d->items[d->n++];
    g->loc = loc;
    g->loc.file = loc.file ? xstrdup(loc.file) : NULL;
    g->severity = sev;
    g->id = id;
    g->msg = msg;
    g->src_line = NULL;
    g->suggestion = NULL;
    size_t n;
    const char *line = find_line(d, loc.file, loc.line, &n);
    if (line) {
        g->src_line = xmalloc(n + 1);
        memcpy(g->src_line, line, n);
        g->src_line[n] = 0;
    }
}

void sg_error(sg_diags *d, sg_loc loc, sg_error_id id, ...)
{
    va_list ap;
    va_start(ap, id);
    add(d, loc, SG_ERROR, id, formats[id], ap);
    va_end(ap);
}

void sg_errorf(sg_diags *d, sg_loc loc, sg_error_id id, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    add(d, loc, SG_ERROR, id, fmt, ap);
    va_end(ap);
}

void sg_warning(sg_diags *d, sg_loc loc, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    add(d, loc, SG_WARNING, SG_E_WARNING, fmt, ap);
    va_end(ap);
}

void sg_warning_id(sg_diags *d, sg_loc loc, sg_error_id id, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    add(d, loc, SG_WARNING, id, fmt, ap);
    va_end(ap);
}

void sg_note(sg_diags *d, sg_loc loc, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    add(d, loc, SG_NOTE, SG_E_INTERNAL, fmt, ap);
    va_end(ap);
}

void sg_hint(sg_diags *d, const char *fmt, ...)
{
    if (d->n == 0 || d->last_dropped)
        return;
    sg_diag *g = &d->items[d->n - 1];
    va_list ap, ap2;
    va_start(ap, fmt);
    va_copy(ap2, ap);
    int len = vsnprintf(NULL, 0, fmt, ap);
    va_end(ap);
    if (len < 0)
        len = 0;
    size_t old = strlen(g->msg);
    g->msg = xrealloc(g->msg, old + 2 + (size_t)len + 1);
    memcpy(g->msg + old, "; ", 2);
    vsnprintf(g->msg + old + 2, (size_t)len + 1, fmt, ap2);
    va_end(ap2);
}

void sg_hint_suggest(sg_diags *d, const char *word)
{
    if (!word || d->n == 0 || d->last_dropped)
        return;
    sg_hint(d, "did you mean '%s'?", word);
    sg_diag *g = &d->items[d->n - 1];
    free(g->suggestion);
    g->suggestion = xstrdup(word);
}

/* ---- did you mean ------------------------------------------------------- */

#define EDIT_MAX 64

static int lower(int c)
{
    return c >= 'A' && c <= 'Z' ? c + 32 : c;
}

int sg_edit_distance(const char *a, const char *b)
{
    int n = (int)strlen(a), m = (int)strlen(b);
    if (n > EDIT_MAX || m > EDIT_MAX)
        return EDIT_MAX;
    /* three rows of the optimal-string-alignment table */
    int rows[3][EDIT_MAX + 1];
    int *pp = rows[0], *prev = rows[1], *cur = rows[2];
    for (int j = 0; j <= m; j++)
        prev[j] = j;
    for (int i = 1; i <= n; i++) {
        cur[0] = i;
        for (int j = 1; j <= m; j++) {
            int cost = lower(a[i - 1]) != lower(b[j - 1]);
            int v = prev[j - 1] + cost;
            if (prev[j] + 1 < v)
                v = prev[j] + 1;
            if (cur[j - 1] + 1 < v)
                v = cur[j - 1] + 1;
            if (i > 1 && j > 1 && lower(a[i - 1]) == lower(b[j - 2]) &&
                lower(a[i - 2]) == lower(b[j - 1]) && pp[j - 2] + 1 < v)
                v = pp[j - 2] + 1;
            cur[j] = v;
        }
        int *t = pp;
        pp = prev;
        prev = cur;
        cur = t;
    }
    return prev[m];
}

void sg_suggest_init(sg_suggest *s, const char *word)
{
    s->word = word;
    s->best = NULL;
    s->dist = EDIT_MAX + 1;
}

static int limit_for(const char *word)
{
    int len = (int)strlen(word);
    /* none for 1 or 2 letters ('c' is as near 'a' as 'b'), 1 up to 4,
     * 2 up to 7, ... */
    return len < 3 ? 0 : len < 5 ? 1 : (len + 1) / 3;
}

/* One name the other starts with ("output" and "out"), both 3 letters or
 * more: near enough, but behind any name within the limit. */
static bool prefix_of(const char *a, const char *b)
{
    size_t na = strlen(a), nb = strlen(b), n = na < nb ? na : nb;
    if (n < 3)
        return false;
    for (size_t i = 0; i < n; i++)
        if (lower(a[i]) != lower(b[i]))
            return false;
    return true;
}

void sg_suggest_offer(sg_suggest *s, const char *name)
{
    if (!name || !s->word || !strcmp(name, s->word))
        return;
    int dist = sg_edit_distance(s->word, name);
    int limit = limit_for(s->word);
    if (dist > limit && prefix_of(s->word, name))
        dist = limit;
    if (dist < s->dist) {
        s->dist = dist;
        s->best = name;
    }
}

const char *sg_suggest_best(const sg_suggest *s)
{
    if (!s->best)
        return NULL;
    return s->dist <= limit_for(s->word) ? s->best : NULL;
}

/* The line, shortened to a window around the caret, with non-printable
 * bytes shown as '?', then the caret line. */
static void print_excerpt(FILE *out, int lineno, const char *line, int col)
{
    int n = (int)strlen(line);
    int c = col > 0 ? col - 1 : 0;
    if (c > n)
        c = n;
    int from = 0, to = n;
    if (n > EXCERPT_MAX) {
        from = c - EXCERPT_MAX / 2;
        if (from < 0)
            from = 0;
        to = from + EXCERPT_MAX;
        if (to > n)
            to = n;
    }
    fprintf(out, "%5d | %s", lineno, from ? "..." : "");
    for (int i = from; i < to; i++) {
        unsigned char ch = (unsigned char)line[i];
        fputc(ch == '\t' || (ch >= 32 && ch < 127) ? ch : '?', out);
    }
    fprintf(out, "%s\n      | %s", to < n ? "..." : "", from ? "   " : "");
    for (int i = from; i < c; i++)
        fputc(line[i] == '\t' ? '\t' : ' ', out);
    fputs("^\n", out);
}

static const char *const names[SG_E_COUNT] = {
#define X(id, fmt) #id,
    SG_ERRORS(X)
#undef X
};

const char *sg_error_name(sg_error_id id)
{
    return (unsigned)id < SG_E_COUNT ? names[id] : "?";
}

/* A JSON string: quotes, backslashes and control characters escaped. */
static void json_string(FILE *out, const char *s)
{
    if (!s) {
        fputs("null", out);
        return;
    }
    fputc('"', out);
    for (const unsigned char *p = (const unsigned char *)s; *p; p++) {
        if (*p == '"' || *p == '\\')
            fprintf(out, "\\%c", *p);
        else if (*p == '\n')
            fputs("\\n", out);
        else if (*p < 0x20)
            fprintf(out, "\\u%04x", *p);
        else
            fputc(*p, out);
    }
    fputc('"', out);
}

void sg_diags_print_json(const sg_diags *d, FILE *out)
{
    sg_diags_print_json_from(d, 0, out);
    if (d->ndropped)
        fprintf(out, "{\"dropped\": %d}\n", d->ndropped);
}

void sg_diags_print_json_from(const sg_diags *d, int from, FILE *out)
{
    static const char *const sev[] = { "error", "warning", "note" };
    for (int i = from < 0 ? 0 : from; i < d->n; i++) {
        const sg_diag *g = &d->items[i];
        fputs("{\"file\": ", out);
        json_string(out, g->loc.file);
        fprintf(out, ", \"line\": %d, \"column\": %d, \"severity\": \"%s\", \"id\": ",
                g->loc.line > 0 ? g->loc.line : 0, g->loc.line > 0 ? g->loc.col : 0,
                sev[g->severity]);
        json_string(out, g->severity == SG_NOTE ? NULL : sg_error_name(g->id));
        fputs(", \"message\": ", out);
        json_string(out, g->msg);
        if (g->suggestion) {
            fputs(", \"suggestion\": ", out);
            json_string(out, g->suggestion);
        }
        fputs("}\n", out);
    }
}

void sg_diags_print(const sg_diags *d, FILE *out)
{
    sg_diags_print_from(d, 0, out);
    if (d->ndropped)
        fprintf(out, "splatc: note: %d more diagnostic%s not shown\n",
                d->ndropped, d->ndropped == 1 ? "" : "s");
}

void sg_diags_print_from(const sg_diags *d, int from, FILE *out)
{
    static const char *const sev[] = { "error", "warning", "note" };
    for (int i = from < 0 ? 0 : from; i < d->n; i++) {
        const sg_diag *g = &d->items[i];
        if (g->loc.file && g->loc.line > 0)
            fprintf(out, "%s:%d:%d: ", g->loc.file, g->loc.line, g->loc.col);
        else if (g->loc.file)
            fprintf(out, "%s: ", g->loc.file);
        else
            fputs("splatc: ", out);
        fprintf(out, "%s: %s\n", sev[g->severity], g->msg);
        if (g->src_line)
            print_excerpt(out, g->loc.line, g->src_line, g->loc.col);
    }
}
