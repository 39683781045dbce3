/* What a part looks like: its grammar derived (the part as it stood in its building), a
 * thumbnail of that (a small PNG: orthographic, flat shaded, seen from the side it faces and a
 * little from above, coloured by label as the client colours them) and its GLB. */
#ifndef AG_PART_MEDIA_H
#define AG_PART_MEDIA_H

#include <stddef.h>
#include <stdint.h>

#include "../core/mesh.h"
#include "../core/parts/part.h"
#include "../core/status.h"

#define AG_PART_THUMBNAIL_SIDE 128

/* The part derived; at most AG_GRAMMAR_MAX_TRIANGLES triangles (AG_ERR_TOO_LARGE). */
ag_status ag_part_media_mesh(const ag_part *p, ag_mesh **out, ag_error *err);
/* An AG_PART_THUMBNAIL_SIDE square PNG of the part (transparent around it); *png malloc'd. */
ag_status ag_part_media_thumbnail(const ag_part *p, uint8_t **png, size_t *len, ag_error *err);
/* A picture of a derived part mesh m (what ag_part_media_thumbnail draws). */
ag_status ag_part_media_picture(const ag_mesh *m, int facing, unsigned side, uint8_t **png,
                                size_t *len, ag_error *err);
/* A derived mesh (a part's, a composition's preview) as GLB, each component's label its
 * group; *glb malloc'd. */
ag_status ag_part_media_mesh_glb(const ag_mesh *m, uint8_t **glb, size_t *len, ag_error *err);
/* The part's GLB, one node per placed terminal with its label; *glb malloc'd. */
ag_status ag_part_media_glb(const ag_part *p, uint8_t **glb, size_t *len, ag_error *err);

#endif
