/* The parts library's tables (migration 0006): parts with their newest metadata and tags,
 * every version as its part-bundle entry (schema/part_bundle.md) with provenance, a thumbnail
 * and stats, the terminal OBJ texts by the SHA-256 of their content (stored once for the
 * whole library, however many versions use them), and the full-text index (SQLite FTS5) over
 * names, tags and descriptions. Provenance names the source model without referring to it:
 * deleting that model leaves its parts whole. Every write runs inside the caller's
 * transaction (ag_db_begin). */
#ifndef AG_STORE_PARTS_H
#define AG_STORE_PARTS_H

#include <stddef.h>
#include <stdint.h>

#include "db.h"

#define AG_PARTS_QUERY_MAX 200 /* bytes of a search text */

typedef struct {
    const char *sha256; /* 64 lowercase hex digits of obj's SHA-256 */
    const char *obj;
    size_t len;
} ag_part_terminal_text;

/* One version of a part as it is stored. */
typedef struct {
    unsigned version;           /* insert: any >= 1; add_version: the base + 1 */
    const char *name;           /* the metadata of this version, searched while it is newest */
    const char *description;    /* may be NULL */
    const char *const *tags;
    size_t ntags;
    const char *entry_json;     /* its entry of a part bundle */
    const ag_part_terminal_text *terminals; /* every terminal the entry names */
    size_t nterminals;
    int64_t source_model;       /* 0: none (a part imported from a bundle) */
    const char *source_name;    /* may be NULL */
    int64_t source_version;
    int64_t source_node;
    const void *thumbnail;      /* PNG */
    size_t thumbnail_len;
    const char *stats_json;     /* NULL = "{}" */
} ag_part_new;

typedef struct {
    int64_t id;
    char *name, *description; /* malloc'd; description "" when none */
    size_t ntags;
    char **tags;              /* malloc'd, in their order */
    int64_t version;          /* the newest */
    char created_at[32], updated_at[32];
} ag_part_row;

typedef struct {
    int64_t part, version;
    char *entry_json;         /* malloc'd when asked for, else NULL */
    int64_t source_model;     /* 0 when none */
    char *source_name;        /* malloc'd, NULL when none */
    int64_t source_version, source_node;
    char *stats_json;         /* malloc'd */
    size_t thumbnail_bytes;
    char created_at[32];
} ag_part_version_row;

void ag_parts_row_clear(ag_part_row *row);
void ag_parts_version_row_clear(ag_part_version_row *row);

/* A new part whose only version is p->version; *id its id. */
ag_status ag_parts_insert(ag_db *db, const ag_part_new *p, int64_t *id, ag_error *err);
/* A new version of part id made on version base: AG_ERR_STALE (the newest version in
 * err->element) when base is not the newest, AG_ERR_NOT_FOUND without the part. The part's
 * name, description and tags become this version's. */
ag_status ag_parts_add_version(ag_db *db, int64_t id, int64_t base, const ag_part_new *p,
                               ag_error *err);

ag_status ag_parts_get(ag_db *db, int64_t id, ag_part_row *row, ag_error *err);
/* Every version of the part, newest first, without entries; *rows malloc'd (clear each). */
ag_status ag_parts_versions(ag_db *db, int64_t id, ag_part_version_row **rows, size_t *n,
                            ag_error *err);
/* One version (0: the newest); AG_ERR_NOT_FOUND names the part or the version. */
ag_status ag_parts_get_version(ag_db *db, int64_t id, int64_t version, int with_entry,
                               ag_part_version_row *row, ag_error *err);
/* Calls each(user, sha256, obj, len) for every terminal of the version; a failure it returns
 * stops the walk and is returned. */
ag_status ag_parts_each_terminal(ag_db *db, int64_t id, int64_t version,
                                 ag_status (*each)(void *user, const char *sha256,
                                                   const char *obj, size_t len),
                                 void *user, ag_error *err);
/* The version's thumbnail; *png malloc'd. */
ag_status ag_parts_thumbnail(ag_db *db, int64_t id, int64_t version, void **png, size_t *len,
                             ag_error *err);

typedef struct {
    const char *q;   /* words matched against names, tags and descriptions (each a prefix,
                        all of them); NULL or blank: every part */
    const char *tag; /* parts with this tag exactly; NULL: any */
    size_t offset, limit;
} ag_parts_query;
/* Parts matching the query, the best matches first (by id when there is no text), at most
 * limit from offset; *more says whether more follow. AG_ERR_INVALID for a text longer than
 * AG_PARTS_QUERY_MAX bytes or with more than 16 words. */
ag_status ag_parts_search(ag_db *db, const ag_parts_query *q, ag_part_row **rows, size_t *n,
                          int *more, ag_error *err);

/* Deletes the part with every version when its newest version is `version` (AG_ERR_STALE
 * otherwise); terminals no other version uses go with it. */
ag_status ag_parts_delete(ag_db *db, int64_t id, int64_t version, ag_error *err);

size_t ag_parts_count(ag_db *db);
/* Terminal texts stored for the whole library (each content once). */
size_t ag_parts_count_terminals(ag_db *db);

#endif
