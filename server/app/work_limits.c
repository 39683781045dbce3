#include "work_limits.h"

ag_work_limits ag_work_limits_resolved(const ag_work_limits *l)
{
    ag_work_limits r = l ? *l : (ag_work_limits){0};
    if (!r.max_triangles)
        r.max_triangles = AG_WORK_LIMITS_MAX_TRIANGLES;
    if (!r.max_nodes)
        r.max_nodes = AG_WORK_LIMITS_MAX_NODES;
    if (!(r.op_seconds > 0))
        r.op_seconds = AG_WORK_LIMITS_OP_SECONDS;
    if (!(r.job_seconds > 0))
        r.job_seconds = AG_WORK_LIMITS_JOB_SECONDS;
    if (!(r.preview_seconds > 0))
        r.preview_seconds = AG_WORK_LIMITS_PREVIEW_SECONDS;
    if (!(r.import_seconds > 0))
        r.import_seconds = AG_WORK_LIMITS_IMPORT_SECONDS;
    return r;
}
