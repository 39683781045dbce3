/* A whole file as read-only bytes: mapped when the file system allows it, else read into
 * memory. For the readers that take a buffer (PLY, LAS, LAZ, XYZ). */
#ifndef AG_FILEMAP_H
#define AG_FILEMAP_H

#include <stddef.h>
#include <stdint.h>

#include "../core/status.h"

typedef struct {
    const uint8_t *data; /* never NULL after a successful open, even for an empty file */
    size_t len;
    void *map;  /* private */
    void *copy; /* private */
} ag_filemap;

/* AG_ERR_IO naming the path when it cannot be opened, is not a regular file or cannot be
 * read; AG_ERR_NOMEM. */
ag_status ag_filemap_open(const char *path, ag_filemap *fm, ag_error *err);
void ag_filemap_close(ag_filemap *fm);

#endif
