/* One numbering of split-tree nodes (app/model_tree.h, app/model_state.h): the tree served for
 * a model is its edit model's tree, node for node (nodes[i] is node i, same kind and box;
 * visible nodes name their components, labelled as the mesh groups them, which is what
 * mesh.glb carries), and the reload of what a workspace keeps gives the same tree again —
 * from the kept mesh (the store, after a proceduralization and after an edit without
 * read-back) and from the kept grammar (a folder, after a read-back edit); a tree stored in the
 * numbering before this one is rebuilt when the model is loaded. Every variant of
 * the generated building is checked: several window grids with and without groups, moved to
 * UTM-sized coordinates, turned by a quarter turn and by 30 degrees, and jittered. Kept
 * sessions without a registry load and free a state of their own. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "app/edit_session.h"
#include "app/model_kept.h"
#include "app/model_state.h"
#include "app/model_tree.h"
#include "app/modelops.h"
#include "app/store_ws.h"
#include "store/grammars.h"
#include "store/models.h"
#include "core/edit/edit.h"
#include "core/gen_facade.h"
#include "core/proc/proceduralize.h"
#include "io/meshblob.h"

/* x, y turned by angle about z, then moved by (dx, dy, dz), then jittered (a deterministic
 * pattern of amplitude jitter). */
static void transform(ag_mesh *m, double angle, double dx, double dy, double dz, double jitter)
{
    double c = cos(angle), s = sin(angle);
    if (fabs(angle - M_PI / 2) < 1e-12)
        c = 0, s = 1; /* an exact quarter turn */
    for (size_t v = 0; v < m->nverts; v++) {
        double *p = m->pos + 3 * v;
        double x = p[0], y = p[1];
        double j = jitter * (double)((v * 2654435761u) % 1000) / 1000.0;
        p[0] = c * x - s * y + dx + j;
        p[1] = s * x + c * y + dy - j;
        p[2] += dz + j;
    }
}

/* The kept mesh encoded and decoded, the stored tree text beside it, and the edit model
 * reloaded from both as the store does: the served tree as text. */
static char *tree_after_store_round_trip(const ag_edit_model *kept)
{
    uint8_t *blob = NULL;
    size_t len = 0;
    assert_int_equal(ag_meshblob_encode(kept->proc->mesh, &blob, &len), AG_OK);
    char *stored = ag_model_kept_tree_text(kept);
    assert_non_null(stored);
    ag_mesh *back = NULL;
    ag_error err;
    assert_int_equal(ag_meshblob_decode(blob, len, &back, &err), AG_OK);
    ag_edit_model *em = NULL;
    if (ag_model_state_reload_kept(back, stored, &em, &err))
        fail_msg("reload: %s", err.text);
    char *text = ag_model_tree_served_text(em);
    assert_non_null(text);
    ag_edit_model_free(em);
    ag_mesh_free(back);
    free(stored);
    free(blob);
    return text;
}

/* The served tree is the edit model's tree, node for node, and mesh.glb's metadata names the
 * same nodes and labels. */
static void assert_one_numbering(const ag_edit_model *em, const char *tree_text)
{
    const ag_splittree *t = em->proc->tree;
    const ag_mesh *m = em->proc->mesh;
    json_t *doc = json_loads(tree_text, 0, NULL);
    json_t *nodes = json_object_get(doc, "nodes");
    assert_int_equal(json_array_size(nodes), t->nnodes);
    static const char *const kinds[] = {"root", "split", "component", "pattern", "dead"};
    double diag = ag_box_diagonal(&t->nodes[0].box);
    size_t visible = 0;
    for (size_t i = 0; i < t->nnodes; i++) {
        json_t *jn = json_array_get(nodes, i);
        const ag_tnode *tn = &t->nodes[i];
        assert_int_equal(json_integer_value(json_object_get(jn, "id")), (json_int_t)i);
        assert_string_equal(json_string_value(json_object_get(jn, "kind")), kinds[tn->kind]);
        if (tn->kind == AG_NODE_DEAD) { /* it keeps only its id: nothing else is served */
            assert_int_equal(json_object_size(jn), 2);
            continue;
        }
        json_t *box = json_object_get(jn, "box");
        for (int k = 0; k < 3; k++) {
            assert_true(fabs(json_number_value(json_array_get(box, k)) - tn->box.min[k]) <=
                        1e-9 * diag);
            assert_true(fabs(json_number_value(json_array_get(box, 3 + k)) - tn->box.max[k]) <=
                        1e-9 * diag);
        }
        /* children and parents agree, independently of the tree's own links */
        size_t k;
        json_t *c;
        json_array_foreach(json_object_get(jn, "children"), k, c)
        {
            json_t *child = json_array_get(nodes, (size_t)json_integer_value(c));
            assert_int_equal(json_integer_value(json_object_get(child, "parent")), (json_int_t)i);
        }
        if (json_is_true(json_object_get(jn, "visible"))) {
            assert_int_equal(tn->kind, AG_NODE_COMPONENT);
            json_int_t comp = json_integer_value(json_object_get(jn, "component"));
            assert_true(comp >= 0 && (size_t)comp < m->ncomponents);
            assert_int_equal(t->comp_node[comp], (int32_t)i);
            int32_t g = m->component_group[comp];
            assert_true(g >= 0);
            assert_string_equal(json_string_value(json_object_get(jn, "label")),
                                m->group_names[g]);
            visible++;
        }
    }
    size_t *tris = calloc(m->ncomponents + 1, sizeof *tris);
    ag_mesh_component_triangle_counts(m, tris);
    size_t with_triangles = 0;
    for (size_t c = 0; c < m->ncomponents; c++)
        with_triangles += tris[c] > 0;
    free(tris);
    assert_int_equal(visible, with_triangles);

    ag_glb_component_meta *meta = NULL;
    char *labels = NULL;
    ag_error err;
    assert_int_equal(ag_model_tree_component_meta(tree_text, m->ncomponents, &meta, &labels,
                                                      &err),
                     AG_OK);
    for (size_t c = 0; c < m->ncomponents; c++) {
        if (t->comp_node[c] < 0)
            continue;
        assert_int_equal(meta[c].node, t->comp_node[c]);
        assert_string_equal(meta[c].label, m->group_names[m->component_group[c]]);
    }
    free(meta);
    free(labels);
    json_decref(doc);
}

typedef struct {
    const char *name;
    ag_gen_facade_options facade;
    double angle, dx, dy, dz, jitter;
} variant;

static const variant variants[] = {
    {"5x3 with annex", {.cols = 5, .rows = 3, .annex = 1}, 0, 0, 0, 0, 0},
    {"6x4 back and sides", {.cols = 6, .rows = 4, .back = 1, .side_cols = 3}, 0, 0, 0, 0, 0},
    {"4x2 without groups", {.cols = 4, .rows = 2, .no_groups = 1}, 0, 0, 0, 0, 0},
    {"5x3 at UTM coordinates", {.cols = 5, .rows = 3}, 0, 512345.0, 5812345.0, 31.0, 0},
    {"5x3 turned a quarter", {.cols = 5, .rows = 3, .annex = 1}, M_PI / 2, 0, 0, 0, 0},
    {"4x3 turned 30 degrees", {.cols = 4, .rows = 3}, M_PI / 6, 0, 0, 0, 0},
    {"5x3 jittered", {.cols = 5, .rows = 3}, 0, 0, 0, 0, 1e-7},
};

static void one_numbering_survives_every_reload(void **state)
{
    (void)state;
    for (size_t vi = 0; vi < sizeof variants / sizeof variants[0]; vi++) {
        const variant *v = &variants[vi];
        ag_error err;
        ag_mesh *m = NULL;
        assert_int_equal(ag_gen_facade(&v->facade, &m, &err), AG_OK);
        transform(m, v->angle, v->dx, v->dy, v->dz, v->jitter);

        /* a proceduralization as the job makes it: read back, the derived mesh kept */
        ag_proceduralize_result *r = NULL;
        if (ag_proceduralize_run(m, NULL, &r, &err))
            fail_msg("%s: proceduralize: %s", v->name, err.text);
        ag_edit_model *made = NULL;
        assert_int_equal(ag_edit_model_wrap(r, NULL, &made, &err), AG_OK);
        ag_model_state st;
        if (ag_model_state_make(&made, AG_MODEL_READ_BACK, &st, &err))
            fail_msg("%s: state: %s", v->name, err.text);
        char *tree = ag_model_tree_served_text(st.em);
        assert_one_numbering(st.em, tree);
        char *again = tree_after_store_round_trip(st.em);
        if (strcmp(tree, again) != 0)
            fail_msg("%s: the reloaded tree differs", v->name);
        free(again);
        free(tree);

        /* an edit as the store makes it: no read-back, the edited model's own mesh kept */
        ag_edit_op op = {.kind = AG_EDIT_RESIZE, .node = AG_EDIT_ROOT, .has_scale = 1,
                         .scale = {1.5, 1, 1}};
        ag_edit_model *edited = NULL;
        ag_edit_report rep = {0};
        if (ag_edit_apply_ex(st.em, &op, 0, &edited, &rep, &err))
            fail_msg("%s: edit: %s", v->name, err.text);
        ag_edit_report_clear(&rep);
        ag_model_state kept;
        assert_int_equal(ag_model_state_make(&edited, 0, &kept, &err), AG_OK);
        assert_null(edited); /* moved into the state */
        tree = ag_model_tree_served_text(kept.em);
        assert_one_numbering(kept.em, tree);
        again = tree_after_store_round_trip(kept.em);
        if (strcmp(tree, again) != 0)
            fail_msg("%s: the tree reloaded after an edit differs", v->name);
        /* the kept mesh names the labels as the saved grammar does */
        assert_non_null(strstr(kept.text, "label L1"));
        free(again);
        free(tree);

        /* the same edit as a folder makes it: read back, only the grammar kept */
        if (ag_edit_apply_ex(st.em, &op, 0, &edited, &rep, &err))
            fail_msg("%s: edit: %s", v->name, err.text);
        ag_edit_report_clear(&rep);
        ag_model_state folder, reread;
        assert_int_equal(ag_model_state_make(&edited, AG_MODEL_READ_BACK, &folder, &err), AG_OK);
        ag_edit_model_free(edited);
        long col = 0;
        assert_int_equal(ag_model_state_from_text(folder.text, folder.text_len,
                                                  ag_terminals_set_lookup, &folder.terms,
                                                  NULL, &reread, &err, &col),
                         AG_OK);
        tree = ag_model_tree_served_text(folder.em);
        again = ag_model_tree_served_text(reread.em);
        assert_one_numbering(folder.em, tree);
        if (strcmp(tree, again) != 0)
            fail_msg("%s: the folder's reloaded tree differs", v->name);
        free(tree);
        free(again);

        ag_model_state_clear(&reread);
        ag_model_state_clear(&folder);
        ag_model_state_clear(&kept);
        ag_model_state_clear(&st);
        ag_edit_model_free(made);
        ag_mesh_free(m);
    }
}

static void a_stored_tree_that_is_not_json_is_refused(void **state)
{
    (void)state;
    ag_glb_component_meta *meta = NULL;
    char *labels = NULL;
    ag_error err;
    assert_int_not_equal(ag_model_tree_component_meta("not json", 3, &meta, &labels, &err),
                         AG_OK);
    assert_null(meta);
}

/* A model stored as archgram stored it before this numbering: the derived mesh and a tree in
 * numbering 1. Loading it rebuilds and stores the tree; the kept session is reused while the
 * version stays, and reloaded, to the same tree, after an op moves the version on. */
static void an_old_tree_is_renumbered_and_sessions_are_kept(void **state)
{
    (void)state;
    char path[] = "/tmp/archgram-numbering-XXXXXX";
    int fd = mkstemp(path);
    assert_true(fd >= 0);
    close(fd);
    unlink(path);
    ag_error err;
    ag_db *db = NULL;
    assert_int_equal(ag_db_open(path, NULL, &db, &err), AG_OK);
    ag_events *bus = ag_events_create();
    ag_store_env env = {.db = db, .seq = ag_sequencer_create(bus)};

    ag_mesh *m = NULL;
    assert_int_equal(ag_gen_facade(&(ag_gen_facade_options){.cols = 4, .rows = 2}, &m, &err),
                     AG_OK);
    ag_proceduralize_result *r = NULL;
    assert_int_equal(ag_proceduralize_run(m, NULL, &r, &err), AG_OK);
    ag_mesh *derived = NULL;
    assert_int_equal(ag_grammar_derive(r->grammar, NULL, &derived, &err), AG_OK);
    int64_t model = 0;
    assert_int_equal(ag_db_begin(db, &err), AG_OK);
    assert_int_equal(ag_store_ws_insert_model(db, "old", derived, NULL, 0, NULL, &model, &err),
                     AG_OK);
    ag_model_row row;
    assert_int_equal(ag_models_get(db, model, &row, &err), AG_OK);
    ag_grammar_new g = {.model = model, .version = 1, .mesh_blob = row.mesh_blob,
                        .text = "archgram-grammar 1\n", .text_len = 19,
                        .tree_json = "{\"root\":0,\"nodes\":[]}", .tree_numbering = 1};
    ag_models_row_clear(&row);
    assert_int_equal(ag_grammars_put(db, &g, &err), AG_OK);
    assert_int_equal(ag_db_commit(db, &err), AG_OK);

    ag_edit_state *st = NULL;
    assert_int_equal(ag_edit_session_acquire(NULL, db, model, &st, &err), AG_OK);
    char *want = ag_model_tree_served_text(st->em);
    char *stored = ag_model_kept_tree_text(st->em);
    ag_edit_session_release(NULL, st);
    ag_grammar_row cur;
    assert_int_equal(ag_grammars_current(db, model, 1, &cur, &err), AG_OK);
    assert_int_equal(cur.tree_numbering, AG_MODEL_TREE_NUMBERING);
    /* the stored tree is the served one with what reloads the model kept after it */
    char *served = ag_model_kept_served_text(cur.tree_json);
    assert_string_equal(served, want);
    free(served);
    assert_string_equal(cur.tree_json, stored);
    free(stored);
    ag_grammars_row_clear(&cur);

    /* a registry keeps the loaded model while the version stays the same */
    ag_edit_sessions *reg = ag_edit_sessions_create();
    env.sessions = reg;
    assert_int_equal(ag_edit_session_acquire(reg, db, model, &st, &err), AG_OK);
    const ag_edit_model *first = st->em;
    ag_edit_session_release(reg, st);
    assert_int_equal(ag_edit_session_acquire(reg, db, model, &st, &err), AG_OK);
    assert_ptr_equal(st->em, first);
    ag_edit_session_release(reg, st);
    /* a rename moves the version on: the state is loaded again, to the same tree */
    json_t *rename = json_pack("{s:s, s:s}", "kind", "rename", "name", "renamed");
    ag_op_request rq = {.model = model, .base = 1, .author = "ana", .cid = "r1", .op = rename};
    int64_t v;
    int dup;
    assert_int_equal(ag_modelops_apply(&env, &rq, &v, &dup, &err), AG_OK);
    json_decref(rename);
    assert_int_equal(ag_edit_session_acquire(reg, db, model, &st, &err), AG_OK);
    assert_int_equal(st->version, 2);
    char *again = ag_model_tree_served_text(st->em);
    assert_string_equal(again, want);
    ag_edit_session_release(reg, st);
    free(again);
    free(want);

    ag_edit_sessions_free(reg);
    ag_proceduralize_result_free(r);
    ag_mesh_free(derived);
    ag_mesh_free(m);
    ag_sequencer_free(env.seq);
    ag_events_free(bus);
    ag_db_close(db);
    unlink(path);
    char side[64];
    snprintf(side, sizeof side, "%s-wal", path);
    unlink(side);
    snprintf(side, sizeof side, "%s-shm", path);
    unlink(side);
}

/* What the work beside a state's read-back saw, and what it answers. */
typedef struct {
    const ag_mesh *seen;
    size_t triangles;
    int fail;
} beside_probe;

static ag_status probe_beside(void *user, const ag_mesh *derived, ag_error *err)
{
    beside_probe *p = user;
    p->seen = derived;
    p->triangles = derived->ntris;
    return p->fail ? ag_error_set(err, AG_ERR_INTERNAL, 0, "the probe refused %zu triangles",
                                  derived->ntris)
                   : AG_OK;
}

/* Work beside the read-back (the proceduralization's fidelity check) sees the state's own
 * derivation, with or without read-back, and its failure is the state's, nothing kept. */
static void work_beside_the_read_back_sees_the_derivation(void **state)
{
    (void)state;
    ag_error err;
    ag_mesh *m = NULL;
    assert_int_equal(ag_gen_facade(&(ag_gen_facade_options){.cols = 5, .rows = 3}, &m, &err),
                     AG_OK);
    for (int fail = 0; fail < 2; fail++) {
        for (unsigned flags = 0; flags <= AG_MODEL_READ_BACK; flags++) {
            ag_proceduralize_result *r = NULL;
            assert_int_equal(ag_proceduralize_run(m, NULL, &r, &err), AG_OK);
            ag_edit_model *made = NULL;
            assert_int_equal(ag_edit_model_wrap(r, NULL, &made, &err), AG_OK);
            beside_probe p = {.fail = fail};
            ag_model_state st;
            ag_error_clear(&err);
            ag_status s = ag_model_state_make_beside(&made, flags, probe_beside, &p, &st, &err);
            assert_non_null(p.seen);
            if (fail) {
                assert_int_equal(s, AG_ERR_INTERNAL);
                assert_non_null(strstr(err.text, "the probe refused"));
                assert_null(st.em);
                assert_null(st.derived);
                assert_non_null(made); /* still the caller's */
            } else {
                assert_int_equal(s, AG_OK);
                assert_ptr_equal(p.seen, st.derived);
                assert_int_equal(p.triangles, st.derived->ntris);
                assert_true(p.triangles > 0);
                assert_non_null(st.em);
            }
            ag_model_state_clear(&st);
            ag_edit_model_free(made);
        }
    }
    ag_mesh_free(m);
}

/* A state whose read-back check runs beside the caller is the state ag_model_state_make makes,
 * once checked; a grammar that does not read back is refused by the check, with the line. */
static void a_started_check_is_the_made_state(void **state)
{
    (void)state;
    ag_error err;
    ag_mesh *m = NULL;
    assert_int_equal(ag_gen_facade(&(ag_gen_facade_options){.cols = 6, .rows = 3, .left = 1},
                                   &m, &err),
                     AG_OK);
    for (int broken = 0; broken < 2; broken++) {
        ag_edit_model *a = NULL, *b = NULL;
        assert_int_equal(ag_edit_model_create(m, NULL, &a, &err), AG_OK);
        assert_int_equal(ag_edit_model_create(m, NULL, &b, &err), AG_OK);
        if (broken) { /* a rule name that is no identifier: the text does not parse */
            free(b->proc->grammar->rules[0].name);
            b->proc->grammar->rules[0].name = strdup("not a name");
        }
        ag_model_state made, started;
        assert_int_equal(ag_model_state_make(&a, 0, &made, &err), AG_OK);
        assert_int_equal(ag_model_state_start(&b, 0, &started, &err), AG_OK);
        assert_null(b); /* moved at once */
        assert_non_null(started.em);
        ag_error_clear(&err);
        ag_status s = ag_model_state_checked(&started, &err);
        if (broken) {
            assert_int_equal(s, AG_ERR_INTERNAL);
            assert_non_null(strstr(err.text, "does not read back"));
        } else {
            assert_int_equal(s, AG_OK);
            assert_int_equal(started.text_len, made.text_len);
            assert_memory_equal(started.text, made.text, made.text_len);
            assert_int_equal(started.terms.n, made.terms.n);
            assert_int_equal(started.derived->ntris, made.derived->ntris);
            assert_int_equal(started.derived->ncomponents, made.derived->ncomponents);
            /* checked again: nothing left to wait for */
            assert_int_equal(ag_model_state_checked(&started, &err), AG_OK);
        }
        ag_model_state_clear(&made);
        ag_model_state_clear(&started);
    }
    /* cleared while the check still runs: waited for, nothing leaks */
    ag_edit_model *c = NULL;
    assert_int_equal(ag_edit_model_create(m, NULL, &c, &err), AG_OK);
    ag_model_state running;
    assert_int_equal(ag_model_state_start(&c, 0, &running, &err), AG_OK);
    ag_model_state_clear(&running);
    assert_null(running.check);
    ag_mesh_free(m);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(one_numbering_survives_every_reload),
        cmocka_unit_test(a_stored_tree_that_is_not_json_is_refused),
        cmocka_unit_test(an_old_tree_is_renumbered_and_sessions_are_kept),
        cmocka_unit_test(work_beside_the_read_back_sees_the_derivation),
        cmocka_unit_test(a_started_check_is_the_made_state),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
