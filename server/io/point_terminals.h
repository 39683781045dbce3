/* The terminals of a point grammar: one binary PLY per distinct point set, named after a hash
 * of its bytes (terminals/<16 hex>.ply), points in local coordinates of the terminal's box
 * [0, size], with normals and every per-point property (schema/grammar.md, "Point
 * terminals"). A grammar is a point grammar when its terminals name .ply files. */
#ifndef AG_POINT_TERMINALS_H
#define AG_POINT_TERMINALS_H

#include <stddef.h>
#include <stdint.h>

#include "../core/points/cloud.h"
#include "../core/proc/grammar.h"
#include "../core/status.h"
#include "terminals.h"

/* Whether the grammar's terminals name PLY files (every one; the first decides an error
 * for a mixed grammar: AG_ERR_PARSE naming the terminal that differs, via *err). Returns 1
 * for a point grammar, 0 for a mesh grammar, -1 for a mixed one. */
int ag_point_terminals_is_point_grammar(const ag_grammar *g, ag_error *err);

/* Binary little-endian PLY bytes of one terminal (*out malloc'd). */
ag_status ag_point_terminals_format(const ag_cloud *t, char **out, size_t *len, ag_error *err);

/* Formats terminal g of the grammar from clouds[g], sets its path, and collects the distinct
 * files in *s (zeroed by the caller; ag_terminals_set_clear afterwards, also after a failure). */
ag_status ag_point_terminals_collect(ag_grammar *g, ag_cloud *const *clouds, ag_terminal_set *s,
                                     ag_error *err);

/* One terminal's points from PLY bytes, checked to lie in the box [0, size] the grammar gives
 * it (within a thousandth of its size): AG_ERR_PARSE naming the terminal and the point. */
ag_status ag_point_terminals_decode(const ag_gterminal *t, const uint8_t *data, size_t len,
                                    ag_cloud **out, ag_error *err);

/* Every terminal's points from dir/<path> (paths checked as ag_terminals_path_is_safe):
 * clouds has g->nterminals entries (freed by the caller, also after a failure). */
ag_status ag_point_terminals_load(const ag_grammar *g, const char *dir, ag_cloud **clouds,
                                  ag_error *err);

#endif
