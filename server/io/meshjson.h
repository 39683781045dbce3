/* JSON views of a mesh (jansson): the summary used by `archgram info` and model metadata. */
#ifndef AG_MESHJSON_H
#define AG_MESHJSON_H

#include <jansson.h>

#include "../core/mesh.h"

/* {"vertices", "triangles", "components", "groups" (counts), "group_names": [...],
 *  "bounds": {"min":[3], "max":[3]} (null for an empty mesh), "diagonal"} — a new reference. */
json_t *ag_meshjson_summary(const ag_mesh *m);

#endif
