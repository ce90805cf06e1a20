/* cli.h — the commands of the splatc executable that live in their own
 * files (main.c dispatches the rest).  Not part of libsplatc: the CLI
 * sources build into the executable only (compiler/CMakeLists.txt).
 * Each takes argv[0] = the command's name and returns the exit status
 * (0 ok, 1 error, 2 usage). */
#ifndef SPLAT_CLI_H
#define SPLAT_CLI_H

/* `splatc build SCENE.sg -o PACKDIR ...` (cli_build.c) */
int splat_cli_build(int argc, char **argv);
/* `splatc texgen --out DIR [--seed N] [--size N] [--all-mips]` (cli_texgen.c) */
int splat_cli_texgen(int argc, char **argv);
int splat_cli_init(int argc, char **argv);    /* cli_init.c: splatc init DIR */
int splat_cli_doc(int argc, char **argv);     /* cli_doc.c: splatc doc [-o FILE] */
int splat_cli_lsp(int argc, char **argv);     /* lsp.c: splatc lsp [-I DIR]... */

#endif
