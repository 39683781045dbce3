/* The proceduralize use case (POST /api/v1/models/{id}/proceduralize), off the request
 * thread. Params JSON: {"model": id, "base": version, "author": text}.
 *
 * Stages and progress: segment, label, tree, rules, patterns, export (core/proc), then
 * verify: the grammar is printed, parsed back with its terminals as stored (10-digit OBJ),
 * derived and compared with the input; a grammar that does not reproduce every input
 * triangle fails the job and leaves the model alone. On success, in one transaction: the
 * derived mesh becomes the model's mesh as version base + 1, the grammar text, split tree
 * (from the derivation, see io/splittree_json.h), summary and terminals are stored, the op
 * {"kind":"proceduralize","rules","terminals","patterns"} is logged and then published, and
 * the job's result is {"model","version","href","tree","grammar"}. A model that moved past
 * base meanwhile fails the job as stale and nothing is stored. */
#ifndef AG_PROCEDURALIZE_JOB_H
#define AG_PROCEDURALIZE_JOB_H

#include "jobqueue.h"

extern const ag_job_kind ag_proceduralize_job_kind;

#endif
