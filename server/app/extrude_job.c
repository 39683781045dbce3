#include "extrude_job.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "store_ws.h"
#include "usecase_extrude.h"

static ag_status read_upload(const char *path, char **data, size_t *len, ag_error *err)
{
    *data = NULL;
    *len = 0;
    FILE *f = fopen(path, "rb");
    if (!f)
        return ag_error_set(err, AG_ERR_IO, 0, "cannot read the uploaded file: %s",
                            strerror(errno));
    ag_status s = AG_OK;
    if (fseek(f, 0, SEEK_END) != 0 || ftell(f) < 0) {
        s = ag_error_set(err, AG_ERR_IO, 0, "cannot read the uploaded file: %s", strerror(errno));
    } else {
        size_t n = (size_t)ftell(f);
        rewind(f);
        char *buf = malloc(n + 1);
        if (!buf)
            s = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory reading the upload");
        else if (fread(buf, 1, n, f) != n) {
            free(buf);
            s = ag_error_set(err, AG_ERR_IO, 0, "cannot read the uploaded file");
        } else {
            buf[n] = '\0';
            *data = buf;
            *len = n;
        }
    }
    fclose(f);
    if (s == AG_OK && *len == 0) {
        free(*data);
        *data = NULL;
        s = ag_error_set(err, AG_ERR_EMPTY, 0, "the uploaded file is empty");
    }
    return s;
}

static ag_status run(void *services, ag_jobctx *ctx, int64_t job, const ag_job_params *p,
                     ag_error *err)
{
    if (p->type != AG_JOB_EXTRUDE)
        return ag_error_set(err, AG_ERR_INTERNAL, 0, "an extrude job without its params");
    const ag_extrude_job *j = &p->u.extrude;
    ag_store_env env;
    ag_status s = ag_store_services_env(services, &env, err);
    char *data = NULL;
    size_t len = 0;
    if (s == AG_OK)
        s = read_upload(j->upload, &data, &len, err);
    if (s != AG_OK)
        return s;
    ag_store_ws w;
    ag_store_ws_init(&w, &(ag_store_ws_options){.env = env, .job = ctx, .job_id = job});
    ag_extrude_input in = {.data = data,
                           .len = len,
                           .name = j->name,
                           .format = j->format,
                           .style = j->style,
                           .height_property = j->height_property,
                           .seed = j->seed,
                           .lonlat = j->lonlat};
    int64_t model = 0;
    s = ag_usecase_extrude_run(&w.ws, &in, &model, err);
    ag_store_ws_end(&w, s);
    free(data);
    return s;
}

const ag_job_kind ag_extrude_job_kind = {.kind = "extrude", .run = run};
