#include "import_job.h"

#include <errno.h>
#include <fcntl.h>
#include <jansson.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include "../io/import.h"
#include "../io/meshblob.h"
#include "../io/meshjson.h"
#include "../store/jobs.h"
#include "../store/models.h"

ag_status ag_import_store_model(ag_db *db, const char *name, const ag_mesh *mesh,
                                const void *source, size_t source_len, const char *source_format,
                                int64_t *model, ag_error *err)
{
    uint8_t *blob = NULL;
    size_t blob_len = 0;
    ag_status s = ag_meshblob_encode(mesh, &blob, &blob_len);
    if (s != AG_OK)
        return ag_error_set(err, s, 0, "cannot encode the mesh");
    json_t *summary = ag_meshjson_summary(mesh);
    char *stats = summary ? json_dumps(summary, JSON_COMPACT) : NULL;
    json_decref(summary);
    if (!stats) {
        free(blob);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory summarising the mesh");
    }
    ag_model_new m = {
        .name = name,
        .stats_json = stats,
        .source = source,
        .source_len = source_len,
        .source_format = source_format,
        .source_media_type = "application/octet-stream",
        .mesh = blob,
        .mesh_len = blob_len,
    };
    s = ag_models_insert(db, &m, model, err);
    free(stats);
    free(blob);
    return s;
}

typedef struct {
    ag_jobctx *ctx;
} parse_progress;

static int on_parse_progress(void *user, double fraction)
{
    parse_progress *p = user;
    return ag_jobctx_progress(p->ctx, 0.05 + 0.8 * fraction, "parse");
}

static ag_up_axis up_from(const char *s)
{
    if (s && (strcmp(s, "z") == 0 || strcmp(s, "Z") == 0))
        return AG_UP_Z;
    if (s && (strcmp(s, "y") == 0 || strcmp(s, "Y") == 0))
        return AG_UP_Y;
    return AG_UP_DEFAULT;
}

static ag_status run(ag_app *app, ag_jobctx *ctx, int64_t job, const char *params_json,
                     ag_error *err)
{
    json_t *params = json_loads(params_json, 0, NULL);
    const char *upload = json_string_value(json_object_get(params, "upload"));
    const char *name = json_string_value(json_object_get(params, "name"));
    const char *format_name = json_string_value(json_object_get(params, "format"));
    const char *filename = json_string_value(json_object_get(params, "filename"));
    ag_up_axis up = up_from(json_string_value(json_object_get(params, "up")));
    ag_status s = AG_OK;
    int fd = -1;
    void *data = MAP_FAILED;
    size_t len = 0;
    ag_mesh *mesh = NULL;

    if (!upload || !name) {
        s = ag_error_set(err, AG_ERR_INTERNAL, 0, "import job without an upload or a name");
        goto done;
    }
    fd = open(upload, O_RDONLY | O_CLOEXEC);
    struct stat st;
    if (fd < 0 || fstat(fd, &st) != 0) {
        s = ag_error_set(err, AG_ERR_IO, 0, "cannot read the uploaded file: %s", strerror(errno));
        goto done;
    }
    len = (size_t)st.st_size;
    if (len == 0) {
        s = ag_error_set(err, AG_ERR_EMPTY, 0, "the uploaded file is empty");
        goto done;
    }
    data = mmap(NULL, len, PROT_READ, MAP_PRIVATE, fd, 0);
    if (data == MAP_FAILED) {
        s = ag_error_set(err, AG_ERR_IO, 0, "cannot map the uploaded file: %s", strerror(errno));
        goto done;
    }
    ag_format format = format_name ? ag_format_from_name(format_name)
                                   : ag_format_sniff(data, len, filename);
    if (format == AG_FORMAT_UNKNOWN) {
        s = format_name ? ag_error_set(err, AG_ERR_UNSUPPORTED, 0, "unknown format \"%s\"",
                                       format_name)
                        : ag_error_set(err, AG_ERR_UNSUPPORTED, 0,
                                       "the file's format could not be recognised; name it "
                                       "with ?format=");
        goto done;
    }
    parse_progress pp = {ctx};
    ag_import_options iopt = {.up = up, .progress = on_parse_progress, .user = &pp};
    if ((s = ag_import_buffer(data, len, format, &iopt, &mesh, err)) != AG_OK)
        goto done;
    if (ag_jobctx_progress(ctx, 0.9, "store")) {
        s = ag_error_set(err, AG_ERR_CANCELLED, 0, "the job was cancelled");
        goto done;
    }

    ag_db *db = ag_app_db(app, err);
    if (!db) {
        s = err ? err->code : AG_ERR_DB;
        goto done;
    }
    if ((s = ag_db_begin(db, err)) != AG_OK)
        goto done;
    int64_t model = 0;
    s = ag_import_store_model(db, name, mesh, data, len, ag_format_name(format), &model, err);
    if (s == AG_OK && ag_jobctx_cancelled(ctx))
        s = ag_error_set(err, AG_ERR_CANCELLED, 0, "the job was cancelled");
    if (s == AG_OK) {
        char result[128];
        snprintf(result, sizeof result, "{\"model\":%lld,\"href\":\"/api/v1/models/%lld\"}",
                 (long long)model, (long long)model);
        s = ag_jobs_finish(db, job, "succeeded", result, NULL, model, err);
    }
    s = s == AG_OK ? ag_db_commit(db, err) : (ag_db_rollback(db), s);
done:
    ag_mesh_free(mesh);
    if (data != MAP_FAILED)
        munmap(data, len);
    if (fd >= 0)
        close(fd);
    json_decref(params);
    return s;
}

const ag_job_kind ag_import_job_kind = {.kind = "import", .run = run,
                                       .cleanup = ag_jobqueue_remove_upload};
