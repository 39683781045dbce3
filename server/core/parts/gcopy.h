/* Copying pieces of split grammars into one another (parts library): statements, rules with
 * the rules and terminals they reach, names made unique. Copies carry no resolved indices;
 * ag_grammar_resolve fills them once the grammar is assembled. */
#ifndef AG_GCOPY_H
#define AG_GCOPY_H

#include <stddef.h>
#include <stdint.h>

#include "../proc/grammar.h"
#include "../status.h"

/* Appends a copy of statement s to r with its node, split parent and callee replaced by the
 * given names (NULL: keep s's). */
ag_status ag_gcopy_stmt(ag_grule *r, const ag_gstmt *s, const char *node, const char *parent,
                        const char *callee);
/* Inserts an empty rule at position `at` of g's rules (declare-before-use order). */
ag_status ag_gcopy_insert_rule(ag_grammar *g, size_t at, const char *name, const double size[3],
                               ag_grule **out);
/* A copy of terminal t (geometry included) appended to g under `name`. */
ag_status ag_gcopy_terminal(ag_grammar *g, const ag_gterminal *t, const char *name);
/* A deep copy of g (geometry included); resolved. */
ag_status ag_gcopy_grammar(const ag_grammar *g, ag_grammar **out, ag_error *err);

/* Index of a rule or terminal named `name`: *is_rule 1 for a rule, 0 for a terminal; -1 when
 * g has neither. */
int32_t ag_gcopy_find(const ag_grammar *g, const char *name, int *is_rule);
/* `want` if no rule or terminal of any of the grammars (up to 3, NULL ones skipped) has that
 * name, else want_2, want_3, ... (at most 63 characters). */
void ag_gcopy_unique_name(const ag_grammar *a, const ag_grammar *b, const ag_grammar *c,
                          const char *want, char out[64]);
/* An identifier made of text: letters, digits and '_' kept, anything else '_', a leading digit
 * prefixed with '_', at most 40 characters; "part" when nothing is left. */
void ag_gcopy_identifier(const char *text, char out[64]);

/* Reorders g's rules so that every rule comes after the rules it applies, keeping the order
 * otherwise (depth-first, in the current order). AG_ERR_INVALID naming a rule when they apply
 * each other in a cycle. Indices are stale afterwards: resolve. */
ag_status ag_gcopy_sort_rules(ag_grammar *g, ag_error *err);

/* Marks, in *rules (g->nrules) and *terminals (g->nterminals), everything that the statements
 * of body r reach, directly or through rules (r is resolved against g). */
void ag_gcopy_mark_reachable(const ag_grammar *g, const ag_grule *r, uint8_t *rules,
                             uint8_t *terminals);

#endif
