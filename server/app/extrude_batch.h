/* City batches on every core: the footprints of a GeoJSON batch are extruded in parallel
 * (ag_building_extrude each: made good, retried, or fallen back, each under its own
 * budget), then assembled in input order into one mesh, one group (named by the
 * footprint id) and one component per building, and reported exactly as the serial
 * ag_footprints_extrude_with would (same mesh, same report). */
#ifndef AG_EXTRUDE_BATCH_H
#define AG_EXTRUDE_BATCH_H

#include <stddef.h>

#include "../core/extrude/extrude.h"
#include "../core/extrude/style.h"
#include "../core/mesh.h"
#include "../io/footprints.h"

typedef struct {
    size_t threads;             /* 0: one per online CPU */
    ag_extrude_options extrude; /* each building's options (budget per building) */
} ag_extrude_batch_options;

/* Fails only on out-of-memory, a thread that cannot start (then it runs serially), or
 * when a building's budget callback cancels (AG_ERR_CANCELLED: m is then unchanged). */
ag_status ag_extrude_batch(const ag_footprints *f, const ag_style *style,
                           const ag_extrude_batch_options *opt, ag_mesh *m,
                           ag_footprints_report *report, ag_error *err);

#endif
