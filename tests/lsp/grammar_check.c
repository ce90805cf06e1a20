/* grammar_check.c — `grammar_check GRAMMAR PARSER_C...`: the TextMate grammar
 * editors/sg.tmLanguage.json is valid JSON, names the scope source.sg for
 * .sg files, and its patterns name every word the language knows, so it
 * fails when one is added to the compiler and not to the grammar:
 *
 *   - every keyword the parser's files (compiler/parse*.c) recognise (each
 *     `is_kw(t, "word")` and `word_is(v, "word")` in their text:
 *     statements, settings, values);
 *   - the types, the settings blocks' keys (sg_scene_keys, …), the light
 *     keys, filter and wrap names, built-in meshes, terrain and view inputs
 *     (the compiler's own tables).
 *
 * A word counts when it stands whole (not inside a longer name) in some
 * "match", "begin" or "end" pattern. */
#include "abi.h"
#include "ir.h"
#include "mesh.h"
#include "sg_internal.h"

#include <jansson.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int failures;

/* Every pattern string of the grammar, appended to *all ("\b" made a blank). */
static void patterns(json_t *j, char **all, size_t *len)
{
    if (json_is_object(j)) {
        const char *key;
        json_t *v;
        json_object_foreach(j, key, v) {
            if (json_is_string(v) && (!strcmp(key, "match") || !strcmp(key, "begin") ||
                                      !strcmp(key, "end"))) {
                const char *s = json_string_value(v);
                size_t n = strlen(s);
                *all = realloc(*all, *len + n + 2);
                for (size_t i = 0; i < n; i++) {
                    bool wb = s[i] == '\\' && s[i + 1] == 'b';
                    (*all)[(*len)++] = wb ? ' ' : s[i];
                    if (wb) {
                        (*all)[(*len)++] = ' ';
                        i++;
                    }
                }
                (*all)[(*len)++] = '\n';
                (*all)[*len] = 0;
            } else {
                patterns(v, all, len);
            }
        }
    } else if (json_is_array(j)) {
        size_t i;
        json_t *v;
        json_array_foreach(j, i, v)
            patterns(v, all, len);
    }
}

static bool word_char(char c)
{
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
}

static void need(const char *all, const char *word, const char *from)
{
    size_t n = strlen(word);
    for (const char *p = strstr(all, word); p; p = strstr(p + 1, word))
        if ((p == all || !word_char(p[-1])) && !word_char(p[n]))
            return;
    fprintf(stderr, "FAIL: editors/sg.tmLanguage.json does not name '%s' (%s)\n", word, from);
    failures++;
}

static void need_list(const char *all, const char *const *words, const char *from)
{
    for (int i = 0; words[i]; i++)
        need(all, words[i], from);
}

/* The words a parser file recognises: is_kw(…, "w") and word_is(…, "w"). */
static int parser_words(const char *all, const char *parse_c)
{
    FILE *f = fopen(parse_c, "rb");
    if (!f) {
        perror(parse_c);
        return -1;
    }
    static char text[1 << 20];
    size_t n = fread(text, 1, sizeof text - 1, f);
    fclose(f);
    text[n] = 0;
    int found = 0;
    static const char *const calls[] = { "is_kw(", "word_is(" };
    for (int c = 0; c < 2; c++)
        for (const char *p = strstr(text, calls[c]); p; p = strstr(p + 1, calls[c])) {
            const char *q = strpbrk(p, "\");");
            if (!q || *q != '"')
                continue;                   /* a call with no literal: is_kw(t, kw) */
            const char *e = strchr(q + 1, '"');
            if (!e || e - q > 64)
                continue;
            char word[64];
            snprintf(word, sizeof word, "%.*s", (int)(e - q - 1), q + 1);
            need(all, word, parse_c);
            found++;
        }
    return found;
}

int main(int argc, char **argv)
{
    if (argc < 3) {
        fprintf(stderr, "usage: grammar_check GRAMMAR PARSER_C...\n");
        return 2;
    }
    json_error_t je;
    json_t *g = json_load_file(argv[1], 0, &je);
    if (!g) {
        fprintf(stderr, "FAIL: %s is not valid JSON: line %d, column %d: %s\n", argv[1], je.line,
                je.column, je.text);
        return 1;
    }
    const char *scope = json_string_value(json_object_get(g, "scopeName"));
    if (!scope || strcmp(scope, "source.sg")) {
        fprintf(stderr, "FAIL: scopeName is not source.sg\n");
        failures++;
    }
    json_t *ft = json_object_get(g, "fileTypes");
    if (!json_is_array(ft) || strcmp(json_string_value(json_array_get(ft, 0)) ?: "", "sg")) {
        fprintf(stderr, "FAIL: fileTypes does not list sg\n");
        failures++;
    }
    char *all = calloc(1, 1);
    size_t len = 0;
    patterns(g, &all, &len);
    int words = 0;
    for (int i = 2; i < argc; i++) {
        int n = parser_words(all, argv[i]);
        if (n < 0)
            failures++;
        words += n > 0 ? n : 0;
    }
    if (words < 30) {
        fprintf(stderr, "FAIL: only %d keywords found in the parser's %d files: has the parser "
                "changed how it recognises them?\n", words, argc - 2);
        failures++;
    }
    for (int t = IR_T_FLOAT; t <= IR_T_TEX; t++)
        need(all, ir_type_name((ir_type)t), "types");
    need_list(all, sg_scene_keys, "sg_scene_keys");
    need_list(all, sg_texture_keys, "sg_texture_keys");
    need_list(all, sg_painted_keys, "sg_painted_keys");
    need_list(all, sg_camera_keys, "sg_camera_keys");
    need_list(all, sg_destruction_keys, "sg_destruction_keys");
    need_list(all, sg_ug_keys, "sg_ug_keys");
    need_list(all, splat_mesh_builtins, "splat_mesh_builtins");
    for (int k = 0; k < SPLAT_LIGHT_COUNT; k++)
        need(all, splat_light_keys[k].key, "splat_light_keys");
    for (int i = 0; strcmp(ir_filter_name((ir_filter)i), "?"); i++)
        need(all, ir_filter_name((ir_filter)i), "filters");
    for (int i = 0; strcmp(ir_wrap_name((ir_wrap)i), "?"); i++)
        need(all, ir_wrap_name((ir_wrap)i), "wraps");
    for (int k = 0; k < IR_IN_COUNT; k++) {
        char name[64];
        snprintf(name, sizeof name, "%s", ir_input_get((ir_input_kind)k)->name);
        char *dot = strchr(name, '.');
        if (dot)
            *dot = 0;
        need(all, name, "IR_INPUTS");
        need(all, dot ? dot + 1 : name, "IR_INPUTS");
    }
    free(all);
    json_decref(g);
    if (!failures)
        printf("grammar: %d parser keywords and the tables' words are named\n", words);
    return failures ? 1 : 0;
}
