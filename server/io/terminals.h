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

/* The terminals as stored without files (e.g. in a database): each distinct OBJ text once,
 * under the path ag_terminals_write gives its file. */
typedef struct {
    size_t n;
    char **path, **obj;
    size_t *len;
    size_t bytes; /* the distinct texts' total size */
} ag_terminal_set;

/* Formats every terminal of g, sets its path as ag_terminals_write would, and collects the
 * distinct texts in *s (zeroed by the caller; clear it with ag_terminals_set_clear, also after
 * a failure). */
ag_status ag_terminals_collect(ag_grammar *g, ag_terminal_set *s, ag_error *err);
void ag_terminals_set_clear(ag_terminal_set *s);
/* A terminal lookup over an ag_terminal_set (user): a malloc'd NUL-terminated copy of the text
 * stored under path; AG_ERR_NOT_FOUND when there is none. */
ag_status ag_terminals_set_lookup(void *user, const char *path, char **obj, size_t *len,
                                  ag_error *err);

/* The parts of the collection, shared with point terminals (point_terminals.h): room in s for
 * a grammar's terminals; and one terminal's file bytes (taken, also after a failure) named
 * terminals/<hash of the bytes>.<ext>, set as t's path and added to s unless an equal file is
 * there already. */
ag_status ag_terminals_set_init(ag_terminal_set *s, size_t nterminals, ag_error *err);
ag_status ag_terminals_set_add(ag_terminal_set *s, ag_gterminal *t, char *bytes, size_t len,
                               const char *ext, ag_error *err);

/* Sets one terminal's geometry from OBJ text in memory (e.g. a terminal kept in a database). */
ag_status ag_terminals_load_buffer(ag_gterminal *t, const char *data, size_t len, ag_error *err);

/* Whether a terminal path may be opened below the grammar's folder: relative, no "..", no
 * empty part, no backslash. */
int ag_terminals_path_is_safe(const char *path);

/* Loads every terminal's geometry from dir/<path>. Paths must be relative and must not
 * leave dir ("..", absolute paths and backslashes are refused). */
ag_status ag_terminals_load(ag_grammar *g, const char *dir, ag_error *err);

#endif
