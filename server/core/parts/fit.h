/* Proportions: a rule body fitted into a box of another size (paper §4.2, "no manual
 * adjustment"), by the attachment equations of server/core/edit (attach.h) solved as sparse
 * least squares (lsq.h).
 *
 * The elements are the body's applied nodes (one per body node that something is applied to)
 * and the body's box itself, whose six coordinates are fixed to the new box. Between every
 * two elements the attachments of ag_attach_detect hold: shared coordinates (contacts, aligned
 * faces) are hard — the coordinates are merged into classes with offsets —, overlaps keep
 * their ratios softly. An element no longer along an axis than AG_FIT_RIGID of the body's
 * extent is rigid on that axis (a frame bar, a mullion, a sill's depth keep their size); rigid
 * sizes that contradict the hard contacts (a slot too narrow for every bar) become strong soft
 * terms instead. Every element also keeps its size (soft) and its place scaled with the box
 * (weakest), so the system is definite. Each application is then placed on its element's new
 * box by two fresh splits from p; patterns keep their counts, their steps scale with their
 * box, and rules applied inside stretch as grammar application does. */
#ifndef AG_FIT_H
#define AG_FIT_H

#include <stddef.h>

#include "../proc/grammar.h"
#include "../status.h"

#define AG_FIT_RIGID 0.25
#define AG_FIT_MAX_ELEMENTS 200000

typedef struct {
    size_t elements, classes, equations;
    size_t rigid, rigid_relaxed; /* rigid sizes kept exactly / turned soft */
    unsigned columns[3][2];      /* per axis re-laid by its columns (fitcount.h): the old and
                                    new column counts; {0, 0} where none */
} ag_fit_report;

/* Appends to `out` (an empty rule; its size is set to size) the statements of body r (of
 * grammar g, resolved) fitted from r->size into size. Callee names are kept. */
ag_status ag_fit_body(const ag_grammar *g, const ag_grule *r, const double size[3], ag_grule *out,
                      ag_fit_report *rep, ag_error *err);

#endif
