/* Demo content for `make run`: the generated buildings, stored when the database is empty and
 * proceduralized by jobs, and a demo street extruded by a job. */
#ifndef AG_DEMO_H
#define AG_DEMO_H

#include "../store/db.h"
#include "jobqueue.h"

ag_status ag_demo_load_if_empty(ag_db *db, ag_jobqueue *jobs, ag_error *err);

#endif
