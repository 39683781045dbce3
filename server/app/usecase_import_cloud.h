/* The point cloud import use case: an uploaded PLY, LAS, LAZ or XYZ file (io/cloud_import.h)
 * → a new model of kind "pointcloud" of the workspace (the store: the import job), with
 * every per-point property, its local origin, and a level-of-detail order stored once
 * (core/points/lod.h) so that any point budget a viewer asks for is a prefix of it. The
 * readers read the file's own bytes only: a cloud never makes the service read another file.
 *
 * Progress (to the workspace): "parse" 0.05, "order" 0.6, "store" 0.8. A cloud of more than
 * AG_CLOUD_MAX_POINTS points (app/cloud_state.h), counted from its header, is refused before
 * it is read (AG_ERR_TOO_LARGE); one without points is AG_ERR_EMPTY. */
#ifndef AG_USECASE_IMPORT_CLOUD_H
#define AG_USECASE_IMPORT_CLOUD_H

#include <stdint.h>

#include "usecase_import.h"
#include "workspace.h"

/* Whether src is a point cloud rather than a mesh: its format is named las, laz, xyz (txt,
 * pts); or it is named ply or not named and the content is a cloud (LAS and LAZ signatures,
 * a PLY whose header parses and has no faces, lines of numbers). A file that cannot be read,
 * or a PLY whose header does not parse, is not one (the mesh import then answers it). */
int ag_usecase_import_cloud_accepts(const ag_mesh_source *src);

ag_status ag_usecase_import_cloud_run(ag_workspace *ws, const ag_mesh_source *src,
                                      const char *name, int64_t *model, ag_error *err);

#endif
