/* The grammar's text form (schema/grammar.ebnf, schema/grammar.md): parse and canonical print.
 *
 * The printer is canonical: printing a parsed canonical text gives the same bytes. Numbers
 * are printed with up to 12 significant digits (shortest %g form), -0 as 0, comments and
 * extra blanks are dropped. */
#ifndef AG_GRAMMAR_TEXT_H
#define AG_GRAMMAR_TEXT_H

#include <stddef.h>

#include "../core/proc/grammar.h"
#include "../core/status.h"

/* Parses and resolves. On failure err->element is the 1-based line, *col the 1-based column
 * (may be NULL) and err->text the message without position. Terminals get no geometry. */
ag_status ag_grammar_text_parse(const char *text, size_t len, ag_grammar **out, ag_error *err,
                                long *col);

/* *out is malloc'd and NUL-terminated; *len excludes the NUL. */
ag_status ag_grammar_text_print(const ag_grammar *g, char **out, size_t *len, ag_error *err);

/* Sets every number of g to what its text reads back as (printed, then parsed), so that g
 * derives what its printed text does. */
void ag_grammar_text_round(ag_grammar *g);

/* Reads a whole file (limit 64 MiB). */
ag_status ag_grammar_text_read_file(const char *path, ag_grammar **out, ag_error *err, long *col);

#endif
