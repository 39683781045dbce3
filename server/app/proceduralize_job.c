#include "proceduralize_job.h"

#include <jansson.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "../core/proc/proceduralize.h"
#include "../io/grammar_text.h"
#include "../io/meshblob.h"
#include "../io/terminals.h"
#include "../store/grammars.h"
#include "../store/jobs.h"
#include "../store/models.h"
#include "grammar_edit.h"
#include "modelops.h"

/* Where each stage starts on the job's 0..1 progress scale. */
static const double stage_start[AG_STAGE_COUNT] = {0.02, 0.2, 0.4, 0.5, 0.6, 0.7, 0.8};

static int on_stage(void *user, ag_stage stage)
{
    return ag_jobctx_progress(user, stage_start[stage], ag_proceduralize_stage_name(stage));
}

static json_t *vec3(const double *v)
{
    return json_pack("[f,f,f]", v[0], v[1], v[2]);
}

static char *summary_json(const ag_mesh *in, const ag_proceduralize_result *r, size_t text_len,
                          const ag_terminal_set *terms, const ag_fidelity *fid,
                          const double *verify_s)
{
    const ag_labels *L = r->labels;
    json_t *j = json_object();
    json_object_set_new(j, "source", json_string("proceduralize"));
    json_object_set_new(j, "input",
                        json_pack("{s:I, s:I, s:I, s:I, s:I, s:b}", "triangles",
                                  (json_int_t)in->ntris, "vertices", (json_int_t)in->nverts,
                                  "components", (json_int_t)r->mesh->ncomponents, "groups",
                                  (json_int_t)in->ngroups, "groups_split",
                                  (json_int_t)r->segment.groups_split, "planar_fallback",
                                  r->segment.planar_fallback));
    json_t *labels = json_array();
    for (size_t l = 0; l < L->nlabels; l++) {
        uint32_t ex = L->exemplar[l];
        double size[3];
        for (int a = 0; a < 3; a++)
            size[a] = L->box[ex].max[a] - L->box[ex].min[a];
        char name[32];
        snprintf(name, sizeof name, "L%zu", l + 1);
        json_array_append_new(labels, json_pack("{s:s, s:I, s:I, s:o}", "label", name, "count",
                                                (json_int_t)L->count[l], "triangles",
                                                (json_int_t)L->ntris[ex], "size", vec3(size)));
    }
    json_object_set_new(j, "labels", labels);
    ag_splittree_stats ts = ag_splittree_stats_of(r->tree);
    json_object_set_new(j, "tree",
                        json_pack("{s:I, s:I, s:I, s:I}", "nodes", (json_int_t)ts.nodes,
                                  "visible", (json_int_t)ts.visible, "invisible",
                                  (json_int_t)ts.invisible, "depth", (json_int_t)ts.depth));
    json_object_set_new(j, "rules", json_integer((json_int_t)r->grammar->nrules));
    json_object_set_new(j, "terminals", json_integer((json_int_t)r->grammar->nterminals));
    json_t *patterns = json_array();
    for (size_t p = 0; p < r->tree->npatterns; p++) {
        const ag_pattern *pt = &r->tree->patterns[p];
        int32_t ri = r->info.rule_of_class && pt->rule >= 0 ? r->info.rule_of_class[pt->rule] : -1;
        json_array_append_new(
            patterns,
            json_pack("{s:o, s:[I,I,I], s:o, s:I}", "rule",
                      ri >= 0 ? json_string(r->grammar->rules[ri].name) : json_null(), "counts",
                      (json_int_t)pt->counts[0], (json_int_t)pt->counts[1],
                      (json_int_t)pt->counts[2], "step", vec3(pt->step), "instances",
                      (json_int_t)pt->counts[0] * pt->counts[1] * pt->counts[2]));
    }
    json_object_set_new(j, "patterns", patterns);
    json_object_set_new(j, "grammar_bytes", json_integer((json_int_t)text_len));
    json_object_set_new(j, "terminal_bytes", json_integer((json_int_t)terms->bytes));
    json_object_set_new(j, "fidelity",
                        json_pack("{s:f, s:f, s:I}", "max_error", fid->max_error, "relative",
                                  fid->relative, "unmatched", (json_int_t)fid->unmatched));
    double total = 0;
    json_t *sec = json_object();
    for (int s = 0; s < AG_STAGE_COUNT; s++) {
        double v = s == AG_STAGE_VERIFY ? *verify_s : r->seconds[s];
        json_object_set_new(sec, ag_proceduralize_stage_name((ag_stage)s), json_real(v));
        total += v;
    }
    json_object_set_new(sec, "total", json_real(total));
    json_object_set_new(j, "seconds", sec);
    char *text = json_dumps(j, JSON_COMPACT | JSON_PRESERVE_ORDER | JSON_REAL_PRECISION(10));
    json_decref(j);
    return text;
}

static ag_status load_mesh(ag_db *db, int64_t model, int64_t base, ag_mesh **mesh, ag_error *err)
{
    ag_model_row row;
    ag_status s = ag_models_get(db, model, &row, err);
    if (s != AG_OK)
        return s;
    int64_t version = row.version, blob_id = row.mesh_blob;
    ag_models_row_clear(&row);
    if (version != base)
        return ag_error_set(err, AG_ERR_STALE, (long)version,
                            "model %lld is at version %lld, not %lld", (long long)model,
                            (long long)version, (long long)base);
    void *blob;
    size_t len;
    if ((s = ag_blobs_get(db, blob_id, &blob, &len, err)) != AG_OK)
        return s;
    s = ag_meshblob_decode(blob, len, mesh, err);
    free(blob);
    return s;
}

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
}

static ag_status run(ag_app *app, ag_jobctx *ctx, int64_t job, const char *params_json,
                     ag_error *err)
{
    json_t *params = json_loads(params_json, 0, NULL);
    json_int_t model = json_integer_value(json_object_get(params, "model"));
    json_int_t base = json_integer_value(json_object_get(params, "base"));
    const char *author = json_string_value(json_object_get(params, "author"));
    ag_mesh *mesh = NULL;
    ag_proceduralize_result *r = NULL;
    ag_terminal_set terms = {0};
    ag_grammar_derived d = {0};
    char *text = NULL, *summary = NULL;
    json_t *op = NULL;
    size_t tlen = 0;
    ag_status s;
    if (model <= 0 || base <= 0 || !author) {
        s = ag_error_set(err, AG_ERR_INTERNAL, 0, "proceduralize job without a model or author");
        goto done;
    }
    ag_db *db = ag_app_db(app, err);
    if (!db) {
        s = err ? err->code : AG_ERR_DB;
        goto done;
    }
    if ((s = load_mesh(db, model, base, &mesh, err)) != AG_OK)
        goto done;

    ag_proceduralize_options po = {.progress = on_stage, .user = ctx};
    if ((s = ag_proceduralize_run(mesh, &po, &r, err)) != AG_OK)
        goto done;

    /* verify: the grammar as it will be stored, read back, derives the input */
    if (ag_jobctx_progress(ctx, stage_start[AG_STAGE_VERIFY],
                           ag_proceduralize_stage_name(AG_STAGE_VERIFY))) {
        s = ag_error_set(err, AG_ERR_CANCELLED, 0, "the job was cancelled");
        goto done;
    }
    double t0 = now();
    if ((s = ag_terminals_collect(r->grammar, &terms, err)) != AG_OK ||
        (s = ag_grammar_text_print(r->grammar, &text, &tlen, err)) != AG_OK)
        goto done;
    long col = 0;
    ag_error e;
    ag_error_clear(&e);
    if ((s = ag_grammar_edit_derive(text, tlen, ag_terminals_set_lookup, &terms, &d, &e, &col)) !=
        AG_OK) {
        s = ag_error_set(err, s == AG_ERR_NOMEM ? s : AG_ERR_INTERNAL, 0,
                         "the grammar does not read back (line %ld, column %ld): %s", e.element,
                         col, e.text);
        goto done;
    }
    ag_fidelity fid;
    if ((s = ag_grammar_fidelity(r->mesh, d.mesh, 10 * r->labels->tol, &fid, err)) != AG_OK)
        goto done;
    if (fid.unmatched) {
        s = ag_error_set(err, AG_ERR_INTERNAL, 0,
                         "the grammar does not reproduce %zu of the %zu input triangles; the "
                         "model was left as it was",
                         fid.unmatched, fid.input_triangles);
        goto done;
    }
    double verify_s = now() - t0;
    summary = summary_json(mesh, r, tlen, &terms, &fid, &verify_s);
    op = json_pack("{s:s, s:I, s:I, s:I}", "kind", "proceduralize", "rules",
                   (json_int_t)r->grammar->nrules, "terminals",
                   (json_int_t)r->grammar->nterminals, "patterns",
                   (json_int_t)r->tree->npatterns);
    if (!summary || !op) {
        s = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        goto done;
    }
    if (ag_jobctx_progress(ctx, 0.95, "verify")) {
        s = ag_error_set(err, AG_ERR_CANCELLED, 0, "the job was cancelled");
        goto done;
    }

    ag_modelops_txn t;
    if ((s = ag_modelops_server_begin(app, model, base, &t, err)) != AG_OK) {
        if (s == AG_ERR_STALE)
            ag_error_set(err, AG_ERR_STALE, err ? err->element : 0,
                         "model %lld changed while it was being proceduralized (it is at "
                         "version %ld, the job started from %lld); nothing was stored",
                         (long long)model, err ? err->element : 0, (long long)base);
        goto done;
    }
    s = ag_grammar_edit_store(t.db, model, t.version, &d, text, tlen, summary, err);
    if (s == AG_OK)
        s = ag_grammars_clear_terminals(t.db, model, err);
    for (size_t i = 0; s == AG_OK && i < terms.n; i++)
        s = ag_grammars_put_terminal(t.db, model, terms.path[i], terms.obj[i], terms.len[i], err);
    if (s == AG_OK && ag_jobctx_cancelled(ctx))
        s = ag_error_set(err, AG_ERR_CANCELLED, 0, "the job was cancelled");
    if (s == AG_OK) {
        char result[320];
        snprintf(result, sizeof result,
                 "{\"model\":%lld,\"version\":%lld,\"href\":\"/api/v1/models/%lld\","
                 "\"tree\":\"/api/v1/models/%lld/tree\",\"grammar\":\"/api/v1/models/%lld/"
                 "grammar\"}",
                 (long long)model, (long long)t.version, (long long)model, (long long)model,
                 (long long)model);
        s = ag_jobs_finish(t.db, job, "succeeded", result, NULL, model, err);
    }
    if (s == AG_OK) {
        char cid[48];
        snprintf(cid, sizeof cid, "job-%lld", (long long)job);
        s = ag_modelops_server_commit(&t, author, cid, op, err);
    } else {
        ag_modelops_server_abort(&t);
    }
done:
    json_decref(op);
    free(summary);
    free(text);
    ag_grammar_derived_clear(&d);
    ag_terminals_set_clear(&terms);
    ag_proceduralize_result_free(r);
    ag_mesh_free(mesh);
    json_decref(params);
    return s;
}

const ag_job_kind ag_proceduralize_job_kind = {.kind = "proceduralize", .run = run};
