/* sg_query.c — what tools ask of a loaded program beyond compiling it:
 * the comment that documents a declaration (`splatc doc`'s node tables,
 * `splatc lsp`'s hover and completion), and the checks `splatc check` runs
 * beyond loading (sg_check).
 *
 * A declaration's comment is the `#` comment after the last token of its
 * line, or else the run of `#` lines right above it:
 *
 *     # ramp: 0 for x <= lo, 1 for x >= hi       <- shader ramp's comment
 *     shader ramp {
 *         in float lo = 0.0   # where it leaves 0  <- port lo's comment
 */
#include "sg_internal.h"

#include <string.h>

/* Start of 1-based line `line` of f's text, or NULL past the end. */
static const char *line_start_of(const sg_file *f, int line)
{
    const char *s = f->text, *end = f->text + f->len;
    for (int l = 1; l < line; l++) {
        const char *nl = memchr(s, '\n', (size_t)(end - s));
        if (!nl)
            return NULL;
        s = nl + 1;
    }
    return s;
}

/* Append the comment text of the line at `s` (at its '#') to buf. */
static size_t append(char *buf, size_t n, size_t o, const char *s, const char *end)
{
    s++;                                    /* the '#' */
    while (s < end && (*s == ' ' || *s == '\t'))
        s++;
    const char *e = s < end ? memchr(s, '\n', (size_t)(end - s)) : NULL;
    if (!e)
        e = end;
    while (e > s && (e[-1] == '\r' || e[-1] == ' ' || e[-1] == '\t'))
        e--;
    if (o < n)
        o += (size_t)snprintf(buf + o, n - o, "%s%.*s", o ? " " : "", (int)(e - s), s);
    return o < n ? o : n - 1;
}

/* The first non-blank of the line at `s`, if it is a '#'. */
static const char *comment_line(const char *s, const char *end)
{
    while (s < end && (*s == ' ' || *s == '\t'))
        s++;
    return s < end && *s == '#' ? s : NULL;
}

size_t sg_doc_comment(const sg_file *f, int line, bool trailing, char *buf, size_t n)
{
    if (!n)
        return 0;
    buf[0] = 0;
    const char *end = f->text + f->len;
    if (line < 1 || !f->text)
        return 0;
    if (trailing) {
        /* the last token of the line, then a '#' */
        const sg_token *last = NULL;
        for (int i = 0; i < f->ntoks && f->toks[i].line <= line; i++)
            if (f->toks[i].line == line && f->toks[i].kind != SG_TK_EOF)
                last = &f->toks[i];
        if (last) {
            const char *s = last->start + last->len;
            while (s < end && (*s == ' ' || *s == '\t'))
                s++;
            if (s < end && *s == '#')
                return append(buf, n, 0, s, end);
        }
    }
    /* the `#` lines right above: walk back from the line's start */
    const char *at = line_start_of(f, line);
    if (!at)
        return 0;
    const char *first = at;
    while (first > f->text) {
        const char *prev = first - 1;           /* the '\n' ending the line above */
        while (prev > f->text && prev[-1] != '\n')
            prev--;
        if (!comment_line(prev, end))
            break;
        first = prev;
    }
    size_t o = 0;
    for (const char *s = first; s < at;) {
        o = append(buf, n, o, comment_line(s, end), end);
        const char *nl = memchr(s, '\n', (size_t)(end - s));
        s = nl ? nl + 1 : end;
    }
    return o;
}

void sg_check(sg_program *p, sg_diags *d)
{
    if (!p || p->load_errors)
        return;
    int errors = d->nerrors;
    sg_check_texture_files(p, d);   /* what `build` would read */
    if (d->nerrors == errors)
        sg_lint(p, NULL, d);        /* over every input's domain */
}

void sg_value_text(const sg_value *v, char *buf, size_t n)
{
    if (v->kind == SG_V_NUMBER)
        snprintf(buf, n, "%g", v->num[0]);
    else if (v->kind == SG_V_VEC) {
        size_t o = (size_t)snprintf(buf, n, "vec%d(", v->width);
        for (int i = 0; i < v->width && o < n; i++)
            o += (size_t)snprintf(buf + o, n - o, "%s%g", i ? ", " : "", v->num[i]);
        if (o < n)
            snprintf(buf + o, n - o, ")");
    } else if (v->kind == SG_V_STRING)
        snprintf(buf, n, "\"%s\"", v->str);
    else if (v->kind == SG_V_PATH) {
        size_t o = 0;
        buf[0] = 0;
        for (int i = 0; i < v->nparts && o < n; i++)
            o += (size_t)snprintf(buf + o, n - o, "%s%s", i ? "." : "", v->parts[i]);
    } else
        buf[0] = 0;
}
