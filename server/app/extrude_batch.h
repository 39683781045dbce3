/* City batches on every core: the buildings of a batch are extruded in parallel (each made
 * good, retried, or fallen back under its own budget: ag_building_extrude for footprints
 * with a style, ag_building_extrude_plan for building descriptions), then assembled in
 * input order, one group (named by the building's id) and one component per building, and
 * reported exactly as the serial ag_footprints_extrude_with would (same mesh, same report).
 *
 * The budget's cancel callback (opt->extrude.budget.cancelled) is polled by every thread,
 * so a cancelled job or a shutdown stops all of them within milliseconds; progress is
 * reported from the calling thread only (it may write to a store). */
#ifndef AG_EXTRUDE_BATCH_H
#define AG_EXTRUDE_BATCH_H

#include <stddef.h>

#include "../core/extrude/building.h"
#include "../core/extrude/extrude.h"
#include "../core/extrude/style.h"
#include "../core/mesh.h"
#include "../io/footprints.h"

typedef struct {
    size_t threads;             /* 0: one per online CPU */
    ag_extrude_options extrude; /* each building's options (budget per building) */
    /* called by the calling thread now and then with how many buildings are done (may be
     * NULL) */
    void (*progress)(void *user, size_t done, size_t total);
    void *progress_user;
} ag_extrude_batch_options;

/* Fails only on out-of-memory, or when a building's budget callback cancels
 * (AG_ERR_CANCELLED: m is then unchanged). A thread that cannot start leaves its share to
 * the others. */
ag_status ag_extrude_batch(const ag_footprints *f, const ag_style *style,
                           const ag_extrude_batch_options *opt, ag_mesh *m,
                           ag_footprints_report *report, ag_error *err);

/* Builds building i into m (a mesh of its own, with no group yet) under opt: e.g.
 * ag_building_extrude or ag_building_extrude_plan into a group it adds. Returns what they
 * return. Called from several threads at once, each with a different i. */
typedef ag_status (*ag_extrude_batch_build)(void *user, size_t i, const ag_extrude_options *opt,
                                            ag_mesh *m, ag_building_result *out,
                                            ag_error *err);

/* Runs build for every i < n on every core, each building into a mesh of its own:
 * meshes[i] (created here; the caller frees each with ag_mesh_free) and results[i]. On
 * failure (out of memory, cancelled: the first error) every mesh is freed and NULL. */
ag_status ag_extrude_batch_each(size_t n, ag_extrude_batch_build build, void *user,
                                const ag_extrude_batch_options *opt, ag_mesh **meshes,
                                ag_building_result *results, ag_error *err);

#endif
