/* Format detection and one entry point that turns an uploaded file into an ag_mesh. */
#ifndef AG_IMPORT_H
#define AG_IMPORT_H

#include <stddef.h>
#include <stdint.h>

#include <jansson.h>

#include "../core/mesh.h"
#include "../core/proc/upaxis.h"
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

/* What the up axis was taken from. */
typedef enum {
    AG_UP_BY_REQUEST = 1, /* the caller said it (--up, ?up=) */
    AG_UP_BY_FILE,        /* the format says it: glTF, Collada and FBX scenes are y-up */
    AG_UP_BY_CONTENT,     /* decided from the geometry (core/proc/upaxis.h) */
    AG_UP_BY_CONVENTION,  /* the content decided nothing: the format's convention (OBJ y,
                             PLY and STL z) */
} ag_up_basis;

typedef struct {
    ag_up_axis axis;              /* AG_UP_Y or AG_UP_Z: what the input was taken as */
    ag_up_basis basis;
    ag_upaxis_evidence evidence;  /* the content's cues, measured whatever the basis */
} ag_up_decision;

/* {"axis": "z", "decided": "content", "evidence": {...}} (schema/openapi.json, UpAxis). */
json_t *ag_import_up_json(const ag_up_decision *d);
const char *ag_import_up_basis_name(ag_up_basis b);

typedef struct {
    /* The input's up axis: AG_UP_Y or AG_UP_Z, or AG_UP_DEFAULT to take it from the format
     * when it says it, else from the content, else from the format's convention. */
    ag_up_axis up;
    /* Filled with the decision and its evidence when not NULL. */
    ag_up_decision *up_decision;
    int (*progress)(void *user, double fraction); /* non-zero return cancels */
    void *user;
    /* Whether the input may bring in other files: glTF buffers and images by URI,
     * Collada/FBX textures (an OBJ's mtllib is ignored either way: the OBJ reader opens no
     * file). Off (0, the default) for everything from the network:
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
