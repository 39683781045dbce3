/* Ops on a model: validation, sequencing by version, idempotent client ids, the log, events;
 * run on a store environment of their own (a connection, a sequencer and its bus), no app. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <jansson.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "app/modelops.h"
#include "app/store_ws.h"
#include "core/mesh.h"
#include "store/models.h"
#include "store/ops.h"

typedef struct {
    ag_db *db;
    ag_events *bus;
    ag_store_env env;
    char dir[64];
    int64_t model;
    int events;
    int64_t last_version;
    uint64_t last_origin;
} fixture;

static void count_event(void *user, const ag_event *ev)
{
    fixture *f = user;
    if (ev->kind != AG_EVENT_OP)
        return;
    f->events++;
    assert_true(ev->version > f->last_version); /* published in version order */
    f->last_version = ev->version;
    f->last_origin = ev->origin;
}

static int setup(void **state)
{
    fixture *f = calloc(1, sizeof *f);
    snprintf(f->dir, sizeof f->dir, "/tmp/archgram-ops-XXXXXX");
    assert_non_null(mkdtemp(f->dir));
    char db[128];
    snprintf(db, sizeof db, "%s/t.db", f->dir);
    ag_error err;
    assert_int_equal(ag_db_open(db, NULL, &f->db, &err), AG_OK);
    f->bus = ag_events_create();
    f->env = (ag_store_env){.db = f->db, .seq = ag_sequencer_create(f->bus)};
    ag_mesh *m = ag_mesh_create();
    size_t c;
    ag_mesh_add_component(m, -1, &c);
    ag_mesh_add_vertex(m, 0, 0, 0);
    ag_mesh_add_vertex(m, 1, 0, 0);
    ag_mesh_add_vertex(m, 0, 1, 0);
    ag_mesh_add_triangle(m, 0, 1, 2, 0);
    ag_db *conn = f->db;
    assert_int_equal(ag_db_begin(conn, &err), AG_OK);
    assert_int_equal(ag_store_ws_insert_model(conn, "Tri", m, NULL, 0, NULL, &f->model, &err),
                     AG_OK);
    assert_int_equal(ag_db_commit(conn, &err), AG_OK);
    ag_mesh_free(m);
    ag_events_subscribe(f->bus, count_event, f);
    *state = f;
    return 0;
}

static int teardown(void **state)
{
    fixture *f = *state;
    ag_sequencer_free(f->env.seq);
    ag_events_free(f->bus);
    ag_db_close(f->db);
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", f->dir);
    assert_int_equal(system(cmd), 0);
    free(f);
    return 0;
}

/* ag_modelops_apply with the request spelt out. */
static ag_status apply(fixture *f, int64_t model, int64_t base, const char *author, const char *cid,
                       const json_t *o, uint64_t origin, int64_t *v, int *dup, ag_error *err)
{
    ag_op_request rq = {.model = model, .base = base, .author = author, .cid = cid, .op = o,
                        .origin = origin};
    return ag_modelops_apply(&f->env, &rq, v, dup, err);
}

static json_t *op(const char *text)
{
    json_t *v = json_loads(text, 0, NULL);
    assert_non_null(v);
    return v;
}

static void validation_names_the_problem(void **state)
{
    (void)state;
    ag_error err;
    json_t *o;
    assert_int_equal(ag_modelops_validate(o = op("{\"kind\":\"rename\",\"name\":\"A\"}"), &err), AG_OK);
    json_decref(o);
    assert_int_equal(ag_modelops_validate(o = op("{\"kind\":\"rename\"}"), &err), AG_ERR_INVALID);
    assert_non_null(strstr(err.text, "name"));
    json_decref(o);
    assert_int_equal(ag_modelops_validate(o = op("{\"kind\":\"rename\",\"name\":\"\"}"), &err),
                     AG_ERR_INVALID);
    json_decref(o);
    assert_int_equal(ag_modelops_validate(o = op("{\"kind\":\"fly\"}"), &err), AG_ERR_INVALID);
    assert_non_null(strstr(err.text, "fly"));
    json_decref(o);
    assert_int_equal(ag_modelops_validate(o = op("{\"kind\":\"note\",\"text\":\"x\",\"y\":1}"), &err),
                     AG_ERR_INVALID);
    assert_non_null(strstr(err.text, "\"y\""));
    json_decref(o);
    assert_int_equal(ag_modelops_validate(o = op("[1]"), &err), AG_ERR_INVALID);
    json_decref(o);
    char big[4100 + 40];
    memset(big, 'a', sizeof big);
    memcpy(big, "{\"kind\":\"note\",\"text\":\"", 23);
    strcpy(big + 23 + 4001, "\"}");
    assert_int_equal(ag_modelops_validate(o = op(big), &err), AG_ERR_INVALID);
    json_decref(o);
}

static void ops_raise_the_version_once_each(void **state)
{
    fixture *f = *state;
    ag_error err;
    int64_t v;
    int dup;
    json_t *rename = op("{\"kind\":\"rename\",\"name\":\"Hall\"}");
    assert_int_equal(apply(f, f->model, 1, "ana", "c1", rename, 7, &v, &dup, &err),
                     AG_OK);
    assert_int_equal(v, 2);
    assert_false(dup);
    assert_int_equal(f->events, 1);
    assert_int_equal(f->last_origin, 7);

    /* Same client id: answered with the first version, not applied again. */
    assert_int_equal(apply(f, f->model, 2, "ana", "c1", rename, 7, &v, &dup, &err),
                     AG_OK);
    assert_int_equal(v, 2);
    assert_true(dup);
    assert_int_equal(f->events, 1);

    /* A stale base is refused and says where the model is. */
    json_t *note = op("{\"kind\":\"note\",\"text\":\"hi\"}");
    assert_int_equal(apply(f, f->model, 1, "bo", "c9", note, 0, &v, &dup, &err),
                     AG_ERR_STALE);
    assert_int_equal(err.element, 2);
    assert_int_equal(apply(f, f->model, 2, "bo", "c9", note, 0, &v, &dup, &err),
                     AG_OK);
    assert_int_equal(v, 3);

    ag_model_row row;
    assert_int_equal(ag_models_get(f->db, f->model, &row, &err), AG_OK);
    assert_string_equal(row.name, "Hall");
    assert_int_equal(row.version, 3);
    ag_models_row_clear(&row);

    assert_int_equal(apply(f, 999, 1, "bo", "c10", note, 0, &v, &dup, &err),
                     AG_ERR_NOT_FOUND);
    assert_int_equal(apply(f, f->model, 3, "bo", "", note, 0, &v, &dup, &err),
                     AG_ERR_INVALID);
    json_decref(rename);
    json_decref(note);
}

static void count_op(void *user, const ag_op_row *row)
{
    int *n = user;
    assert_int_equal(row->version, 2 + *n);
    (*n)++;
}

static void the_log_replays_in_order(void **state)
{
    fixture *f = *state;
    ag_error err;
    int64_t v;
    int dup;
    char cid[16];
    for (int i = 0; i < 5; i++) {
        json_t *note = op("{\"kind\":\"note\",\"text\":\"n\"}");
        snprintf(cid, sizeof cid, "n%d", i);
        assert_int_equal(apply(f, f->model, 1 + i, "ana", cid, note, 0, &v, &dup,
                                           &err),
                         AG_OK);
        json_decref(note);
    }
    int n = 0;
    assert_int_equal(ag_ops_each_since(f->db, f->model, 1, 0, count_op, &n, &err),
                     AG_OK);
    assert_int_equal(n, 5);
    /* Deleting the model takes its log with it; a stale delete is refused first. */
    assert_int_equal(ag_sequencer_delete(f->env.seq, f->db, f->model, 3, &err), AG_ERR_STALE);
    assert_int_equal(ag_sequencer_delete(f->env.seq, f->db, f->model, 6, &err), AG_OK);
    n = 0;
    assert_int_equal(ag_ops_each_since(f->db, f->model, 0, 0, count_op, &n, &err),
                     AG_OK);
    assert_int_equal(n, 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(validation_names_the_problem),
        cmocka_unit_test_setup_teardown(ops_raise_the_version_once_each, setup, teardown),
        cmocka_unit_test_setup_teardown(the_log_replays_in_order, setup, teardown),
    };
    return cmocka_run_group_tests_name("modelops", tests, NULL, NULL);
}
