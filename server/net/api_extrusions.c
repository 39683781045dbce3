/* Extrusions over REST: POST /api/v1/extrusions (an upload becomes an extrude job) and
 * GET /api/v1/models/{id}/plan (the stored building descriptions). Plan and profile edits
 * are ops (POST …/ops, websocket), see app/plan_edit.h. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "../app/app_jobs.h"
#include "../app/app_query.h"
#include "routes.h"
#include "upload.h"

/* The query parameters as job params (without the upload), or a problem. */
static ag_status job_params(ag_request *r, char *name, size_t name_len, ag_extrude_job *p,
                            ag_error *err)
{
    ag_upload_name(r, "extrusion", name, name_len);
    const char *format = ag_request_query(r, "format");
    const char *ctype = ag_request_header(r, MHD_HTTP_HEADER_CONTENT_TYPE);
    if (!format && ctype && strncasecmp(ctype, "application/geo+json", 20) == 0)
        format = "geojson";
    *p = (ag_extrude_job){.name = name,
                          .format = (char *)format,
                          .style = (char *)ag_request_query(r, "style"),
                          .height_property = (char *)ag_request_query(r, "height_property"),
                          .seed = -1};
    ag_status s = ag_app_jobs_check_extrude(p, err);
    if (s != AG_OK)
        return s;
    const char *sv = ag_request_query(r, "seed");
    if (sv) {
        char *end;
        long long n = strtoll(sv, &end, 10);
        if (!*sv || *end || n < 0)
            return ag_error_set(err, AG_ERR_INVALID, 0, "seed must be a whole number >= 0");
        p->seed = n;
    }
    const char *lv = ag_request_query(r, "lonlat");
    if (lv) {
        if (strcmp(lv, "true") == 0 || strcmp(lv, "1") == 0)
            p->lonlat = 1;
        else if (strcmp(lv, "false") == 0 || strcmp(lv, "0") == 0)
            p->lonlat = -1;
        else
            return ag_error_set(err, AG_ERR_INVALID, 0, "lonlat must be true or false");
    }
    return AG_OK;
}

enum MHD_Result ag_api_extrusions_create(ag_request *r)
{
    ag_error err;
    ag_error_clear(&err);
    char name[1024];
    ag_extrude_job p;
    ag_status s = job_params(r, name, sizeof name, &p, &err);
    if (s == AG_OK && ag_upload_bytes(r->upload) == 0)
        s = ag_error_set(&err, AG_ERR_INVALID, 0,
                         "the request has no body: send a building description or GeoJSON "
                         "footprints (or a multipart \"file\" part)");
    if (s != AG_OK)
        return ag_reply_problem(r, s, &err);
    p.upload = (char *)ag_upload_take_path(r->upload);
    int64_t job = 0;
    s = ag_app_jobs_extrude(r->cfg->app, &r->who, &p, &job, &err);
    return ag_reply_new_job(r, s, job, &err);
}

enum MHD_Result ag_api_model_plan(ag_request *r)
{
    ag_error err;
    json_t *doc;
    int64_t version;
    ag_status s = ag_app_query_plan(r->cfg->app, r->ids[0], &doc, &version, &err);
    if (s != AG_OK)
        return ag_reply_problem(r, s, &err);
    char etag[32];
    snprintf(etag, sizeof etag, "\"%lld\"", (long long)version);
    return ag_reply_json(r, 200, doc, etag);
}
