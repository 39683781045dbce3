/* The import job (POST /api/v1/models): the import use case (app/usecase_import.h), or the
 * point cloud import (app/usecase_import_cloud.h) for a cloud, from the spooled upload into
 * the store, off the request thread. Nothing is visible until the model,
 * its files and the job's success are committed in one transaction. Registered with the
 * store services (app/store_env.h). */
#ifndef AG_IMPORT_JOB_H
#define AG_IMPORT_JOB_H

#include "jobqueue.h"

extern const ag_job_kind ag_import_job_kind;

#endif
