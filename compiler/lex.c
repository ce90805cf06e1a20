/* lex.c — the .sg lexer: text -> tokens with line and column.
 *
 * Tokens: identifiers [A-Za-z_][A-Za-z0-9_]* (keywords are identifiers
 * the parser recognises by text, so `out` can also be a port name),
 * numbers (`1`, `-0.5`, `.5`, `1e6`, `2.5E-3`), strings ("…", one line,
 * escapes \" and \\), and { } ( ) [ ] , : = .  `#` starts a comment to
 * the end of the line.
 *
 * A number is lexed greedily over [0-9A-Za-z_.] (plus a sign after an
 * exponent) and then checked, so `1.2.3`, `0x`, `1e` and `2x` are one
 * BAD_LITERAL each rather than a confusing run of tokens.  A run of
 * unexpected bytes (binary garbage) is one BAD_CHAR.  Linear time. */
#include "sg_internal.h"
#include "util.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct lexer {
    sg_arena   *arena;
    sg_file    *f;
    sg_diags   *d;
    const char *s, *end;
    int         line;
    const char *line_start;
} lexer;

static sg_loc here(const lexer *l, const char *at)
{
    return (sg_loc){ l->f->path, l->line, (int)(at - l->line_start) + 1 };
}

static sg_token *emit(lexer *l, sg_tok_kind k, const char *start, int len)
{
    sg_token *t = SG_PUSH(l->arena, l->f->toks, l->f->ntoks, l->f->captoks);
    t->kind = k;
    t->start = start;
    t->len = len;
    t->line = l->line;
    t->col = (int)(start - l->line_start) + 1;
    return t;
}

static bool ident_start(int c) { return isalpha(c) || c == '_'; }
static bool ident_char(int c) { return isalnum(c) || c == '_'; }

/* Why `s` (n bytes) is not a number, or NULL if it is one. */
static const char *bad_number(const char *s, int n, double *val)
{
    int i = 0, digits = 0;
    if (i < n && s[i] == '-')
        i++;
    while (i < n && isdigit((unsigned char)s[i]))
        i++, digits++;
    if (i < n && s[i] == '.') {
        i++;
        while (i < n && isdigit((unsigned char)s[i]))
            i++, digits++;
    }
    if (!digits)
        return "no digits";
    if (i < n && (s[i] == 'e' || s[i] == 'E')) {
        i++;
        if (i < n && (s[i] == '+' || s[i] == '-'))
            i++;
        int ed = 0;
        while (i < n && isdigit((unsigned char)s[i]))
            i++, ed++;
        if (!ed)
            return "expected digits after the exponent";
    }
    if (i < n) {
        if (s[i] == '.')
            return "more than one decimal point";
        if (s[i] == 'x' || s[i] == 'X')
            return "only decimal numbers are allowed";
        return "unexpected characters after the number";
    }
    char buf[64];
    const char *text = s;
    char *heap = NULL;
    if (n < (int)sizeof buf) {
        memcpy(buf, s, (size_t)n);
        buf[n] = 0;
        text = buf;
    } else {
        heap = xmalloc((size_t)n + 1);
        memcpy(heap, s, (size_t)n);
        heap[n] = 0;
        text = heap;
    }
    errno = 0;
    *val = strtod(text, NULL);
    free(heap);
    if (!isfinite(*val))
        return "out of range";
    return NULL;
}

static void lex_number(lexer *l)
{
    const char *start = l->s;
    const char *p = l->s;
    if (*p == '-')
        p++;
    while (p < l->end) {
        char c = *p;
        if (ident_char((unsigned char)c) || c == '.') {
            p++;
        } else if ((c == '+' || c == '-') && (p[-1] == 'e' || p[-1] == 'E')) {
            p++;
        } else {
            break;
        }
    }
    int n = (int)(p - start);
    sg_token *t = emit(l, SG_TK_NUMBER, start, n);
    const char *why = bad_number(start, n, &t->num);
    if (why) {
        t->num = 0;
        /* show at most 40 bytes of a runaway literal */
        char shown[48];
        int m = n > 40 ? 40 : n;
        memcpy(shown, start, (size_t)m);
        strcpy(shown + m, n > 40 ? "..." : "");
        sg_error(l->d, here(l, start), SG_E_BAD_LITERAL, shown, why);
    }
    l->s = p;
}

static void lex_string(lexer *l)
{
    const char *start = l->s++;
    /* The unescaped text is never longer than the source text. */
    const char *p = l->s;
    while (p < l->end && *p != '"' && *p != '\n') {
        if (*p == '\\' && p + 1 < l->end && p[1] != '\n')
            p++;
        p++;
    }
    bool closed = p < l->end && *p == '"';
    if (!closed)   /* report, then read it as closed at the end of the line */
        sg_error(l->d, here(l, start), SG_E_UNTERMINATED, "string", l->line);
    sg_token *t = emit(l, SG_TK_STRING, start, (int)(p + closed - start));
    char *out = sg_alloc(l->arena, (size_t)(p - l->s) + 1);
    int o = 0;
    for (const char *q = l->s; q < p; q++) {
        if (*q == '\\' && q + 1 < p)
            q++;
        out[o++] = *q;
    }
    out[o] = 0;
    t->str = out;
    l->s = p + closed;      /* an unclosed string leaves the newline next */
}

static bool starts_token(const char *p)
{
    unsigned char c = (unsigned char)*p;
    return ident_start(c) || isdigit(c) || isspace(c) ||
           (c && strchr("{}()[],:=.\"#-", c));
}

void sg_lex(sg_arena *a, sg_file *f, sg_diags *d)
{
    lexer l = { a, f, d, f->text, f->text + f->len, 1, f->text };
    while (l.s < l.end) {
        const char *s = l.s;
        unsigned char c = (unsigned char)*s;
        if (c == '\n') {
            l.s++;
            l.line++;
            l.line_start = l.s;
        } else if (c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v') {
            l.s++;
        } else if (c == '#') {
            while (l.s < l.end && *l.s != '\n')
                l.s++;
        } else if (ident_start(c)) {
            const char *p = s;
            while (p < l.end && ident_char((unsigned char)*p))
                p++;
            emit(&l, SG_TK_IDENT, s, (int)(p - s));
            l.s = p;
        } else if (isdigit(c) ||
                   (c == '.' && s + 1 < l.end && isdigit((unsigned char)s[1]) &&
                    !(f->ntoks && f->toks[f->ntoks - 1].kind == SG_TK_IDENT &&
                      f->toks[f->ntoks - 1].start + f->toks[f->ntoks - 1].len == s)) ||
                   (c == '-' && s + 1 < l.end &&
                    (isdigit((unsigned char)s[1]) ||
                     (s[1] == '.' && s + 2 < l.end && isdigit((unsigned char)s[2]))))) {
            lex_number(&l);
        } else if (c == '"') {
            lex_string(&l);
        } else {
            static const char punct[] = "{}()[],:=.";
            static const sg_tok_kind kinds[] = {
                SG_TK_LBRACE, SG_TK_RBRACE, SG_TK_LPAREN, SG_TK_RPAREN,
                SG_TK_LBRACK, SG_TK_RBRACK, SG_TK_COMMA, SG_TK_COLON,
                SG_TK_EQ, SG_TK_DOT };
            const char *pc = c ? strchr(punct, c) : NULL;
            if (pc) {
                emit(&l, kinds[pc - punct], s, 1);
                l.s++;
                continue;
            }
            char what[32];
            if (c >= 32 && c < 127)
                snprintf(what, sizeof what, "'%c'", c);
            else
                snprintf(what, sizeof what, "byte 0x%02x", c);
            sg_error(d, here(&l, s), SG_E_BAD_CHAR, what);
            /* one error for a run of garbage on this line */
            l.s++;
            while (l.s < l.end && *l.s != '\n' && !starts_token(l.s))
                l.s++;
        }
    }
    emit(&l, SG_TK_EOF, l.s, 0);
}

const char *sg_tok_describe(const sg_token *t, char *buf, size_t n)
{
    switch (t->kind) {
    case SG_TK_EOF:
        snprintf(buf, n, "end of file");
        break;
    case SG_TK_NUMBER:
        snprintf(buf, n, "number %.*s", t->len > 40 ? 40 : t->len, t->start);
        break;
    case SG_TK_STRING:
        snprintf(buf, n, "string %.*s%s", t->len > 40 ? 40 : t->len, t->start,
                 t->len > 40 ? "...\"" : "");
        break;
    default:
        snprintf(buf, n, "'%.*s'", t->len > 40 ? 40 : t->len, t->start);
        break;
    }
    return buf;
}
