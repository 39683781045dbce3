/* The jobs table: long work (imports, later inference) with status, progress and outcome. */
#ifndef AG_JOBS_H
#define AG_JOBS_H

#include <stdint.h>

#include "db.h"

typedef struct {
    int64_t id;
    char kind[32];
    char status[16]; /* queued | running | succeeded | failed | cancelled */
    double progress;
    char stage[32];  /* "" when none */
    char *params_json;
    char *result_json; /* NULL when none */
    char *error_json;  /* NULL when none */
    int64_t model;     /* 0 when none */
    int64_t user;      /* the account that asked for it; 0: the server itself */
    char created_at[32];
    char updated_at[32];
} ag_job_row;

void ag_jobs_row_clear(ag_job_row *row);

/* user: the account that asks for the job (0: the server itself). */
ag_status ag_jobs_insert(ag_db *db, const char *kind, const char *params_json, int64_t user,
                         int64_t *id, ag_error *err);
ag_status ag_jobs_get(ag_db *db, int64_t id, ag_job_row *row, ag_error *err);
/* Status, progress and stage (stage may be NULL to keep it). Only unfinished jobs change. */
ag_status ag_jobs_update(ag_db *db, int64_t id, const char *status, double progress,
                         const char *stage, ag_error *err);
/* Final state; result/error JSON may be NULL; model 0 = none. Only unfinished jobs change. */
ag_status ag_jobs_finish(ag_db *db, int64_t id, const char *status, const char *result_json,
                         const char *error_json, int64_t model, ag_error *err);
/* Marks every queued or running job cancelled with the given problem JSON (used at start-up
 * for jobs a previous process left behind). Returns how many through *count. */
ag_status ag_jobs_cancel_unfinished(ag_db *db, const char *error_json, int *count, ag_error *err);

#endif
