/* The models table: a model's name, kind, version and its stored geometry. */
#ifndef AG_MODELS_H
#define AG_MODELS_H

#include <stddef.h>
#include <stdint.h>

#include "db.h"

#define AG_MODEL_NAME_MAX 200

typedef struct {
    int64_t id;
    char name[AG_MODEL_NAME_MAX * 4 + 1]; /* UTF-8: up to 200 characters */
    char kind[32];
    int64_t version;
    int64_t mesh_blob;
    int64_t source_blob; /* 0 when none */
    char source_format[16];
    char created_at[32];
    char updated_at[32];
    char *stats_json; /* malloc'd; ag_models_row_clear frees it */
    char *up_json;    /* how the import decided the up axis, malloc'd; NULL when not imported */
    int public_read;  /* readable by every account */
    char member_role[8]; /* ag_models_list: the role of its visible_to on it ("" none) */
} ag_model_row;

void ag_models_row_clear(ag_model_row *row);

typedef struct {
    const char *name;
    const char *kind;          /* NULL = "mesh" */
    const char *stats_json;    /* NULL = "{}" */
    const char *up_json;       /* the import's up-axis decision (JSON); may be NULL */
    const char *source_format; /* may be NULL */
    const void *source;        /* may be NULL */
    size_t source_len;
    const char *source_media_type;
    const void *mesh;
    size_t mesh_len;
} ag_model_new;

/* Inside the caller's transaction. */
ag_status ag_models_insert(ag_db *db, const ag_model_new *m, int64_t *id, ag_error *err);
ag_status ag_models_get(ag_db *db, int64_t id, ag_model_row *row, ag_error *err);
/* Rows with id > after_id, ascending, at most limit; *rows is malloc'd (clear each). With
 * visible_to (an account id; 0 = every model) only the models that account has a role on or
 * that are public-read, each with its role in member_role. */
ag_status ag_models_list(ag_db *db, int64_t visible_to, int64_t after_id, size_t limit,
                         ag_model_row **rows, size_t *count, ag_error *err);
size_t ag_models_count(ag_db *db);
/* Raises the version by one if it is base; AG_ERR_STALE (current version in err->element)
 * otherwise, AG_ERR_NOT_FOUND when there is no such model. Inside the caller's transaction. */
ag_status ag_models_bump_version(ag_db *db, int64_t id, int64_t base, int64_t *new_version,
                                 ag_error *err);
ag_status ag_models_set_name(ag_db *db, int64_t id, const char *name, ag_error *err);
/* The public-read flag (AG_ERR_NOT_FOUND when there is no such model). */
ag_status ag_models_set_public_read(ag_db *db, int64_t id, int on, ag_error *err);
/* Replaces the model's mesh by a new stored file (the old file is removed by a trigger, see
 * migration 0002) and its stats JSON (NULL = "{}"); *blob (may be NULL) gets the new file's id.
 * AG_ERR_NOT_FOUND when there is no such model. Inside the caller's transaction. */
ag_status ag_models_set_mesh(ag_db *db, int64_t id, const void *mesh, size_t mesh_len,
                             const char *stats_json, int64_t *blob, ag_error *err);
/* Replaces the model's stats JSON (NULL = "{}"), e.g. a point cloud's figures after a
 * segmentation. AG_ERR_NOT_FOUND when there is no such model. Inside the caller's
 * transaction. */
ag_status ag_models_set_stats(ag_db *db, int64_t id, const char *stats_json, ag_error *err);
/* Deletes when the version is `version` (AG_ERR_STALE otherwise); its blobs and ops go too. */
ag_status ag_models_delete(ag_db *db, int64_t id, int64_t version, ag_error *err);

/* *data is malloc'd. */
ag_status ag_blobs_get(ag_db *db, int64_t id, void **data, size_t *len, ag_error *err);

/* Checks a model name: 1..200 characters of valid UTF-8 without control characters. */
ag_status ag_models_check_name(const char *name, ag_error *err);

#endif
