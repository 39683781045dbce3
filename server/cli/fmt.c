/* archgram fmt GRAMMAR — print the grammar in canonical form. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../io/grammar_text.h"
#include "commands.h"

int ag_cli_fmt(int argc, char **argv)
{
    if (argc == 2 && !strcmp(argv[1], "--help")) {
        fputs("usage: archgram fmt GRAMMAR\n", stdout);
        return 0;
    }
    if (argc != 2 || (argv[1][0] == '-' && argv[1][1])) {
        fputs("usage: archgram fmt GRAMMAR\n", stderr);
        return 2;
    }
    ag_error err;
    ag_error_clear(&err);
    ag_grammar *g = NULL;
    long col = 0;
    ag_status st = ag_grammar_text_read_file(argv[1], &g, &err, &col);
    if (st) {
        if (st == AG_ERR_PARSE)
            fprintf(stderr, "%s:%ld:%ld: %s\n", argv[1], err.element, col, err.text);
        else
            ag_cli_report(argv[1], &err);
        return 1;
    }
    char *text;
    size_t len;
    st = ag_grammar_text_print(g, &text, &len, &err);
    ag_grammar_free(g);
    if (st) {
        ag_cli_report(argv[1], &err);
        return 1;
    }
    int ok = fwrite(text, 1, len, stdout) == len;
    free(text);
    return ok ? 0 : 1;
}
