#include "views.h"

#include <stdio.h>
#include <stdlib.h>

static json_t *parse_or_null(const char *text)
{
    if (!text)
        return json_null();
    json_t *v = json_loads(text, JSON_DECODE_ANY, NULL);
    return v ? v : json_null();
}

json_t *ag_view_model(const ag_model_row *row)
{
    char href[64], mesh[80];
    snprintf(href, sizeof href, "/api/v1/models/%lld", (long long)row->id);
    snprintf(mesh, sizeof mesh, "/api/v1/models/%lld/mesh.glb", (long long)row->id);
    return json_pack("{s:I, s:s, s:s, s:I, s:s, s:s, s:s, s:s, s:o, s:o, s:b, s:o}", "id",
                     (json_int_t)row->id, "name", row->name, "kind", row->kind, "version",
                     (json_int_t)row->version, "created_at", row->created_at, "updated_at",
                     row->updated_at, "href", href, "mesh", mesh, "stats",
                     parse_or_null(row->stats_json), "source_format",
                     row->source_format[0] ? json_string(row->source_format) : json_null(),
                     "public_read", row->public_read, "up", parse_or_null(row->up_json));
}

json_t *ag_view_job(const ag_job_row *row)
{
    char href[64];
    snprintf(href, sizeof href, "/api/v1/jobs/%lld", (long long)row->id);
    return json_pack("{s:I, s:s, s:s, s:f, s:o, s:o, s:o, s:s, s:s, s:s}", "id",
                     (json_int_t)row->id, "kind", row->kind, "status", row->status, "progress",
                     row->progress, "stage", row->stage[0] ? json_string(row->stage) : json_null(),
                     "result", parse_or_null(row->result_json), "error",
                     parse_or_null(row->error_json), "created_at", row->created_at, "updated_at",
                     row->updated_at, "href", href);
}

json_t *ag_view_op(const ag_op_row *op)
{
    return json_pack("{s:I, s:s, s:s, s:o, s:s}", "version", (json_int_t)op->version, "author",
                     op->author ? op->author : "", "cid", op->cid ? op->cid : "", "op",
                     parse_or_null(op->body_json), "at", op->at ? op->at : "");
}
