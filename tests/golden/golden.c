/* golden.c — the golden test runner: each .sg file in tests/golden states
 * the diagnostics it must produce in comments,
 *
 *     # expect: 4:14: error: unknown node type 'rampp'
 *     # expect: tests/golden/inc/b.sg:2:1: error: …   (another file)
 *
 * in the order the compiler reports them.  A file with no `expect` line
 * must load without errors and every one of its materials must lower to
 * valid IR.  A file with a `# golden: texture files` line also has its
 * texture files checked (sg_check_texture_files, as `splatc check` does),
 * one with `# golden: lint` the warnings of sg_lint over every input's
 * domain (as `splatc check` has).
 * Usage: golden FILE.sg [--print] (from the repository root;
 * --print shows what the compiler says, in the expect format). */
#include "sg.h"

#include <stdlib.h>
#include <string.h>

static char *read_file(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *s = malloc((size_t)n + 1);
    if (!s || fread(s, 1, (size_t)n, f) != (size_t)n) {
        fclose(f);
        free(s);
        return NULL;
    }
    s[n] = 0;
    fclose(f);
    return s;
}

/* "L:C: error: msg" for the file itself, "file:L:C: error: msg" otherwise. */
static char *format(const char *self, const sg_diag *g)
{
    static const char *const sev[] = { "error", "warning", "note" };
    char buf[1200];
    if (g->loc.file && strcmp(g->loc.file, self))
        snprintf(buf, sizeof buf, "%s:%d:%d: %s: %s", g->loc.file, g->loc.line, g->loc.col,
                 sev[g->severity], g->msg);
    else
        snprintf(buf, sizeof buf, "%d:%d: %s: %s", g->loc.line, g->loc.col, sev[g->severity],
                 g->msg);
    return strdup(buf);
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: golden FILE.sg [--print]\n");
        return 2;
    }
    const char *path = argv[1];
    bool print = argc > 2 && !strcmp(argv[2], "--print");
    char *text = read_file(path);
    if (!text) {
        fprintf(stderr, "golden: cannot read %s\n", path);
        return 2;
    }
    bool texture_files = strstr(text, "# golden: texture files") != NULL;
    bool lint = strstr(text, "# golden: lint") != NULL;
    /* the expectations */
    char **want = NULL;
    int nwant = 0;
    for (char *line = strtok(text, "\n"); line; line = strtok(NULL, "\n")) {
        char *e = strstr(line, "# expect: ");
        if (!e)
            continue;
        want = realloc(want, (size_t)(nwant + 1) * sizeof *want);
        want[nwant++] = e + strlen("# expect: ");
    }
    const char *const search[] = { ".", NULL };
    sg_diags d;
    sg_diags_init(&d);
    sg_program *p = sg_load(path, search, &d);
    if (p && texture_files && d.nerrors == 0)
        sg_check_texture_files(p, &d);
    if (p && lint && d.nerrors == 0)
        sg_lint(p, NULL, &d);
    int failures = 0;
    if (print) {
        for (int i = 0; i < d.n; i++) {
            char *got = format(path, &d.items[i]);
            printf("# expect: %s\n", got);
            free(got);
        }
    } else {
        int n = d.n > nwant ? d.n : nwant;
        for (int i = 0; i < n; i++) {
            char *got = i < d.n ? format(path, &d.items[i]) : NULL;
            const char *w = i < nwant ? want[i] : NULL;
            if (!got || !w || strcmp(got, w)) {
                fprintf(stderr, "%s: diagnostic %d:\n  want: %s\n  got:  %s\n", path, i + 1,
                        w ? w : "(none)", got ? got : "(none)");
                failures++;
            }
            free(got);
        }
        int nwant_errors = 0;
        for (int i = 0; i < nwant; i++)
            nwant_errors += strstr(want[i], ": error: ") != NULL;
        if (d.nerrors != nwant_errors && d.n == nwant) {
            fprintf(stderr, "%s: %d errors counted, %d expected\n", path, d.nerrors,
                    nwant_errors);
            failures++;
        }
    }
    if (!print && d.nerrors == 0 && p && (nwant == 0 || lint)) {
        /* a good file: every material lowers to valid IR */
        for (int i = 0; i < sg_material_count(p); i++) {
            ir ir;
            ir_init(&ir);
            if (!sg_lower_material(p, sg_material_name(p, i), &ir, &d) ||
                !ir_validate(&ir, stderr)) {
                sg_diags_print(&d, stderr);
                fprintf(stderr, "%s: material '%s' does not lower\n", path,
                        sg_material_name(p, i));
                failures++;
            }
            ir_free(&ir);
        }
    }
    if (failures)
        sg_diags_print(&d, stderr);
    sg_free(p);
    sg_diags_free(&d);
    free(want);
    free(text);
    return failures ? 1 : 0;
}
