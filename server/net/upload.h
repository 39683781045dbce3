/* Spooling an uploaded file to the upload folder while it arrives, never holding it whole
 * in memory: a raw body, or the `file` part of a multipart/form-data body (with an optional
 * `name` part). The size limit is enforced as bytes arrive. */
#ifndef AG_UPLOAD_H
#define AG_UPLOAD_H

#include <stddef.h>

#include "request.h"

typedef struct ag_upload ag_upload;

ag_status ag_upload_begin(ag_request *r, ag_upload **out, ag_error *err);
ag_status ag_upload_feed(ag_upload *u, const char *data, size_t len, ag_error *err);
/* Ends the body; AG_ERR_INVALID when a multipart body had no `file` part. */
ag_status ag_upload_end(ag_upload *u, ag_error *err);
/* Removes the spooled file unless it was handed on with ag_upload_take_path. */
void ag_upload_free(ag_upload *u);

size_t ag_upload_bytes(const ag_upload *u);
/* The form's `name` part / the file part's file name, or NULL. */
const char *ag_upload_form_name(const ag_upload *u);
const char *ag_upload_filename(const ag_upload *u);
/* The name for what r uploads: ?name=, the form's `name` part, the file name without its
 * extension, else fallback. */
void ag_upload_name(ag_request *r, const char *fallback, char *buf, size_t len);
/* The spooled file's path; after this call the file belongs to the caller. */
const char *ag_upload_take_path(ag_upload *u);

/* The spooled body whole, as NUL-terminated text (*text malloc'd; the file is removed):
 * AG_ERR_TOO_LARGE past max bytes, AG_ERR_INVALID when empty (both naming `what`). */
ag_status ag_upload_read_all(ag_request *r, size_t max, const char *what, char **text,
                             size_t *len, ag_error *err);

#endif
