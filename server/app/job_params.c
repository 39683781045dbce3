#include "job_params.h"

#include <jansson.h>
#include <stdlib.h>
#include <string.h>

const char *ag_job_params_kind(ag_job_type type)
{
    switch (type) {
    case AG_JOB_IMPORT:
        return "import";
    case AG_JOB_PROCEDURALIZE:
        return "proceduralize";
    case AG_JOB_EXTRUDE:
        return "extrude";
    case AG_JOB_DEMO_PARTS:
        return "demo-parts";
    case AG_JOB_SEGMENT:
        return "segment";
    default:
        return NULL;
    }
}

char *ag_job_params_encode(const ag_job_params *p)
{
    json_t *j = NULL;
    switch (p->type) {
    case AG_JOB_IMPORT: {
        const ag_import_job *i = &p->u.import;
        j = json_pack("{s:s, s:s, s:s?, s:s?, s:s?}", "upload", i->upload, "name", i->name,
                      "format", i->format, "up", i->up, "filename", i->filename);
        break;
    }
    case AG_JOB_PROCEDURALIZE: {
        const ag_proceduralize_job *q = &p->u.proceduralize;
        j = json_pack("{s:I, s:I, s:s, s:b, s:f, s:s?}", "model", (json_int_t)q->model, "base",
                      (json_int_t)q->base, "author", q->author, "exact", q->exact != 0,
                      "metres_per_unit", q->metres_per_unit, "cloud", q->cloud);
        break;
    }
    case AG_JOB_EXTRUDE: {
        const ag_extrude_job *e = &p->u.extrude;
        j = json_pack("{s:s, s:s, s:s?, s:s, s:s?, s:o, s:o}", "upload", e->upload, "name",
                      e->name, "format", e->format, "style", e->style, "height_property",
                      e->height_property, "seed",
                      e->seed >= 0 ? json_integer((json_int_t)e->seed) : json_null(), "lonlat",
                      e->lonlat > 0 ? json_true() : e->lonlat < 0 ? json_false() : json_null());
        break;
    }
    case AG_JOB_SEGMENT: {
        const ag_segment_job *q = &p->u.segment;
        j = json_pack("{s:I, s:I, s:s, s:f, s:f, s:f, s:b}", "model", (json_int_t)q->model,
                      "base", (json_int_t)q->base, "author", q->author, "threshold",
                      q->threshold, "coarse_threshold", q->coarse_threshold,
                      "cluster_tolerance", q->cluster_tolerance, "recompute_normals",
                      q->recompute_normals);
        break;
    }
    case AG_JOB_DEMO_PARTS: {
        j = json_pack("{s:[]}", "models");
        for (size_t i = 0; j && i < p->u.demo_parts.n; i++)
            json_array_append_new(json_object_get(j, "models"),
                                  json_integer((json_int_t)p->u.demo_parts.models[i]));
        break;
    }
    default:
        j = json_object();
    }
    char *text = j ? json_dumps(j, JSON_COMPACT) : NULL;
    json_decref(j);
    return text;
}

static char *dup_or_null(const char *s)
{
    return s ? strdup(s) : NULL;
}

/* A string member: copied into *out; required ones must be there. 0 on success. */
static int take(const json_t *o, const char *name, int required, char **out)
{
    json_t *v = json_object_get(o, name);
    *out = NULL;
    if (!v || json_is_null(v))
        return required ? -1 : 0;
    if (!json_is_string(v))
        return -1;
    return (*out = strdup(json_string_value(v))) ? 0 : -1;
}

ag_status ag_job_params_decode(const char *kind, const char *json, ag_job_params *out,
                               ag_error *err)
{
    memset(out, 0, sizeof *out);
    json_t *o = json_loads(json ? json : "{}", 0, NULL);
    if (!json_is_object(o)) {
        json_decref(o);
        return ag_error_set(err, AG_ERR_INVALID, 0, "the params of a %s job are not an object",
                            kind);
    }
    int bad = 0;
    if (strcmp(kind, "import") == 0) {
        out->type = AG_JOB_IMPORT;
        ag_import_job *i = &out->u.import;
        bad = take(o, "upload", 1, &i->upload) | take(o, "name", 1, &i->name) |
              take(o, "format", 0, &i->format) | take(o, "up", 0, &i->up) |
              take(o, "filename", 0, &i->filename);
    } else if (strcmp(kind, "proceduralize") == 0) {
        out->type = AG_JOB_PROCEDURALIZE;
        ag_proceduralize_job *q = &out->u.proceduralize;
        json_t *m = json_object_get(o, "model"), *b = json_object_get(o, "base");
        json_t *x = json_object_get(o, "exact");
        q->model = json_integer_value(m);
        q->base = json_integer_value(b);
        q->exact = json_is_true(x);
        /* absent in the jobs of earlier versions: decided from the content */
        q->metres_per_unit = json_number_value(json_object_get(o, "metres_per_unit"));
        bad = !json_is_integer(m) || !json_is_integer(b) || q->model <= 0 || q->base <= 0 ||
              take(o, "author", 1, &q->author) | take(o, "cloud", 0, &q->cloud);
    } else if (strcmp(kind, "segment") == 0) {
        out->type = AG_JOB_SEGMENT;
        ag_segment_job *q = &out->u.segment;
        json_t *m = json_object_get(o, "model"), *b = json_object_get(o, "base");
        q->model = json_integer_value(m);
        q->base = json_integer_value(b);
        q->threshold = json_number_value(json_object_get(o, "threshold"));
        q->coarse_threshold = json_number_value(json_object_get(o, "coarse_threshold"));
        q->cluster_tolerance = json_number_value(json_object_get(o, "cluster_tolerance"));
        q->recompute_normals = json_is_true(json_object_get(o, "recompute_normals"));
        bad = !json_is_integer(m) || !json_is_integer(b) || q->model <= 0 || q->base <= 0 ||
              take(o, "author", 1, &q->author);
    } else if (strcmp(kind, "extrude") == 0) {
        out->type = AG_JOB_EXTRUDE;
        ag_extrude_job *e = &out->u.extrude;
        json_t *seed = json_object_get(o, "seed"), *ll = json_object_get(o, "lonlat");
        e->seed = json_is_integer(seed) ? json_integer_value(seed) : -1;
        e->lonlat = json_is_true(ll) ? 1 : json_is_false(ll) ? -1 : 0;
        bad = take(o, "upload", 1, &e->upload) | take(o, "name", 1, &e->name) |
              take(o, "format", 0, &e->format) | take(o, "style", 1, &e->style) |
              take(o, "height_property", 0, &e->height_property);
    } else if (strcmp(kind, "demo-parts") == 0) {
        out->type = AG_JOB_DEMO_PARTS;
        ag_demo_parts_job *dp = &out->u.demo_parts;
        json_t *m = json_object_get(o, "models");
        bad = !json_is_array(m) || json_array_size(m) > AG_DEMO_PARTS_MAX_MODELS;
        for (size_t i = 0; !bad && i < json_array_size(m); i++) {
            json_t *id = json_array_get(m, i);
            bad = !json_is_integer(id) || json_integer_value(id) <= 0;
            dp->models[dp->n++] = json_integer_value(id);
        }
    } else {
        out->type = AG_JOB_TEST;
    }
    json_decref(o);
    if (bad) {
        ag_job_params_clear(out);
        return ag_error_set(err, AG_ERR_INVALID, 0, "the params of a %s job are incomplete",
                            kind);
    }
    return AG_OK;
}

ag_status ag_job_params_copy(ag_job_params *dst, const ag_job_params *src, ag_error *err)
{
    *dst = *src;
    int bad = 0;
#define DUP(field) \
    (dst->field = dup_or_null(src->field), bad |= src->field && !dst->field)
    switch (src->type) {
    case AG_JOB_IMPORT:
        DUP(u.import.upload), DUP(u.import.name), DUP(u.import.format), DUP(u.import.up),
            DUP(u.import.filename);
        break;
    case AG_JOB_PROCEDURALIZE:
        DUP(u.proceduralize.author), DUP(u.proceduralize.cloud);
        break;
    case AG_JOB_SEGMENT:
        DUP(u.segment.author);
        break;
    case AG_JOB_EXTRUDE:
        DUP(u.extrude.upload), DUP(u.extrude.name), DUP(u.extrude.format),
            DUP(u.extrude.style), DUP(u.extrude.height_property);
        break;
    default:
        break;
    }
#undef DUP
    if (bad) {
        ag_job_params_clear(dst);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    return AG_OK;
}

void ag_job_params_clear(ag_job_params *p)
{
    if (!p)
        return;
    switch (p->type) {
    case AG_JOB_IMPORT:
        free(p->u.import.upload), free(p->u.import.name), free(p->u.import.format),
            free(p->u.import.up), free(p->u.import.filename);
        break;
    case AG_JOB_PROCEDURALIZE:
        free(p->u.proceduralize.author), free(p->u.proceduralize.cloud);
        break;
    case AG_JOB_SEGMENT:
        free(p->u.segment.author);
        break;
    case AG_JOB_EXTRUDE:
        free(p->u.extrude.upload), free(p->u.extrude.name), free(p->u.extrude.format),
            free(p->u.extrude.style), free(p->u.extrude.height_property);
        break;
    default:
        break;
    }
    memset(p, 0, sizeof *p);
}

const char *ag_job_params_upload(const ag_job_params *p)
{
    return p->type == AG_JOB_IMPORT    ? p->u.import.upload
           : p->type == AG_JOB_EXTRUDE ? p->u.extrude.upload
                                       : NULL;
}
