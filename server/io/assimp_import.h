/* glTF/GLB, Collada (DAE), PLY, STL and FBX through libassimp's C API.
 *
 * Every scene node that holds meshes becomes one group (named after the node, or
 * "node_<i>"), with the node's accumulated transform applied. Faces are triangulated;
 * points and lines are dropped. Assimp hands out y-up scenes for glTF, Collada and FBX, so
 * AG_UP_DEFAULT means y for those and z for PLY and STL (CAD convention); an explicit axis
 * overrides. FBX files carry a unit (UnitScaleFactor, centimetres by default) that is turned
 * into metres; the others are taken as metres.
 *
 * assimp sees a file system of one file: the buffer, under the name it opens first (the
 * source path when external files are allowed). Unless opt->allow_external_files is set, every
 * other open (a glTF buffer by URI, a glTF 1 buffer, ...) is refused, and so is a scene whose
 * materials name a texture file it does not embed: the import fails with AG_ERR_EXTERNAL_REF
 * naming the first such reference. data: URIs are decoded by assimp without an open. */
#ifndef AG_ASSIMP_IMPORT_H
#define AG_ASSIMP_IMPORT_H

#include <stddef.h>
#include <stdint.h>

#include "../core/mesh.h"
#include "../core/status.h"
#include "import.h"

typedef struct {
    double scale;    /* applied to reach metres */
    int y_up;        /* the scene was turned from y-up to z-up */
} ag_assimp_info;

ag_status ag_assimp_import_buffer(const uint8_t *data, size_t len, ag_format fmt,
                                  const ag_import_options *opt, ag_mesh **out,
                                  ag_assimp_info *info, ag_error *err);

#endif
