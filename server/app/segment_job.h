/* The segment job (POST /api/v1/models/{id}/segment): the segment use case
 * (app/usecase_segment.h) on a point cloud model of the store, off the request thread; the
 * segmentation is logged as a "segment" op with its report. Registered with the store
 * services (app/store_env.h). */
#ifndef AG_SEGMENT_JOB_H
#define AG_SEGMENT_JOB_H

#include "jobqueue.h"

extern const ag_job_kind ag_segment_job_kind;

#endif
