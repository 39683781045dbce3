/* Format detection and one entry point that turns an uploaded file into an ag_mesh. */
#ifndef AG_IMPORT_H
#define AG_IMPORT_H

#include <stddef.h>
#include <stdint.h>

#include "../core/mesh.h"
#include "../core/status.h"
#include "obj.h"

typedef enum {
    AG_FORMAT_UNKNOWN = 0,
    AG_FORMAT_OBJ,
    /* Recognised so a message can name them; importing them is not supported yet. */
    AG_FORMAT_PLY,
    AG_FORMAT_STL,
    AG_FORMAT_GLTF,
    AG_FORMAT_GLB,
    AG_FORMAT_FBX,
    AG_FORMAT_DAE,
} ag_format;

/* "obj" → AG_FORMAT_OBJ; unknown names give AG_FORMAT_UNKNOWN. Case-insensitive. */
ag_format ag_format_from_name(const char *name);
const char *ag_format_name(ag_format f);
/* Guess from content (and an optional file name's extension); AG_FORMAT_UNKNOWN when unsure. */
ag_format ag_format_sniff(const uint8_t *data, size_t len, const char *filename);

typedef struct {
    ag_up_axis up;
    int (*progress)(void *user, double fraction); /* non-zero return cancels */
    void *user;
    /* Whether the input may bring in other files: glTF buffers and images by URI, OBJ
     * mtllib, Collada/FBX textures. Off (0, the default) for everything from the network:
     * only the given bytes and inline data: URIs are read, and any other reference fails
     * with AG_ERR_EXTERNAL_REF naming it (external_ref.h). The CLI turns it on for a file on
     * the user's own disk. Every importer follows it. */
    int allow_external_files;
    /* With allow_external_files: the input's path, so references resolve next to it (NULL:
     * relative to the working directory). */
    const char *source_path;
} ag_import_options;

/* OBJ is read by the built-in reader, PLY, STL, glTF/GLB, FBX and DAE through assimp;
 * AG_FORMAT_UNKNOWN is sniffed from the content. opt may be NULL (the defaults: no external
 * files). */
ag_status ag_import_buffer(const uint8_t *data, size_t len, ag_format fmt,
                           const ag_import_options *opt, ag_mesh **out, ag_error *err);

#endif
