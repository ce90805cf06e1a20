/* args.c — command-line options declared once (args.h): one table of
 * rows parses argv, prints --help and prints README.md's option list. */
#include "args.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

enum { WIDTH = 79 };   /* the longest line --help and the lists print */

static void set_bool(void *opts, size_t off) { *(bool *)((char *)opts + off) = true; }

static bool takes_value(const splat_arg *a)
{
    return a->kind != SPLAT_ARG_FLAG && a->kind != SPLAT_ARG_SECTION;
}

static bool row_active(const splat_args_desc *d, const splat_arg *a)
{
    return a->kind != SPLAT_ARG_SECTION && (!a->only || !d->command || (a->only & d->command));
}

/* ---- printing ------------------------------------------------------------ */

const char *splat_arg_value_name(const splat_arg *a)
{
    if (!takes_value(a))
        return NULL;
    return a->arg ? a->arg : a->kind == SPLAT_ARG_ENUM ? a->choices : "VALUE";
}

/* "NAME ARG", "NAME[=ARG]" or "NAME" into buf. */
static void row_head(const splat_arg *a, char *buf, size_t n)
{
    const char *v = splat_arg_value_name(a);
    if (!v)
        snprintf(buf, n, "%s", a->name);
    else if (a->optional)
        snprintf(buf, n, "%s[=%s]", a->name, v);
    else
        snprintf(buf, n, "%s %s", a->name, v);
}

/* `text` from column `col` (the cursor is at `at`), words wrapped at `width`;
 * '\n' in the text breaks the line. */
static void wrap(FILE *f, const char *text, int at, int col, int width)
{
    const char *p = text;
    while (*p) {
        size_t w = strcspn(p, " \n");
        if (at > col && at + 1 + (int)w > width) {
            fprintf(f, "\n%*s", col, "");
            at = col;
        } else if (at > col) {
            fputc(' ', f);
            at++;
        } else if (at < col) {
            fprintf(f, "%*s", col - at, "");
            at = col;
        }
        fwrite(p, 1, w, f);
        at += (int)w;
        p += w;
        if (*p == '\n') {
            fprintf(f, "\n%*s", col, "");
            at = col;
        }
        while (*p == ' ' || *p == '\n')
            p++;
    }
    fputc('\n', f);
}

/* Sections at column `base`, options two further in, their help at the
 * desc's column (plus `base`). */
static void print_rows(const splat_args_desc *d, FILE *f, int base)
{
    for (int i = 0; i < d->nargs; i++) {
        const splat_arg *a = &d->args[i];
        if (a->kind == SPLAT_ARG_SECTION) {   /* a blank line before all but the first */
            fprintf(f, "%s%*s%s\n", i ? "\n" : "", base, "", a->help);
            continue;
        }
        if (!row_active(d, a))
            continue;
        char head[128], help[1024];
        row_head(a, head, sizeof head);
        size_t n = 0;
        help[0] = '\0';
        for (int b = 0; a->only && d->command_names && b < 32 && n < sizeof help; b++)
            if (a->only & (1u << b))
                n += (size_t)snprintf(help + n, sizeof help - n, "%s%s", n ? ", " : "(",
                                      d->command_names[b]);
        snprintf(help + n, sizeof help - n, "%s%s", n ? ") " : "", a->help);
        splat_args_item(f, head, help, base, d->column ? d->column : 26);
    }
}

void splat_args_item(FILE *f, const char *head, const char *help, int base, int column)
{
    int col = column + base;
    int at = fprintf(f, "%*s%s", base + 2, "", head);
    if (at + 2 > col) {
        fputc('\n', f);
        at = 0;
    }
    wrap(f, help, at, col, WIDTH + base);
}

void splat_args_help(const splat_args_desc *d, FILE *f)
{
    if (d->usage)
        fputs(d->usage, f);
    print_rows(d, f, 0);
    if (d->epilog)
        fputs(d->epilog, f);
}

/* In README.md the list is a code block: every line four spaces in. */
void splat_args_markdown(const splat_args_desc *d, FILE *f)
{
    print_rows(d, f, 4);
}

/* ---- parsing ------------------------------------------------------------- */

/* Edit distance of two short strings (the unknown option's suggestion). */
static int distance(const char *a, const char *b)
{
    size_t n = strlen(b);
    if (n > 63)
        return 99;
    int row[64];
    for (size_t j = 0; j <= n; j++)
        row[j] = (int)j;
    for (size_t i = 1; a[i - 1]; i++) {
        int diag = row[0];
        row[0] = (int)i;
        for (size_t j = 1; j <= n; j++) {
            int up = row[j];
            int best = diag + (a[i - 1] != b[j - 1]);
            if (up + 1 < best)
                best = up + 1;
            if (row[j - 1] + 1 < best)
                best = row[j - 1] + 1;
            row[j] = best;
            diag = up;
        }
    }
    return row[n];
}

static int unknown(const splat_args_desc *d, const char *word)
{
    const char *best = NULL;
    int bd = 3;   /* at most two edits away */
    size_t wn = strcspn(word, "=");
    char w[64];
    snprintf(w, sizeof w, "%.*s", (int)(wn < 63 ? wn : 63), word);
    for (int i = 0; i < d->nargs; i++) {
        if (!row_active(d, &d->args[i]))
            continue;
        int k = distance(w, d->args[i].name);
        if (k < bd)
            bd = k, best = d->args[i].name;
    }
    if (best)
        fprintf(stderr, "%s: unknown option '%s'; did you mean '%s'? (see --help)\n", d->prog,
                word, best);
    else
        fprintf(stderr, "%s: unknown option '%s' (see --help)\n", d->prog, word);
    return SPLAT_ARGS_USAGE;
}

/* "a|b|c" as "a, b or c". */
static void choices_text(const char *choices, char *buf, size_t n)
{
    size_t len = 0;
    buf[0] = '\0';
    for (const char *p = choices; *p && len + 1 < n;) {
        size_t w = strcspn(p, "|");
        const char *sep = !p[w] ? "" : strchr(p + w + 1, '|') ? ", " : " or ";
        len += (size_t)snprintf(buf + len, n - len, "%.*s%s", (int)w, p, sep);
        p += w + (p[w] == '|');
    }
}

static int refuse(const splat_args_desc *d, const splat_arg *a, const char *value,
                  const splat_arg_why *why)
{
    if (why && why->text[0]) {
        fprintf(stderr, "%s: %s\n", d->prog, why->text);
        return SPLAT_ARGS_USAGE;
    }
    char buf[256];
    const char *exp = a->expects;
    if (!exp && a->kind == SPLAT_ARG_ENUM) {
        choices_text(a->choices, buf, sizeof buf);
        exp = buf;
    } else if (!exp && (a->kind == SPLAT_ARG_INT || a->kind == SPLAT_ARG_FLOAT) &&
               (a->min || a->max)) {
        snprintf(buf, sizeof buf, "%s %.15g..%.15g", a->kind == SPLAT_ARG_INT ? "a whole number"
                 : "a number", a->min, a->max);
        exp = buf;
    } else if (!exp) {
        exp = a->kind == SPLAT_ARG_INT ? "a whole number" : a->kind == SPLAT_ARG_FLOAT
              ? "a number" : splat_arg_value_name(a);
    }
    fprintf(stderr, "%s: %s expects %s, found '%s'\n", d->prog, a->name, exp, value);
    return SPLAT_ARGS_USAGE;
}

static bool in_range(const splat_arg *a, double x)
{
    return isfinite(x) && (!(a->min || a->max) || (x >= a->min && x <= a->max));
}

static bool parse_enum(const splat_arg *a, const char *value, int *out)
{
    const char *p = a->choices;
    for (int i = 0; *p; i++) {
        size_t w = strcspn(p, "|");
        if (strlen(value) == w && !strncmp(p, value, w)) {
            *out = a->values ? a->values[i] : i;
            return true;
        }
        p += w + (p[w] == '|');
    }
    return false;
}

/* The row's value into its field; SPLAT_ARGS_OK or the printed error. */
static int store(const splat_args_desc *d, const splat_arg *a, const char *value, void *opts)
{
    void *field = (char *)opts + a->field;
    splat_arg_why why = { { 0 } };
    char *end;
    switch (a->kind) {
    case SPLAT_ARG_FLAG:
        set_bool(opts, a->field);
        if (a->parse && !a->parse(NULL, opts, &why))
            return refuse(d, a, "", &why);
        break;
    case SPLAT_ARG_INT: {
        long n = strtol(value, &end, 10);
        if (!*value || *end || !in_range(a, (double)n) || n < -2147483647L || n > 2147483647L)
            return refuse(d, a, value, NULL);
        *(int *)field = (int)n;
        break;
    }
    case SPLAT_ARG_FLOAT: {
        double x = strtod(value, &end);
        if (!*value || *end || !in_range(a, x))
            return refuse(d, a, value, NULL);
        *(double *)field = x;
        break;
    }
    case SPLAT_ARG_STRING:
        if (d->once && *(const char **)field) {
            fprintf(stderr, "%s: %s given twice\n", d->prog, a->name);
            return SPLAT_ARGS_USAGE;
        }
        *(const char **)field = value;
        break;
    case SPLAT_ARG_ENUM:
        if (!parse_enum(a, value, (int *)field))
            return refuse(d, a, value, NULL);
        break;
    case SPLAT_ARG_LIST: {
        int *count = (int *)((char *)opts + a->count);
        if (*count >= a->capacity) {
            fprintf(stderr, "%s: more than %d %s options\n", d->prog, a->capacity, a->name);
            return SPLAT_ARGS_USAGE;
        }
        ((const char **)field)[(*count)++] = value;
        break;
    }
    case SPLAT_ARG_CUSTOM:
        if (!a->parse(value, opts, &why))
            return refuse(d, a, value, &why);
        break;
    case SPLAT_ARG_SECTION:
        break;
    }
    if (a->given)
        set_bool(opts, a->given - 1);
    return SPLAT_ARGS_OK;
}

/* The row `word` names, and where its value is: after '=' (--name=V), glued
 * to a short name (-j4), or NULL (the next word).  NULL: no such row. */
static const splat_arg *find(const splat_args_desc *d, const char *word, const char **glued)
{
    *glued = NULL;
    for (int i = 0; i < d->nargs; i++) {
        const splat_arg *a = &d->args[i];
        if (!row_active(d, a))
            continue;
        size_t n = strlen(a->name);
        if (strncmp(word, a->name, n))
            continue;
        if (!word[n])
            return a;
        if (word[n] == '=' && a->name[1] == '-') {
            *glued = word + n + 1;
            return a;
        }
        if (n == 2 && takes_value(a)) {   /* -jN, -Ifolder */
            *glued = word + n;
            return a;
        }
    }
    return NULL;
}

static int option(const splat_args_desc *d, int argc, char **argv, int *i, void *opts)
{
    const char *word = argv[*i], *value;
    const splat_arg *a = find(d, word, &value);
    if (!a)
        return unknown(d, word);
    if (!takes_value(a)) {
        if (value) {
            fprintf(stderr, "%s: %s takes no value, found '%s'\n", d->prog, a->name, word);
            return SPLAT_ARGS_USAGE;
        }
    } else if (!value && a->optional) {
        value = a->optional;
    } else if (!value) {
        if (*i + 1 >= argc) {
            fprintf(stderr, "%s: %s needs a value (%s)\n", d->prog, a->name,
                    splat_arg_value_name(a));
            return SPLAT_ARGS_USAGE;
        }
        value = argv[++*i];
    }
    return store(d, a, value, opts);
}

int splat_args_parse(const splat_args_desc *d, int argc, char **argv, int first, void *opts)
{
    bool options = true;
    for (int i = first; i < argc; i++) {
        const char *w = argv[i];
        if (options && (!strcmp(w, "--help") || !strcmp(w, "-h"))) {
            splat_args_help(d, stdout);
            return SPLAT_ARGS_HELP;
        }
        if (options && !strcmp(w, "--help-markdown")) {
            splat_args_markdown(d, stdout);
            return SPLAT_ARGS_HELP;
        }
        if (options && !strcmp(w, "--")) {
            options = false;
            continue;
        }
        if (options && w[0] == '-' && w[1]) {
            int rc = option(d, argc, argv, &i, opts);
            if (rc)
                return rc;
            continue;
        }
        splat_arg_why why = { { 0 } };
        if (!d->positional) {
            fprintf(stderr, "%s: unexpected argument '%s' (see --help)\n", d->prog, w);
            return SPLAT_ARGS_USAGE;
        }
        if (!d->positional(w, opts, &why)) {
            fprintf(stderr, "%s: %s\n", d->prog,
                    why.text[0] ? why.text : "unexpected argument (see --help)");
            return SPLAT_ARGS_USAGE;
        }
    }
    return SPLAT_ARGS_OK;
}
