/* Terminal geometry files: one OBJ per distinct terminal content, named after a hash of the
 * content (terminals/<16 hex>.obj), so identical terminals share one file. Coordinates are
 * local to the terminal's box, z up, written with 10 significant digits. */
#ifndef AG_TERMINALS_H
#define AG_TERMINALS_H

#include <stddef.h>

#include "../core/proc/grammar.h"
#include "../core/status.h"

/* OBJ text of one terminal; *out malloc'd. */
ag_status ag_terminals_format(const ag_gterminal *t, char **out, size_t *len, ag_error *err);

/* Writes every terminal's geometry under dir/terminals/ and sets its path (relative to dir).
 * *bytes (may be NULL) receives the total size of the distinct files. */
ag_status ag_terminals_write(ag_grammar *g, const char *dir, size_t *bytes, ag_error *err);

/* Sets one terminal's geometry from OBJ text in memory (e.g. a terminal kept in a database). */
ag_status ag_terminals_load_buffer(ag_gterminal *t, const char *data, size_t len, ag_error *err);

/* Loads every terminal's geometry from dir/<path>. Paths must be relative and must not
 * leave dir ("..", absolute paths and backslashes are refused). */
ag_status ag_terminals_load(ag_grammar *g, const char *dir, ag_error *err);

#endif
