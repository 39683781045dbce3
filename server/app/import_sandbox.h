/* Reading an uploaded file with a third-party importer (assimp: glTF, GLB, PLY, STL, FBX,
 * DAE) in a child process, so that a file which makes the importer loop, crash or leak cannot
 * take a worker, its time budget or the service with it (a 189-byte PLY sends assimp 5.2 into
 * a loop that never ends; some malformed ones leak its parser state).
 *
 * The child is forked with the bytes already in memory, reads them (io/import.h; files beside
 * them only when the options allow, as for the command line's own files), writes the mesh in the store's encoding (io/meshblob.h) into a pipe and exits; it
 * touches nothing of the parent's (no connection, no file). The parent waits with a deadline,
 * asks progress now and then (non-zero: cancel) and kills the child on either; the child's
 * address space is capped a few GiB above the parent's (unless built with AddressSanitizer,
 * whose shadow memory would not fit a cap). */
#ifndef AG_IMPORT_SANDBOX_H
#define AG_IMPORT_SANDBOX_H

#include <stddef.h>
#include <stdint.h>

#include "../core/mesh.h"
#include "../core/status.h"
#include "../io/import.h"

/* Extra address space the child may use beyond the parent's. */
#define AG_IMPORT_SANDBOX_EXTRA_BYTES ((size_t)4 << 30)

/* As ag_import_buffer (opt: up axis; its progress callback is called here, in the parent,
 * with the fraction of the time used; seconds <= 0: no deadline). Beyond the
 * importer's own problems: AG_ERR_DEADLINE when reading took longer than `seconds`,
 * AG_ERR_CANCELLED when progress asked, AG_ERR_PARSE when the importer crashed or ran out of
 * memory on the file, AG_ERR_INTERNAL when the child could not run or said nothing. */
ag_status ag_import_sandbox_read(const uint8_t *data, size_t len, ag_format fmt,
                                 const ag_import_options *opt, double seconds, ag_mesh **out,
                                 ag_error *err);

#endif
