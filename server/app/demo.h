/* Demo content for `make run`: the generated buildings, stored when the database is empty and
 * proceduralized by jobs, a few parts of the library saved from them by a job once they are
 * (a window, the row of windows, the door of the row house, a column of the tower), and a
 * demo street extruded by a job. */
#ifndef AG_DEMO_H
#define AG_DEMO_H

#include "../store/db.h"
#include "jobqueue.h"

ag_status ag_demo_load_if_empty(ag_db *db, ag_jobqueue *jobs, ag_error *err);

/* The job that saves the demo parts (registered by the app). */
extern const ag_job_kind ag_demo_parts_job_kind;

#endif
