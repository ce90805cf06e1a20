/* test_args.c — options declared once (compiler/args.h): every kind of row
 * parses into its field, every refusal names the option and says what it
 * expects (exit status 2), and --help / --help-markdown print the rows
 * wrapped within 79 columns (the markdown as a code block). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "args.h"

typedef struct topts {
    bool flag, given, checked;
    int count, mode, nlist;
    double scale;
    const char *name, *list[2], *files[4];
    int nfiles;
    char pair[16];
} topts;

static bool parse_pair(const char *v, void *o, splat_arg_why *why)
{
    if (!strchr(v, ':')) {
        snprintf(why->text, sizeof why->text, "--pair wants A:B, and '%s' has no colon", v);
        return false;
    }
    snprintf(((topts *)o)->pair, sizeof ((topts *)o)->pair, "%s", v);
    return true;
}

static bool on_flag(const char *v, void *o, splat_arg_why *why)
{
    (void)why;
    ((topts *)o)->checked = v == NULL;
    return true;
}

static bool add_file(const char *w, void *o_, splat_arg_why *why)
{
    topts *o = o_;
    if (o->nfiles == 4) {
        snprintf(why->text, sizeof why->text, "too many files ('%s')", w);
        return false;
    }
    o->files[o->nfiles++] = w;
    return true;
}

static const int mode_values[] = { 10, 20, 30 };

#define F(f) offsetof(topts, f)
static const splat_arg rows[] = {
    { NULL, SPLAT_ARG_SECTION, .help = "General:" },
    { "--flag", SPLAT_ARG_FLAG, NULL, "a flag", F(flag), .parse = on_flag },
    { "-j", SPLAT_ARG_INT, "N", "a count", F(count), .min = 1, .max = 64 },
    { "--scale", SPLAT_ARG_FLOAT, "S", "a scale with a long help text that has to be wrapped "
      "over several lines because it goes on and on about what the scale means", F(scale),
      .min = 0, .max = 2, .given = SPLAT_ARG_GIVEN(topts, given) },
    { "--name", SPLAT_ARG_STRING, "NAME", "a name", F(name) },
    { "--mode", SPLAT_ARG_ENUM, NULL, "a mode", F(mode), .choices = "low|mid|high",
      .values = mode_values },
    { "--item", SPLAT_ARG_LIST, "X", "an item (repeatable)", F(list), .count = F(nlist),
      .capacity = 2 },
    { NULL, SPLAT_ARG_SECTION, .help = "Other:" },
    { "--pair", SPLAT_ARG_CUSTOM, "A:B", "a pair", .parse = parse_pair },
    { "--level", SPLAT_ARG_INT, "N", "a level", F(count), .optional = "7", .min = 1,
      .max = 9 },
    { "--a-very-long-option-name", SPLAT_ARG_STRING, "VALUE", "its help on the next line",
      F(name), .only = 2 },
};
#undef F

static splat_args_desc desc(void)
{
    return (splat_args_desc){ .prog = "prog", .usage = "usage: prog [options] FILE...\n",
                              .args = rows, .nargs = (int)(sizeof rows / sizeof rows[0]),
                              .positional = add_file, .once = true, .command = 1 };
}

static char err[1024];

/* Parse the words (NULL-terminated) into *o; stderr into err. */
static int parse(topts *o, ...)
{
    char *argv[32] = { "prog" };
    int argc = 1;
    va_list ap;
    va_start(ap, o);
    for (char *w; (w = va_arg(ap, char *)) != NULL;)
        argv[argc++] = w;
    va_end(ap);
    memset(o, 0, sizeof *o);
    fflush(stderr);
    FILE *tmp = tmpfile();
    assert_non_null(tmp);
    int saved = dup(2);
    dup2(fileno(tmp), 2);
    splat_args_desc d = desc();
    int rc = splat_args_parse(&d, argc, argv, 1, o);
    fflush(stderr);
    dup2(saved, 2);
    close(saved);
    rewind(tmp);
    size_t n = fread(err, 1, sizeof err - 1, tmp);
    err[n] = '\0';
    fclose(tmp);
    return rc;
}

static void test_kinds(void **state)
{
    (void)state;
    topts o;
    assert_int_equal(parse(&o, "a.sg", "--flag", "-j", "8", "--scale=0.5", "--name", "x",
                           "--mode", "high", "--item", "p", "--item", "q", "--pair", "1:2",
                           "b.sg", NULL), 0);
    assert_string_equal(err, "");
    assert_true(o.flag && o.checked && o.given);
    assert_int_equal(o.count, 8);
    assert_true(o.scale == 0.5);
    assert_string_equal(o.name, "x");
    assert_int_equal(o.mode, 30);
    assert_int_equal(o.nlist, 2);
    assert_string_equal(o.list[1], "q");
    assert_string_equal(o.pair, "1:2");
    assert_int_equal(o.nfiles, 2);
    assert_string_equal(o.files[1], "b.sg");
    /* a short option's value glued on; an optional value; "--" ends options */
    assert_int_equal(parse(&o, "-j12", NULL), 0);
    assert_int_equal(o.count, 12);
    assert_int_equal(parse(&o, "--level", "f.sg", NULL), 0);
    assert_int_equal(o.count, 7);
    assert_int_equal(o.nfiles, 1);
    assert_int_equal(parse(&o, "--level=3", NULL), 0);
    assert_int_equal(o.count, 3);
    assert_int_equal(parse(&o, "--", "--flag", "-", NULL), 0);
    assert_false(o.flag);
    assert_int_equal(o.nfiles, 2);
    assert_string_equal(o.files[0], "--flag");
}

static void refused(topts *o, const char *want, int rc)
{
    assert_int_equal(rc, SPLAT_ARGS_USAGE);
    if (!strstr(err, want))
        fail_msg("stderr '%s' lacks '%s'", err, want);
    (void)o;
}

static void test_errors(void **state)
{
    (void)state;
    topts o;
    refused(&o, "prog: unknown option '--flga'; did you mean '--flag'? (see --help)",
            parse(&o, "--flga", NULL));
    refused(&o, "prog: unknown option '--zzzzzz' (see --help)", parse(&o, "--zzzzzz", NULL));
    refused(&o, "prog: --name needs a value (NAME)", parse(&o, "--name", NULL));
    refused(&o, "prog: -j expects a whole number 1..64, found '65'", parse(&o, "-j", "65", NULL));
    refused(&o, "prog: -j expects a whole number 1..64, found '3x'", parse(&o, "-j3x", NULL));
    refused(&o, "prog: --scale expects a number 0..2, found 'nan'",
            parse(&o, "--scale", "nan", NULL));
    refused(&o, "prog: --mode expects low, mid or high, found 'max'",
            parse(&o, "--mode", "max", NULL));
    refused(&o, "prog: more than 2 --item options",
            parse(&o, "--item", "a", "--item", "b", "--item", "c", NULL));
    refused(&o, "prog: --flag takes no value, found '--flag=1'", parse(&o, "--flag=1", NULL));
    refused(&o, "prog: --name given twice", parse(&o, "--name", "a", "--name", "b", NULL));
    refused(&o, "prog: --pair wants A:B, and '12' has no colon", parse(&o, "--pair", "12", NULL));
    refused(&o, "prog: too many files ('e')", parse(&o, "a", "b", "c", "d", "e", NULL));
    /* a row of another command is unknown here */
    refused(&o, "unknown option '--a-very-long-option-name'",
            parse(&o, "--a-very-long-option-name", "v", NULL));
}

static char *print(bool markdown)
{
    char *text = NULL;
    size_t n = 0;
    FILE *f = open_memstream(&text, &n);
    assert_non_null(f);
    splat_args_desc d = desc();
    d.command = 0;   /* all rows */
    if (markdown)
        splat_args_markdown(&d, f);
    else
        splat_args_help(&d, f);
    fclose(f);
    return text;
}

static void test_help(void **state)
{
    (void)state;
    char *help = print(false), *md = print(true);
    assert_non_null(strstr(help, "usage: prog [options] FILE...\nGeneral:\n  --flag"));
    assert_non_null(strstr(help, "  --mode low|mid|high     a mode\n"));
    assert_non_null(strstr(help, "  --level[=N]             a level\n"));
    assert_non_null(strstr(help, "\n\nOther:\n"));
    /* a head too long for the column: its help starts on the next line */
    assert_non_null(strstr(help, "  --a-very-long-option-name VALUE\n"
                                 "                          its help on the next line\n"));
    int lines = 0;
    for (char *l = help; *l; lines++) {
        size_t n = strcspn(l, "\n");
        if (n > 79)
            fail_msg("a help line of %zu columns: %.*s", n, (int)n, l);
        l += n + (l[n] == '\n');
    }
    assert_true(lines > 12);
    assert_non_null(strstr(help, "over several lines"));
    /* the markdown: the rows alone, each line a code block's (4 spaces in) */
    assert_null(strstr(md, "usage"));
    for (char *l = md; *l;) {
        size_t n = strcspn(l, "\n");
        if (n && strncmp(l, "    ", 4))
            fail_msg("a markdown line outside the code block: %.*s", (int)n, l);
        l += n + (l[n] == '\n');
    }
    assert_non_null(strstr(md, "      --flag                  a flag\n"));
    free(help);
    free(md);
}

static void test_help_option(void **state)
{
    (void)state;
    topts o;
    fflush(stdout);
    FILE *tmp = tmpfile();
    int saved = dup(1);
    dup2(fileno(tmp), 1);
    int rc = parse(&o, "--flag", "--help", NULL);
    fflush(stdout);
    dup2(saved, 1);
    close(saved);
    fclose(tmp);
    assert_int_equal(rc, SPLAT_ARGS_HELP);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_kinds),
        cmocka_unit_test(test_errors),
        cmocka_unit_test(test_help),
        cmocka_unit_test(test_help_option),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
