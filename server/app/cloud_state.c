#include "cloud_state.h"

#include <math.h>
#include <stdlib.h>

void ag_cloud_state_clear(ag_cloud_state *st)
{
    if (!st)
        return;
    ag_cloud_free(st->cloud);
    ag_segment_cloud_free(st->seg);
    st->cloud = NULL;
    st->seg = NULL;
    st->had_normals = 0;
}

static json_t *vec3(const double *v)
{
    return json_pack("[f,f,f]", v[0], v[1], v[2]);
}

json_t *ag_cloud_state_stats(const ag_cloud *c, const char *positions_encoding)
{
    double lo[3], hi[3];
    ag_cloud_bounds(c, lo, hi);
    json_t *j = json_pack("{s:I, s:o, s:b, s:s, s:b}", "points", (json_int_t)c->n, "offset",
                          vec3(c->offset), "normals", c->normals != NULL, "positions",
                          positions_encoding ? positions_encoding : "f64", "segmented", 0);
    if (!j)
        return NULL;
    if (c->scale[0] > 0 && c->scale[1] > 0 && c->scale[2] > 0)
        json_object_set_new(j, "scale", vec3(c->scale));
    if (c->n)
        json_object_set_new(j, "bounds", json_pack("{s:o, s:o}", "min", vec3(lo), "max", vec3(hi)));
    json_t *props = json_array();
    for (size_t p = 0; props && p < c->nprops; p++)
        json_array_append_new(props, json_pack("{s:s, s:s}", "name", c->props[p].name, "type",
                                               ag_scalar_name(c->props[p].type)));
    json_object_set_new(j, "properties", props ? props : json_array());
    return j;
}

json_t *ag_cloud_state_segmentation(const ag_segment_cloud_result *r, int with_run)
{
    size_t none = 0;
    for (size_t i = 0; i < r->n; i++)
        none += r->segment[i] < 0;
    json_t *j = json_pack("{s:I, s:I, s:I, s:I, s:I, s:I, s:I, s:f, s:f}", "points",
                          (json_int_t)r->n, "segments", (json_int_t)ag_segment_cloud_in_use(r),
                          "planes",
                          (json_int_t)r->nplanes, "clusters", (json_int_t)r->nclusters,
                          "pieces", (json_int_t)r->npieces, "labels", (json_int_t)r->nlabels,
                          "unsegmented", (json_int_t)none, "diagonal",
                          isfinite(r->diagonal) ? r->diagonal : 0.0, "spacing",
                          isfinite(r->spacing) ? r->spacing : 0.0);
    if (!j)
        return NULL;
    /* ids below it may be in use; the next new segment gets it */
    json_object_set_new(j, "segment_ids", json_integer((json_int_t)r->nsegments));
    if (!with_run)
        return j;

    json_object_set_new(j, "coarse_threshold", json_real(r->coarse_threshold));
    json_object_set_new(j, "fine_threshold", json_real(r->fine_threshold));
    json_object_set_new(j, "cluster_tolerance", json_real(r->cluster_tolerance));
    json_t *sec = json_object();
    double total = 0;
    for (int s = 0; sec && s < AG_SEGMENT_CLOUD_STAGES; s++) {
        json_object_set_new(sec, ag_segment_cloud_stage_name((ag_segment_cloud_stage)s),
                            json_real(r->seconds[s]));
        total += r->seconds[s];
    }
    if (sec)
        json_object_set_new(sec, "total", json_real(total));
    json_object_set_new(j, "seconds", sec ? sec : json_object());
    return j;
}

static const char *const FIGURES[] = {"segments", "segment_ids", "planes", "clusters", "pieces",
                                      "labels", "unsegmented", NULL};

json_t *ag_cloud_state_stats_segmented(json_t *stats, const json_t *seg)
{
    if (!stats)
        return NULL;
    json_object_set_new(stats, "segmented", json_boolean(seg != NULL));
    for (const char *const *f = FIGURES; *f; f++) {
        json_t *v = seg ? json_object_get(seg, *f) : NULL;
        if (v)
            json_object_set(stats, *f, v);
        else
            json_object_del(stats, *f);
    }
    return stats;
}
