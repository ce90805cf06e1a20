/* args.h — command-line options declared once.
 *
 * A program declares its options as one table of splat_arg rows (sokol's
 * desc structs): the option's name, its argument as help shows it, its
 * help, the field it sets and how it reads the value.  The same table
 * drives parsing (splat_args_parse), --help (splat_args_help) and the
 * option lists in README.md (splat_args_markdown, checked by the test
 * docs.options), so the three cannot disagree.
 *
 *     typedef struct opts { bool stats; int frames; const char *out; } opts;
 *     static const splat_arg rows[] = {
 *         { "-o", SPLAT_ARG_STRING, "OUT.png", "write a PNG", offsetof(opts, out) },
 *         { "--frames", SPLAT_ARG_INT, "N", "render N frames", offsetof(opts, frames),
 *           .min = 1, .max = 1000000, .expects = "a positive count" },
 *         { "--stats", SPLAT_ARG_FLAG, NULL, "print timings", offsetof(opts, stats) },
 *     };
 *
 * Errors name the option and say what it expects and what was found
 * ("splatview: --frames expects a positive count, found 'x'"), and the
 * parse returns 2 (a usage error); it never exits (STYLE).  The values of
 * string options point into argv. */
#ifndef SPLAT_ARGS_H
#define SPLAT_ARGS_H

#include <stdbool.h>
#include <stddef.h>
#include <stdio.h>

typedef enum splat_arg_kind {
    SPLAT_ARG_FLAG,     /* bool = true; no value                               */
    SPLAT_ARG_INT,      /* int, a whole decimal number within [min, max]       */
    SPLAT_ARG_FLOAT,    /* double, finite, within [min, max]                   */
    SPLAT_ARG_STRING,   /* const char *, pointing into argv                    */
    SPLAT_ARG_ENUM,     /* int (or an int-sized enum): values[i] for the i-th
                           of choices "a|b|c"                                 */
    SPLAT_ARG_LIST,     /* const char *field[max] with an int count: repeatable */
    SPLAT_ARG_CUSTOM,   /* parse(value, opts, why): anything else              */
    SPLAT_ARG_SECTION,  /* no option: `help` is a heading in --help and lists  */
} splat_arg_kind;

/* The reason a custom parser gives when it refuses a value: a full
 * sentence after "PROG: " (it names the option itself), or empty for the
 * row's "OPTION expects EXPECTS, found 'VALUE'". */
typedef struct splat_arg_why {
    char text[256];
} splat_arg_why;

typedef struct splat_arg {
    const char    *name;     /* "--size", "-o" (a short one also takes "-oVALUE");
                                every long one also takes "--name=VALUE"       */
    splat_arg_kind kind;
    const char    *arg;      /* the value as help shows it ("WxH"); NULL: a flag,
                                or an enum's choices                             */
    const char    *help;     /* one paragraph, wrapped by the printers           */
    size_t         field;    /* offsetof the field it sets                        */
    size_t         given;    /* offsetof a bool set when given, plus 1; 0: none  */
    double         min, max; /* INT, FLOAT: the range (both 0: any value)        */
    const char    *choices;  /* ENUM: "forward|screen"                            */
    const int     *values;   /* ENUM: each choice's value; NULL: 0, 1, 2, ...     */
    size_t         count;    /* LIST: offsetof the int count                      */
    int            capacity; /* LIST: how many fit                                */
    const char    *expects;  /* the error's "expects ..."; NULL: from arg/choices */
    bool         (*parse)(const char *value, void *opts, splat_arg_why *why);
                             /* CUSTOM (also FLAG: value NULL): false refuses     */
    const char    *optional; /* the value when given alone: then only
                                --name=VALUE sets another ("--far-atlas[=N]")  */
    unsigned       only;     /* a bit set: the commands that take it; 0: all     */
} splat_arg;

/* Offsets for the table: SPLAT_ARG_GIVEN(opts, shading_set). */
#define SPLAT_ARG_GIVEN(type, field) (offsetof(type, field) + 1)

typedef struct splat_args_desc {
    const char      *prog;      /* "splatview", "splatc build": error prefix   */
    const char      *usage;     /* the synopsis lines printed before the list  */
    const char      *epilog;    /* printed after the list by --help (or NULL)  */
    const splat_arg *args;
    int              nargs;
    int              column;    /* help text column (0: 26)                    */
    unsigned         command;   /* the bit of the command parsing (0: all rows) */
    const char *const *command_names; /* bit i's command, named in the help of
                                         a row with `only` (NULL: none)      */
    bool             once;      /* a string option given twice is an error     */
    /* a word that is not an option (a file, a pack); NULL: an error */
    bool           (*positional)(const char *word, void *opts, splat_arg_why *why);
} splat_args_desc;

enum { SPLAT_ARGS_OK = 0, SPLAT_ARGS_USAGE = 2, SPLAT_ARGS_HELP = -1 };

/* Parse argv[first..argc) into `opts` (already holding the defaults).
 * --help and -h print the help on stdout, --help-markdown the list as
 * README.md has it; both return SPLAT_ARGS_HELP (exit 0).  An error is
 * printed on stderr and returns SPLAT_ARGS_USAGE.  "--" ends the options. */
int  splat_args_parse(const splat_args_desc *d, int argc, char **argv, int first, void *opts);
/* The usage lines, the option list and the epilog. */
void splat_args_help(const splat_args_desc *d, FILE *f);
/* The option list alone, as an indented (code) block of Markdown. */
void splat_args_markdown(const splat_args_desc *d, FILE *f);
/* One "HEAD  help" item as the lists print them (a program's commands):
 * HEAD at column base + 2, the help wrapped from base + column. */
void splat_args_item(FILE *f, const char *head, const char *help, int base, int column);
/* The rows that take a value, as "NAME ARG" (for the usage line). */
const char *splat_arg_value_name(const splat_arg *a);

#endif
