/* The extrude job (POST /api/v1/extrusions): the extrude use case (app/usecase_extrude.h) from
 * the spooled upload into the store, off the request thread, with the params of
 * app/job_params.h (ag_extrude_job), registered with the store services (app/store_env.h). On
 * success, in one transaction: a model of kind "extrusion" (one group and component per
 * building with geometry, named by its id), its buildings' plans, meshes and outcomes
 * (store/extrusions.h), and the job's result {"model", "href", "report": {...}}. */
#ifndef AG_EXTRUDE_JOB_H
#define AG_EXTRUDE_JOB_H

#include "jobqueue.h"

extern const ag_job_kind ag_extrude_job_kind;

#endif
