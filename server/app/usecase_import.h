/* The import use case: a mesh file of any importable format (io/import.h) → a new model of
 * the workspace (the store: the import job). The reading half is shared with every
 * `archgram` command that takes a mesh file. */
#ifndef AG_USECASE_IMPORT_H
#define AG_USECASE_IMPORT_H

#include <stddef.h>
#include <stdint.h>

#include "../core/mesh.h"
#include "../io/import.h"
#include "../io/obj.h"
#include "../core/status.h"
#include "workspace.h"

typedef struct {
    const char *path;
    const char *format;      /* a format name; NULL: sniffed from the content and file name */
    const char *filename;    /* the name the file came with, for sniffing; NULL: path */
    ag_up_axis up;
    /* How problems name the file ("the uploaded file"); NULL: they do not (the caller puts the
     * path in front, as `archgram` does). */
    const char *what;
    /* Appended when the format is not recognised ("name it with ?format="); NULL: the
     * importer's own message for content it cannot place. */
    const char *format_hint;
    /* Non-zero for a person's own file (the CLI): the files it refers to (an OBJ's mtllib, a
     * glTF's buffers) are read from next to it. Zero (uploads): no other file is ever read. */
    int own_file;
    /* A format read by assimp (anything but OBJ) is always read in a child process
     * (app/import_sandbox.h), so that a file that crashes assimp is refused rather than taking
     * the program down; > 0: the child is killed after this many seconds (the service's
     * uploads), 0: no deadline (the CLI). */
    double sandbox_seconds;
} ag_mesh_source;

/* The file, mapped, while its mesh is used. */
typedef struct {
    void *data;
    size_t len;
    const char *format; /* the format read */
    ag_up_decision up;  /* the up axis the mesh was read with, why, and the content's cues */
} ag_mesh_file;

/* Maps src's file (the checks and messages of ag_usecase_import_read: AG_ERR_IO, AG_ERR_EMPTY);
 * file->format stays NULL. Shared with the point cloud import (app/usecase_import_cloud.h). */
ag_status ag_usecase_import_map(const ag_mesh_source *src, ag_mesh_file *file, ag_error *err);

/* Reads src into *mesh; progress (may be NULL) gets the parsed fraction and may cancel.
 * AG_ERR_IO for a file that cannot be read (strerror), AG_ERR_EMPTY for an empty one,
 * AG_ERR_UNSUPPORTED for an unknown format, the reader's errors (with the line) otherwise.
 * Release the file with ag_usecase_import_release. */
ag_status ag_usecase_import_read(const ag_mesh_source *src, int (*progress)(void *, double),
                                 void *user, ag_mesh **mesh, ag_mesh_file *file, ag_error *err);
void ag_usecase_import_release(ag_mesh_file *file);

/* Reads src and stores it as a new model named name (progress to the workspace: "parse" from
 * 0.05 to 0.85, "store" at 0.9). */
ag_status ag_usecase_import_run(ag_workspace *ws, const ag_mesh_source *src, const char *name,
                                int64_t *model, ag_error *err);

#endif
