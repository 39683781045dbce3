/* The proceduralize job (POST /api/v1/models/{id}/proceduralize): the proceduralize use case
 * (app/usecase_proceduralize.h) on the store workspace, off the request thread.
 *
 * Stages and progress: segment, label, tree, rules, patterns, export (core/proc), then
 * verify: the grammar is printed, parsed back with its terminals as stored (10-digit OBJ),
 * derived and compared with the input; a grammar that does not reproduce every input
 * triangle fails the job and leaves the model alone. On success, in one transaction: the
 * model's mesh (the derivation, components in the order its tree numbers them) as version
 * base + 1, the grammar text, split tree (app/model_tree.h), summary and terminals are
 * stored, the op {"kind":"proceduralize","rules","terminals","patterns"} is logged and then
 * published, and the job's result is {"model","version","href","tree","grammar"}. A model
 * that moved past base meanwhile fails the job as stale and nothing is stored. The edit model
 * stays in memory for the first edit. */
#ifndef AG_PROCEDURALIZE_JOB_H
#define AG_PROCEDURALIZE_JOB_H

#include "jobqueue.h"

extern const ag_job_kind ag_proceduralize_job_kind;

#endif
