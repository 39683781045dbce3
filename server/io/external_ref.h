/* The one rule every importer follows for files an input refers to (a glTF buffer or image by
 * URI, a Collada or FBX texture, ...): an upload is read from its own bytes and inline data
 * only, and a reference to any other file fails with AG_ERR_EXTERNAL_REF (422, problem
 * "external-reference") naming it. Importers call this to refuse one, so the message is the
 * same everywhere. (An OBJ's mtllib is not such a reference: materials are ignored and the
 * OBJ reader opens nothing, so the mesh imports.) */
#ifndef AG_EXTERNAL_REF_H
#define AG_EXTERNAL_REF_H

#include <stddef.h>

#include "../core/status.h"

/* Refuses the reference name[0..len) found at `where` (e.g. "gltf", "line 3: mtllib"), with
 * element as the line (0 when none). The name is shown bounded, with control characters and
 * non-ASCII bytes replaced by '?' so the message is always valid UTF-8. Returns
 * AG_ERR_EXTERNAL_REF. */
ag_status ag_external_ref_refuse(ag_error *err, long element, const char *where,
                                 const char *name, size_t len);

#endif
