/* test_lex.c — the .sg lexer: token kinds, values and positions, comments,
 * number forms good and bad, strings, garbage, and linear behaviour on
 * large inputs. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include <stdlib.h>
#include <string.h>

#include "sg_internal.h"

typedef struct lexed {
    sg_arena arena;
    sg_file  file;
    sg_diags d;
} lexed;

static lexed *lex(const char *text)
{
    lexed *l = calloc(1, sizeof *l);
    l->file.path = "t.sg";
    l->file.len = strlen(text);
    l->file.text = sg_strndup(&l->arena, text, l->file.len);
    sg_diags_init(&l->d);
    sg_lex(&l->arena, &l->file, &l->d);
    return l;
}

static void lexed_free(lexed *l)
{
    sg_diags_free(&l->d);
    sg_arena_free(&l->arena);
    free(l);
}

static void assert_tok(const sg_token *t, sg_tok_kind k, const char *text, int line, int col)
{
    assert_int_equal(t->kind, k);
    if (text) {
        assert_int_equal(t->len, (int)strlen(text));
        assert_memory_equal(t->start, text, strlen(text));
    }
    assert_int_equal(t->line, line);
    assert_int_equal(t->col, col);
}

static void test_tokens_and_positions(void **state)
{
    lexed *l = lex("node r : div { a = n.out, b = 1.5 }  # comment\n\tout float x = r.out\n");
    const sg_token *t = l->file.toks;
    assert_int_equal(l->d.nerrors, 0);
    assert_tok(&t[0], SG_TK_IDENT, "node", 1, 1);
    assert_tok(&t[1], SG_TK_IDENT, "r", 1, 6);
    assert_tok(&t[2], SG_TK_COLON, ":", 1, 8);
    assert_tok(&t[3], SG_TK_IDENT, "div", 1, 10);
    assert_tok(&t[4], SG_TK_LBRACE, "{", 1, 14);
    assert_tok(&t[5], SG_TK_IDENT, "a", 1, 16);
    assert_tok(&t[6], SG_TK_EQ, "=", 1, 18);
    assert_tok(&t[7], SG_TK_IDENT, "n", 1, 20);
    assert_tok(&t[8], SG_TK_DOT, ".", 1, 21);
    assert_tok(&t[9], SG_TK_IDENT, "out", 1, 22);
    assert_tok(&t[10], SG_TK_COMMA, ",", 1, 25);
    assert_tok(&t[13], SG_TK_NUMBER, "1.5", 1, 31);
    assert_true(t[13].num == 1.5);
    assert_tok(&t[14], SG_TK_RBRACE, "}", 1, 35);
    /* the comment is gone; the tab counts as one column */
    assert_tok(&t[15], SG_TK_IDENT, "out", 2, 2);
    assert_tok(&t[19], SG_TK_IDENT, "r", 2, 16);
    assert_tok(&t[22], SG_TK_EOF, NULL, 3, 1);
    assert_int_equal(l->file.ntoks, 23);
    lexed_free(l);
}

static void test_numbers(void **state)
{
    lexed *l = lex("1e6 -0.5 .5 2.5E-3 0 -.25 vec2(1,.5) x.y");
    const sg_token *t = l->file.toks;
    assert_int_equal(l->d.nerrors, 0);
    double want[] = { 1e6, -0.5, 0.5, 2.5e-3, 0, -0.25 };
    for (int i = 0; i < 6; i++) {
        assert_int_equal(t[i].kind, SG_TK_NUMBER);
        assert_true(t[i].num == want[i]);
    }
    assert_int_equal(t[6].kind, SG_TK_IDENT);     /* vec2 */
    assert_int_equal(t[7].kind, SG_TK_LPAREN);
    assert_true(t[8].num == 1 && t[10].num == 0.5);
    /* `.y` after a name is a dot and a name, never a number */
    assert_int_equal(t[12].kind, SG_TK_IDENT);
    assert_int_equal(t[13].kind, SG_TK_DOT);
    assert_int_equal(t[14].kind, SG_TK_IDENT);
    lexed_free(l);
}

static void test_bad_literals(void **state)
{
    const char *bad[] = { "1.2.3", "0x", "1e", "2x", "1e+", "1e999" };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        char text[64];
        snprintf(text, sizeof text, "a = %s\n", bad[i]);
        lexed *l = lex(text);
        assert_int_equal(l->d.nerrors, 1);
        assert_int_equal(l->d.items[0].id, SG_E_BAD_LITERAL);
        assert_int_equal(l->d.items[0].loc.line, 1);
        assert_int_equal(l->d.items[0].loc.col, 5);
        assert_non_null(strstr(l->d.items[0].msg, bad[i]));
        /* one number token stands for the whole literal */
        assert_int_equal(l->file.toks[2].kind, SG_TK_NUMBER);
        assert_int_equal(l->file.toks[3].kind, SG_TK_EOF);
        lexed_free(l);
    }
}

static void test_strings(void **state)
{
    lexed *l = lex("f = \"tex/rock \\\"big\\\".png\" x");
    assert_int_equal(l->d.nerrors, 0);
    assert_int_equal(l->file.toks[2].kind, SG_TK_STRING);
    assert_string_equal(l->file.toks[2].str, "tex/rock \"big\".png");
    assert_int_equal(l->file.toks[3].kind, SG_TK_IDENT);
    lexed_free(l);

    l = lex("a\n  f = \"open\nb");
    assert_int_equal(l->d.nerrors, 1);
    assert_int_equal(l->d.items[0].id, SG_E_UNTERMINATED);
    assert_int_equal(l->d.items[0].loc.line, 2);
    assert_int_equal(l->d.items[0].loc.col, 7);
    assert_string_equal(l->d.items[0].msg, "unterminated string (opened at line 2)");
    /* lexing goes on after the bad string */
    assert_int_equal(l->file.toks[l->file.ntoks - 2].kind, SG_TK_IDENT);
    lexed_free(l);
}

static void test_garbage(void **state)
{
    /* a run of unexpected bytes is one error; lexing resumes after it */
    lexed *l = lex("a @$%\x01\xff b\n;c");
    assert_int_equal(l->d.nerrors, 2);
    assert_int_equal(l->d.items[0].id, SG_E_BAD_CHAR);
    assert_string_equal(l->d.items[0].msg, "unexpected character '@'");
    assert_int_equal(l->d.items[0].loc.col, 3);
    assert_int_equal(l->d.items[1].loc.line, 2);
    assert_int_equal(l->file.ntoks, 4);   /* a b c EOF */
    lexed_free(l);

    /* NUL bytes inside the text are errors, not the end of the file */
    sg_arena a = { 0 };
    sg_file f = { .path = "n.sg", .len = 5 };
    f.text = sg_alloc(&a, 6);
    memcpy(f.text, "a\0\0 b", 5);
    sg_diags d;
    sg_diags_init(&d);
    sg_lex(&a, &f, &d);
    assert_int_equal(d.nerrors, 1);
    assert_string_equal(d.items[0].msg, "unexpected character byte 0x00");
    assert_int_equal(f.ntoks, 3);
    sg_diags_free(&d);
    sg_arena_free(&a);
}

static void test_many_errors_are_capped(void **state)
{
    /* 100 000 bad lines: every error is counted, SG_MAX_STORED_DIAGS kept */
    size_t n = 100000;
    char *text = malloc(n * 3 + 1);
    for (size_t i = 0; i < n; i++)
        memcpy(text + 3 * i, "@x\n", 3);
    text[3 * n] = 0;
    lexed *l = lex(text);
    assert_int_equal(l->d.nerrors, (int)n);
    assert_int_equal(l->d.n, SG_MAX_STORED_DIAGS);
    assert_int_equal(l->d.ndropped, (int)n - SG_MAX_STORED_DIAGS);
    assert_int_equal(l->file.ntoks, (int)n + 1);
    lexed_free(l);
    free(text);
}

static void test_diagnostic_print(void **state)
{
    sg_diags d;
    sg_diags_init(&d);
    sg_diags_add_source(&d, "g.sg", "line one\n\tnode x : rampp\n", 24);
    sg_error(&d, (sg_loc){ "g.sg", 2, 11 }, SG_E_UNKNOWN_NODE, "rampp");
    char *buf = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&buf, &len);
    sg_diags_print(&d, f);
    fclose(f);
    assert_string_equal(buf, "g.sg:2:11: error: unknown node type 'rampp'\n"
                             "    2 | \tnode x : rampp\n"
                             "      | \t         ^\n");
    free(buf);
    sg_diags_free(&d);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_tokens_and_positions),
        cmocka_unit_test(test_numbers),
        cmocka_unit_test(test_bad_literals),
        cmocka_unit_test(test_strings),
        cmocka_unit_test(test_garbage),
        cmocka_unit_test(test_many_errors_are_capped),
        cmocka_unit_test(test_diagnostic_print),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
