/* How much work the service takes on: the largest result of one op, and how long one op, job
 * or preview may run. archgramd sets them from its flags (--max-triangles, --max-nodes,
 * --op-seconds, --job-seconds, --preview-seconds, --import-seconds); zero fields take the defaults below, which
 * fit a 2-core machine with 24 GiB: a result at the limits is proceduralized in about five
 * seconds in under 1 GiB, so a handful of them at once stay far from the memory.
 *
 * What they bound:
 *   max_triangles   the mesh a structural edit, a paste or a grammar edit makes, and the mesh
 *                   a proceduralization starts from (AG_ERR_RESULT_TOO_LARGE before the work)
 *   max_nodes       the terminals (components, visible split-tree nodes) such a result places
 *   op_seconds      one structural op, undo/redo/restore, grammar edit or drag preview, from
 *                   the moment it starts (AG_ERR_DEADLINE when it runs out)
 *   job_seconds     one stored job (import, proceduralize, extrude)
 *   import_seconds  reading one uploaded file with assimp (in a child process that is
 *                   killed past it, app/import_sandbox.h)
 *   preview_seconds one extrusion preview */
#ifndef AG_WORK_LIMITS_H
#define AG_WORK_LIMITS_H

#include <stddef.h>

#define AG_WORK_LIMITS_MAX_TRIANGLES ((size_t)2000000)
#define AG_WORK_LIMITS_MAX_NODES ((size_t)200000)
#define AG_WORK_LIMITS_OP_SECONDS 60.0
#define AG_WORK_LIMITS_JOB_SECONDS 3600.0
#define AG_WORK_LIMITS_PREVIEW_SECONDS 10.0
#define AG_WORK_LIMITS_IMPORT_SECONDS 120.0

typedef struct {
    size_t max_triangles;
    size_t max_nodes;
    double op_seconds;
    double job_seconds;
    double preview_seconds;
    double import_seconds;
} ag_work_limits;

/* l with every zero field set to its default. */
ag_work_limits ag_work_limits_resolved(const ag_work_limits *l);

#endif
