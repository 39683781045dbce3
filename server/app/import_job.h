/* The import use case: an uploaded file (spooled to the upload folder by the REST layer)
 * becomes a stored model, off the request thread. Params JSON:
 * {"upload": path, "name": text, "format": "obj"|null, "up": "y"|"z"|null,
 *  "filename": text|null}. Nothing is visible until the model, its files and the job's
 * success are committed in one transaction. */
#ifndef AG_IMPORT_JOB_H
#define AG_IMPORT_JOB_H

#include <stddef.h>
#include <stdint.h>

#include "../core/mesh.h"
#include "jobqueue.h"

extern const ag_job_kind ag_import_job_kind;

/* Stores a mesh as a new model inside the caller's transaction (used by the import job and
 * the demo content). source may be NULL. */
ag_status ag_import_store_model(ag_db *db, const char *name, const ag_mesh *mesh,
                                const void *source, size_t source_len, const char *source_format,
                                int64_t *model, ag_error *err);

#endif
