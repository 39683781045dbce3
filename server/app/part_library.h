/* The store's parts library: parts (core/parts/part.h) written to and read from the tables of
 * store/parts.h whole. A version is kept as its part-bundle entry (io/part_bundle.h) with its
 * terminals by content, a thumbnail (app/part_media.h) and stats; reading a version puts its
 * entry and terminals together as a bundle again and reads that, so what comes back is checked
 * as any bundle is, and a library exports byte for byte what it imported. Every call that
 * writes is one transaction (BEGIN IMMEDIATE): an import stores every part of its bundle or
 * none. */
#ifndef AG_PART_LIBRARY_H
#define AG_PART_LIBRARY_H

#include <stddef.h>
#include <stdint.h>

#include "../core/parts/part.h"
#include "../store/db.h"

/* Where a part saved from a model came from (provenance, never a reference). */
typedef struct {
    int64_t model;
    const char *name;   /* the model's name */
    int64_t version;    /* its version */
} ag_part_library_source;

/* Stores p: a new part (update = 0; its version p->version, 1 for a new part) or a new
 * version of part `update` made on its version base (AG_ERR_STALE otherwise; p->version
 * becomes base + 1). from (may be NULL) sets p's provenance. *id and *version tell where it
 * went. p stays the caller's. */
ag_status ag_part_library_save(ag_db *db, ag_part *p, const ag_part_library_source *from,
                               int64_t update, int64_t base, int64_t *id, int64_t *version,
                               ag_error *err);

/* A part version (0: the newest) read back; AG_ERR_NOT_FOUND names the part or the version. */
ag_status ag_part_library_load(ag_db *db, int64_t id, int64_t version, ag_part **out,
                               ag_error *err);

/* A bundle of parts: ids (n of them; n = 0: every part of the library, at most
 * AG_PART_BUNDLE_MAX_PARTS) at their newest version, or with n = 1 the given version
 * (0: newest). *text malloc'd. */
ag_status ag_part_library_export(ag_db *db, const int64_t *ids, size_t n, int64_t version,
                                 char **text, size_t *len, ag_error *err);

/* Reads a bundle (untrusted: refused whole at the first problem, the element named, nothing
 * stored) and stores each of its parts as a new part; *ids (malloc'd, *n of them) in bundle
 * order. */
ag_status ag_part_library_import(ag_db *db, const char *data, size_t len, int64_t **ids,
                                 size_t *n, ag_error *err);

#endif
