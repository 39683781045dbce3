#include "part_media.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../core/raster.h"
#include "../io/glb.h"
#include "../io/image_png.h"
#include "model_state.h"
#include "model_tree.h"

ag_status ag_part_media_mesh(const ag_part *p, ag_mesh **out, ag_error *err)
{
    *out = NULL;
    ag_grammar_derive_options o = {.max_triangles = AG_GRAMMAR_MAX_TRIANGLES};
    return ag_grammar_derive(p->grammar, &o, out, err);
}

/* "#rrggbb" to bytes. */
static void parse_colour(const char *hex, uint8_t rgb[3])
{
    unsigned v = 0x8a8a8a;
    if (hex[0] == '#')
        sscanf(hex + 1, "%6x", &v);
    rgb[0] = (uint8_t)(v >> 16);
    rgb[1] = (uint8_t)(v >> 8);
    rgb[2] = (uint8_t)v;
}

ag_status ag_part_media_picture(const ag_mesh *m, int facing, unsigned side, uint8_t **png,
                                size_t *len, ag_error *err)
{
    *png = NULL;
    *len = 0;
    uint8_t(*rgb)[3] = m->ngroups ? malloc(m->ngroups * sizeof *rgb) : NULL;
    if (m->ngroups && !rgb)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    for (size_t g = 0; g < m->ngroups; g++) {
        char hex[8];
        ag_model_tree_label_color(m->group_names[g], hex);
        parse_colour(hex, rgb[g]);
    }
    /* seen from the side it faces, from its left and a little from above */
    static const double out[4][2] = {{1, 0}, {0, 1}, {-1, 0}, {0, -1}};
    const double *n = out[facing & 3];
    double left[2] = {-n[1], n[0]};
    ag_raster_view v = {.dir = {-(n[0] + 0.45 * left[0]), -(n[1] + 0.45 * left[1]), -0.35},
                        .up = {0, 0, 1},
                        .margin = 0.06,
                        .group_rgb = (const uint8_t(*)[3])rgb,
                        .ngroups = m->ngroups,
                        .colour = {0x8a, 0x8a, 0x8a}};
    ag_raster_image im;
    ag_status s = ag_raster_mesh(m, &v, side, side, &im, err);
    if (s == AG_OK)
        s = ag_image_png_encode(&im, png, len, err);
    ag_raster_image_clear(&im);
    free(rgb);
    return s;
}

ag_status ag_part_media_thumbnail(const ag_part *p, uint8_t **png, size_t *len, ag_error *err)
{
    *png = NULL;
    *len = 0;
    ag_mesh *m = NULL;
    ag_status s = ag_part_media_mesh(p, &m, err);
    if (s == AG_OK)
        s = ag_part_media_picture(m, p->facing, AG_PART_THUMBNAIL_SIDE, png, len, err);
    ag_mesh_free(m);
    return s;
}

ag_status ag_part_media_mesh_glb(const ag_mesh *m, uint8_t **glb, size_t *len, ag_error *err)
{
    *glb = NULL;
    /* each component's label is its group: a derivation groups components by label */
    ag_glb_component_meta *meta = m->ncomponents ? calloc(m->ncomponents, sizeof *meta) : NULL;
    if (m->ncomponents && !meta)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    for (size_t c = 0; c < m->ncomponents; c++) {
        int32_t g = m->component_group[c];
        meta[c].label = g >= 0 ? m->group_names[g] : NULL;
        meta[c].node = -1;
    }
    ag_status s = ag_glb_write_meta(m, meta, m->ncomponents, glb, len, err);
    free(meta);
    return s;
}

ag_status ag_part_media_glb(const ag_part *p, uint8_t **glb, size_t *len, ag_error *err)
{
    *glb = NULL;
    ag_mesh *m = NULL;
    ag_status s = ag_part_media_mesh(p, &m, err);
    if (s == AG_OK)
        s = ag_part_media_mesh_glb(m, glb, len, err);
    ag_mesh_free(m);
    return s;
}
