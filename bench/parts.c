/* Parts library timings (figures, not pass/fail), median of 11 runs each unless said:
 * - core: save (ag_part_extract) and compose (ag_compose) on a generated ~200k-triangle
 *   building, the operations the service runs on a model in memory;
 * - service: the same building in a store on a temporary database with the edit models kept
 *   as archgramd keeps them (no HTTP): saving a part (the use case on the store workspace:
 *   extraction, thumbnail, one transaction), previewing a compose op (rewrite and derivation)
 *   and the compose op itself (rewrite, the new state: the part grafted into the model's tree,
 *   core/parts/graft.h, or where that does not apply its derivation proceduralized, counted
 *   from the op log; one sequenced commit), with its stages as the op log reports them: the
 *   rewrite, the new state (print, read back, derivation, graft) and the rest (the commit);
 * - search latency over a library of 10,000 parts (FTS5 words, prefixes, tags, deep pages).
 * The service keeps a version's derivation traced (the part save's and the rewrite's map from
 * nodes to grammar sites) for its next saves and compositions: a save line prints the median
 * of the saves after the first and, apart, the first (which traces). Compose ops make a new
 * version each, so each of them traces. A compose line also prints its case's first op: the
 * cases run each on a model of its own (the generated building as proceduralized; the fill
 * after the facade case, on its model), and a case's ops one after another on it: its tree
 * keeps the ids of every node an op removed (dead), so later ops carry more of them, and
 * what earlier ops added.
 * Target: save and compose <= 50 ms each in the service. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <jansson.h>
#include <unistd.h>

#include "app/compose_ops.h"
#include "app/dbpool.h"
#include "app/heap.h"
#include "app/edit_session.h"
#include "app/events.h"
#include "app/modelops.h"
#include "app/sequencer.h"
#include "app/store_ws.h"
#include "app/usecase_compose.h"
#include "app/usecase_proceduralize.h"
#include "app/usecase_save_part.h"
#include "core/gen_facade.h"
#include "core/parts/compose.h"
#include "core/parts/part.h"
#include "core/proc/proceduralize.h"
#include "store/ops.h"
#include "store/parts.h"

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

static int cmp(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

#define RUNS 11

static size_t subtree(const ag_splittree *t, int32_t n)
{
    size_t k = t->nodes[n].kind == AG_NODE_COMPONENT;
    for (int32_t c = t->nodes[n].first_child; c >= 0; c = t->nodes[c].next_sibling)
        k += subtree(t, c);
    return k;
}

/* The nodes benchmarked: the most repeated visible node, the node with the largest subtree,
 * the largest leaf (a blank wall), a facade of another width. */
typedef struct {
    int32_t rep, big, leaf, side;
} picks;

static picks pick(const ag_splittree *t)
{
    picks k = {-1, -1, -1, -1};
    size_t best_rep = 0, best_sub = 0;
    double best_area = 0;
    for (size_t i = 1; i < t->nnodes; i++) {
        const ag_tnode *n = &t->nodes[i];
        if (n->kind != AG_NODE_COMPONENT)
            continue;
        if (n->rule >= 0 && t->rule_count[n->rule] > best_rep) {
            best_rep = t->rule_count[n->rule];
            k.rep = (int32_t)i;
        }
        size_t s = subtree(t, (int32_t)i);
        if (s > best_sub) {
            best_sub = s;
            k.big = (int32_t)i;
        }
        /* a wall: wide and tall */
        double area = fmax(n->box.max[0] - n->box.min[0], n->box.max[1] - n->box.min[1]) *
                      (n->box.max[2] - n->box.min[2]);
        if (n->first_child < 0 && area > best_area) {
            best_area = area;
            k.leaf = (int32_t)i;
        }
    }
    size_t second = 0;
    for (size_t i = 1; k.big >= 0 && i < t->nnodes; i++) {
        if (t->nodes[i].kind != AG_NODE_COMPONENT || (int32_t)i == k.big)
            continue;
        size_t s = subtree(t, (int32_t)i);
        const ag_box *b = &t->nodes[i].box, *bb = &t->nodes[k.big].box;
        double w = b->max[0] - b->min[0] + b->max[1] - b->min[1];
        double wb = bb->max[0] - bb->min[0] + bb->max[1] - bb->min[1];
        if (s > second && w < 0.95 * wb) {
            second = s;
            k.side = (int32_t)i;
        }
    }
    return k;
}

static double median(double *ms, int n)
{
    qsort(ms, (size_t)n, sizeof *ms, cmp);
    return ms[n / 2];
}

static void die(const char *what, const ag_error *err)
{
    fprintf(stderr, "%s: %s\n", what, err->text);
    exit(1);
}

/* --- the service ----------------------------------------------------------------------------- */

typedef struct {
    char path[64];
    ag_dbpool *pool; /* as archgramd keeps its connections (checkpoints off the commits) */
    ag_db *db;
    ag_events *bus;
    ag_store_env env;
    int64_t model, version;
} service;

/* The generated building stored as a new model of the service and proceduralized there;
 * sv->model and sv->version name it. */
static void service_new_model(service *sv, const ag_mesh *m, int report)
{
    ag_error err = {0};
    if (ag_db_begin(sv->db, &err) ||
        ag_store_ws_insert_model(sv->db, "bench", m, NULL, 0, NULL, &sv->model, &err) ||
        ag_db_commit(sv->db, &err))
        die("store the model", &err);
    double t0 = now_ms();
    ag_store_ws w;
    ag_store_ws_init(&w, &(ag_store_ws_options){.env = sv->env, .model = sv->model, .base = 1,
                                                .author = "bench", .cid = "proc"});
    ag_usecase_proceduralize_result pr;
    ag_status s = ag_usecase_proceduralize_run(&w.ws, NULL, &pr, &err);
    ag_store_ws_end(&w, s);
    if (s)
        die("proceduralize in the store", &err);
    sv->version = w.version;
    /* a restarted service loads the model once, at its first edit (not counted below) */
    ag_edit_sessions_free(sv->env.sessions);
    sv->env.sessions = ag_edit_sessions_create();
    double t1 = now_ms();
    ag_edit_state *st;
    if (ag_edit_session_acquire(sv->env.sessions, sv->db, sv->model, &st, &err))
        die("load", &err);
    ag_edit_session_release(sv->env.sessions, st);
    if (report)
        printf("service: stored and proceduralized in %.0f ms, loaded again in %.0f ms (a "
               "restart's first edit; not counted below)\n",
               t1 - t0, now_ms() - t1);
}

static void service_open(service *sv, const ag_mesh *m)
{
    ag_error err = {0};
    snprintf(sv->path, sizeof sv->path, "/tmp/archgram-bench-XXXXXX");
    int fd = mkstemp(sv->path);
    if (fd < 0) {
        perror("mkstemp");
        exit(1);
    }
    close(fd);
    unlink(sv->path);
    if (ag_dbpool_create(sv->path, &sv->pool, &err) || !(sv->db = ag_dbpool_get(sv->pool, &err)))
        die("database", &err);
    sv->bus = ag_events_create();
    sv->env = (ag_store_env){.db = sv->db, .seq = ag_sequencer_create(sv->bus),
                             .sessions = ag_edit_sessions_create()};
    service_new_model(sv, m, 1);
}

static void service_close(service *sv)
{
    ag_edit_sessions_free(sv->env.sessions);
    ag_sequencer_free(sv->env.seq);
    ag_events_free(sv->bus);
    ag_dbpool_free(sv->pool);
    char side[96];
    unlink(sv->path);
    snprintf(side, sizeof side, "%s-wal", sv->path);
    unlink(side);
    snprintf(side, sizeof side, "%s-shm", sv->path);
    unlink(side);
}

/* The model's nodes at its current version (nodes and dead: its tree's size, may be NULL). */
static picks service_picks_sized(service *sv, size_t *nodes, size_t *dead)
{
    ag_error err = {0};
    ag_edit_state *st;
    if (ag_edit_session_acquire(sv->env.sessions, sv->db, sv->model, &st, &err))
        die("acquire", &err);
    const ag_splittree *t = st->em->proc->tree;
    picks k = pick(t);
    if (nodes)
        *nodes = t->nnodes;
    for (size_t i = 0; dead && i < t->nnodes; i++)
        *dead += t->nodes[i].kind == AG_NODE_DEAD;
    sv->version = st->version;
    ag_edit_session_release(sv->env.sessions, st);
    return k;
}

static picks service_picks(service *sv)
{
    return service_picks_sized(sv, NULL, NULL);
}

/* The model's kept trace forgotten, as a new version has none: the next save or composition
 * traces the derivation again. */
static void forget_trace(service *sv)
{
    ag_edit_state *st = NULL;
    if (ag_edit_session_hold(sv->env.sessions, sv->model, &st, NULL) != AG_OK)
        return;
    ag_trace_free(st->trace);
    st->trace = NULL;
    ag_edit_session_release(sv->env.sessions, st);
}

static int64_t service_save(service *sv, int32_t node, const char *what)
{
    double ms[RUNS];
    forget_trace(sv);
    int64_t id = 0;
    ag_usecase_save_part_result r = {0};
    for (int i = 0; i < RUNS; i++) {
        ag_error err = {0};
        ag_part_meta meta = {.name = what};
        ag_store_ws w;
        ag_store_ws_init(&w, &(ag_store_ws_options){.env = sv->env, .model = sv->model,
                                                    .base = sv->version});
        double t0 = now_ms();
        ag_status s = ag_usecase_save_part_run(
            &w.ws, &(ag_usecase_save_part_params){.nodes = &node, .nnodes = 1, .meta = &meta},
            &r, &err);
        ms[i] = now_ms() - t0;
        ag_store_ws_end(&w, s);
        if (s)
            die("save in the service", &err);
        id = w.part_id;
    }
    printf("service save    %-34s %6zu visible nodes: %8.2f ms (extraction %.2f ms; the rest "
           "thumbnail and transaction); the version's first: %.2f ms (its derivation traced)\n",
           what, r.visible, median(ms + 1, RUNS - 1), r.save_ms, ms[0]);
    return id;
}

static json_t *compose_op(int64_t part, int32_t target, const char *mode, const char *scope)
{
    return json_pack("{s:s,s:I,s:i,s:s,s:s}", "kind", "compose", "part", (json_int_t)part,
                     "target", target, "mode", mode, "scope", scope);
}

/* How the op log says the compose op made its new state (report.state, report.fallback). */
typedef struct {
    int grafted;
    char fallback[200];
    double compose_ms, state_ms; /* the rewrite, the new state */
    double tree_ms, mesh_ms, writes_ms; /* the commit: tree text, mesh blob, store writes */
    /* the new state: terminals, grammar text, read back, edit model; inside the graft */
    double st[4], gr[7];
} op_state;

static const char *const state_names[4] = {"terminals_ms", "text_ms", "read_back_ms",
                                           "model_ms"};
static const char *const graft_names[7] = {"components_ms", "removal_ms", "pair_ms",
                                           "classify_ms",   "insert_ms",  "input_ms",
                                           "rebuild_ms"};

static void read_state(void *user, const ag_op_row *row)
{
    op_state *o = user;
    json_t *b = json_loads(row->body_json, 0, NULL);
    json_t *r = json_object_get(b, "report");
    const char *st = json_string_value(json_object_get(r, "state"));
    const char *fb = json_string_value(json_object_get(r, "fallback"));
    o->grafted = st && !strcmp(st, "grafted");
    o->compose_ms = json_number_value(json_object_get(r, "compose_ms"));
    o->state_ms = json_number_value(json_object_get(r, "state_ms"));
    json_t *c = json_object_get(r, "commit");
    o->tree_ms = json_number_value(json_object_get(c, "tree_ms"));
    o->mesh_ms = json_number_value(json_object_get(c, "mesh_ms"));
    o->writes_ms = json_number_value(json_object_get(c, "writes_ms"));
    json_t *ss = json_object_get(r, "state_stages");
    for (int k = 0; k < 4; k++)
        o->st[k] = json_number_value(json_object_get(ss, state_names[k]));
    for (int k = 0; k < 7; k++)
        o->gr[k] = json_number_value(json_object_get(json_object_get(ss, "graft"), graft_names[k]));
    snprintf(o->fallback, sizeof o->fallback, "%s", fb ? fb : "");
    json_decref(b);
}

static void service_compose(service *sv, int64_t part, int which, const char *mode,
                            const char *scope, const char *what)
{
    double pv[RUNS], op[RUNS], rw[RUNS], ns[RUNS], rest[RUNS], tr[RUNS], mb[RUNS], wr[RUNS];
    double st[4][RUNS], gr[7][RUNS];
    int grafted = 0;
    char fallback[200] = "";
    json_t *rep = NULL;
    for (int i = 0; i < RUNS; i++) {
        ag_error err = {0};
        picks k = service_picks(sv); /* node ids of the current version */
        int32_t target = which == 0 ? k.rep : which == 1 ? k.big : k.leaf;
        json_t *o = compose_op(part, target, mode, scope);
        ag_mesh *mesh = NULL;
        json_decref(rep);
        double t0 = now_ms();
        if (ag_compose_ops_preview(&sv->env, sv->model, sv->version, o, &mesh, &rep, &err)) {
            printf("service compose %-34s %-7s %-4s refused: %s\n", what, mode, scope, err.text);
            json_decref(o);
            return;
        }
        pv[i] = now_ms() - t0;
        ag_mesh_free(mesh);
        static int ops;
        char cid[32];
        snprintf(cid, sizeof cid, "c%d", ops++);
        ag_op_request rq = {.model = sv->model, .base = sv->version, .author = "bench",
                            .cid = cid, .op = o};
        int64_t v;
        int dup;
        t0 = now_ms();
        if (ag_modelops_apply(&sv->env, &rq, &v, &dup, &err) || dup)
            die("compose op", &err);
        op[i] = now_ms() - t0;
        json_decref(o);
        sv->version = v;
        op_state os = {0};
        if (ag_ops_each_since(sv->db, sv->model, v - 1, 1, read_state, &os, &err))
            die("op log", &err);
        grafted += os.grafted;
        rw[i] = os.compose_ms;
        ns[i] = os.state_ms;
        rest[i] = op[i] - os.compose_ms - os.state_ms;
        tr[i] = os.tree_ms;
        mb[i] = os.mesh_ms;
        wr[i] = os.writes_ms;
        for (int k = 0; k < 4; k++)
            st[k][i] = os.st[k];
        for (int k = 0; k < 7; k++)
            gr[k][i] = os.gr[k];
        if (!os.grafted)
            snprintf(fallback, sizeof fallback, "%s", os.fallback);
    }
    double first = op[0]; /* before median sorts op */
    printf("service compose %-34s %-7s %-4s %6lld instances: preview %8.2f ms, op %8.2f ms "
           "(the case's first %.2f ms; in the op: rewrite %.1f ms, new state %.1f ms, commit and the rest %.1f ms; "
           "in the preview: loading %.1f ms, rewrite %.1f ms, derivation %.1f ms; the op's new "
           "state grafted in %d of %d runs%s%s)\n",
           what, mode, scope, (long long)json_integer_value(json_object_get(rep, "instances")),
           median(pv, RUNS), median(op, RUNS), first, median(rw, RUNS), median(ns, RUNS),
           median(rest, RUNS), json_real_value(json_object_get(rep, "load_ms")),
           json_real_value(json_object_get(rep, "compose_ms")),
           json_real_value(json_object_get(rep, "state_ms")), grafted, RUNS,
           fallback[0] ? ", else proceduralized: " : "", fallback);
    printf("                the commit: tree text %.1f ms (beside the mesh blob), mesh blob "
           "%.1f ms, store writes %.1f ms (then the sequenced commit)\n",
           median(tr, RUNS), median(mb, RUNS), median(wr, RUNS));
    printf("                the new state: terminals %.1f ms, grammar text %.1f ms, read back "
           "%.1f ms, edit model %.1f ms (graft: components %.1f, removal %.1f, pairing %.1f, "
           "classes %.1f, insertion %.1f, rebuild input %.1f, rebuild %.1f ms)\n",
           median(st[0], RUNS), median(st[1], RUNS), median(st[2], RUNS), median(st[3], RUNS),
           median(gr[0], RUNS), median(gr[1], RUNS), median(gr[2], RUNS), median(gr[3], RUNS),
           median(gr[4], RUNS), median(gr[5], RUNS), median(gr[6], RUNS));
    /* removed nodes keep their ids (dead in the tree): what every later op carries */
    size_t nodes = 0, dead = 0;
    service_picks_sized(sv, &nodes, &dead);
    printf("                after: the model's tree has %zu nodes, %zu of them removed ones\n",
           nodes, dead);
    json_decref(rep);
}

/* 10,000 parts named, tagged and described from small vocabularies (their content is not what
 * a search reads: one tiny entry each), then queries timed over them. */
static void bench_search(service *sv)
{
    static const char *const adj[] = {"sash", "bay", "oriel", "dormer", "casement", "gothic",
                                      "tudor", "modern", "arched", "round"};
    static const char *const noun[] = {"window", "door", "portico", "balcony", "cornice",
                                       "column", "gable", "chimney", "parapet", "frieze"};
    static const char *const tag[] = {"timber", "stone", "brick", "glass", "steel",
                                      "ornament", "classical", "facade"};
    enum { N = 10000 };
    ag_error err = {0};
    double t0 = now_ms();
    if (ag_db_begin(sv->db, &err))
        die("begin", &err);
    for (int i = 0; i < N; i++) {
        char name[96], desc[160];
        snprintf(name, sizeof name, "%s %s %d", adj[i % 10], noun[(i / 10) % 10], i);
        snprintf(desc, sizeof desc, "a %s %s in %s, number %d of the library",
                 adj[(i * 7) % 10], noun[(i * 3) % 10], tag[(i / 3) % 8], i);
        const char *tags[2] = {tag[i % 8], tag[(i / 8) % 8]};
        ag_part_new p = {.version = 1, .name = name, .description = desc, .tags = tags,
                         .ntags = 2, .entry_json = "{}", .thumbnail = "p", .thumbnail_len = 1};
        int64_t id;
        if (ag_parts_insert(sv->db, &p, &id, &err))
            die("insert", &err);
    }
    if (ag_db_commit(sv->db, &err))
        die("commit", &err);
    printf("search: %zu parts in the library (inserted in %.0f ms)\n", ag_parts_count(sv->db),
           now_ms() - t0);
    static const struct {
        const char *q, *tag;
        size_t offset;
        const char *what;
    } queries[] = {
        {NULL, NULL, 0, "first page, no words"},
        {"window", NULL, 0, "a common word (1 part in 10)"},
        {"win", NULL, 0, "a prefix"},
        {"sash window", NULL, 0, "two words"},
        {"4711", NULL, 0, "a rare word (1 part)"},
        {NULL, "stone", 0, "a tag"},
        {"gothic", "timber", 0, "a word and a tag"},
        {"library", NULL, 5000, "every part, a page at offset 5000"},
    };
    enum { QRUNS = 21 };
    for (size_t k = 0; k < sizeof queries / sizeof queries[0]; k++) {
        double ms[QRUNS];
        size_t n = 0;
        int more = 0;
        for (int i = 0; i < QRUNS; i++) {
            ag_part_row *rows;
            ag_parts_query q = {queries[k].q, queries[k].tag, queries[k].offset, 50};
            double t = now_ms();
            if (ag_parts_search(sv->db, &q, &rows, &n, &more, &err))
                die("search", &err);
            ms[i] = now_ms() - t;
            for (size_t j = 0; j < n; j++)
                ag_parts_row_clear(&rows[j]);
            free(rows);
        }
        printf("search %-38s q=%-12s tag=%-7s %2zu hits%s: %6.2f ms (median of %d)\n",
               queries[k].what, queries[k].q ? queries[k].q : "-",
               queries[k].tag ? queries[k].tag : "-", n, more ? "+" : " ", median(ms, QRUNS),
               QRUNS);
    }
}

static void bench_save(const ag_proceduralize_result *r, int32_t node, const char *what,
                       ag_part **keep)
{
    double ms[RUNS];
    ag_part_meta meta = {.name = what};
    for (int i = 0; i < RUNS; i++) {
        ag_part *p = NULL;
        ag_error err = {0};
        double t0 = now_ms();
        if (ag_part_extract(r, node, &meta, &p, &err)) {
            fprintf(stderr, "save %s: %s\n", what, err.text);
            exit(1);
        }
        ms[i] = now_ms() - t0;
        if (i == RUNS - 1)
            *keep = p;
        else
            ag_part_free(p);
    }
    qsort(ms, RUNS, sizeof *ms, cmp);
    printf("save    %-34s node %6d, %6zu visible nodes: %8.2f ms (min %.2f)\n", what, (int)node,
           subtree(r->tree, node), ms[RUNS / 2], ms[0]);
}

static void bench_compose(const ag_proceduralize_result *r, const ag_part *p, int32_t target,
                          int mode, int scope, const char *what)
{
    double ms[RUNS];
    ag_compose_report rep;
    for (int i = 0; i < RUNS; i++) {
        ag_compose_op op = {.target = target, .mode = mode, .scope = scope};
        ag_grammar *g = NULL;
        ag_error err = {0};
        double t0 = now_ms();
        if (ag_compose(r, p, &op, &g, &rep, &err)) {
            fprintf(stderr, "compose %s: %s\n", what, err.text);
            exit(1);
        }
        ms[i] = now_ms() - t0;
        ag_grammar_free(g);
    }
    qsort(ms, RUNS, sizeof *ms, cmp);
    /* the columns the fit re-counted (core/parts/fitcount.h), when it did */
    char cols[48] = "";
    for (int a = 0; a < 3; a++)
        if (rep.fit.columns[a][1])
            snprintf(cols + strlen(cols), sizeof cols - strlen(cols), ", columns %u -> %u",
                     rep.fit.columns[a][0], rep.fit.columns[a][1]);
    printf("compose %-34s %-7s %-4s %6zu instances: %8.2f ms (min %.2f)%s\n", what,
           ag_compose_mode_name(mode), ag_compose_scope_name(scope), rep.instances, ms[RUNS / 2],
           ms[0], cols);
}

/* Which parts run: all, or those named in the arguments (core, save, compose, search), so a
 * profile can look at one. */
static int runs_part(int argc, char **argv, const char *name)
{
    if (argc < 2)
        return 1;
    for (int i = 1; i < argc; i++)
        if (!strcmp(argv[i], name))
            return 1;
    return 0;
}

int main(int argc, char **argv)
{
    ag_heap_keep_large_blocks(); /* as archgramd runs */
    /* every box its own component: 1720 windows of 9 boxes on three facades, a blank back */
    ag_gen_facade_options go = {.cols = 34, .rows = 20, .side_cols = 26, .left = 1, .bars = 3,
                                .no_groups = 1, .annex = 1};
    ag_mesh *m = NULL;
    ag_error err = {0};
    if (ag_gen_facade(&go, &m, &err)) {
        fprintf(stderr, "generate: %s\n", err.text);
        return 1;
    }
    double t0 = now_ms();
    ag_proceduralize_result *r = NULL;
    if (ag_proceduralize_run(m, NULL, &r, &err)) {
        fprintf(stderr, "proceduralize: %s\n", err.text);
        return 1;
    }
    printf("generated building: %zu triangles, %zu components, %zu tree nodes, %zu rules; "
           "proceduralized in %.0f ms (not counted below)\n",
           m->ntris, r->mesh->ncomponents, r->tree->nnodes, r->grammar->nrules, now_ms() - t0);
    picks k = pick(r->tree);
    int32_t rep = k.rep, big = k.big, leaf = k.leaf, side = k.side;
    ag_part *small = NULL, *facade = NULL;
    if (runs_part(argc, argv, "core")) {
    bench_save(r, rep, "a window piece (most repeated)", &small);
    bench_save(r, big, "a facade with its windows", &facade);
    bench_compose(r, small, rep, AG_COMPOSE_REPLACE, AG_COMPOSE_RULE, "window piece into its rule");
    bench_compose(r, small, rep, AG_COMPOSE_REPLACE, AG_COMPOSE_NODE, "window piece into one node");
    bench_compose(r, small, big, AG_COMPOSE_INSERT, AG_COMPOSE_NODE, "window piece under a facade");
    bench_compose(r, small, leaf, AG_COMPOSE_FILL, AG_COMPOSE_NODE, "window piece filling a wall");
    bench_compose(r, facade, leaf, AG_COMPOSE_REPLACE, AG_COMPOSE_NODE, "facade onto the blank wall");
    bench_compose(r, facade, side, AG_COMPOSE_REPLACE, AG_COMPOSE_NODE, "facade onto a narrower wall");
    }
    ag_part_free(small);
    ag_part_free(facade);
    ag_proceduralize_result_free(r);

    service sv;
    service_open(&sv, m);
    picks sk = service_picks(&sv);
    int compose = runs_part(argc, argv, "compose");
    if (compose || runs_part(argc, argv, "save")) {
        int64_t piece = service_save(&sv, sk.rep, "a window piece (most repeated)");
        int64_t facade_part = service_save(&sv, sk.big, "a facade with its windows");
        if (compose) {
            /* each case on a model of its own, the generated building as proceduralized (the
             * parts stay in the library), so that a case's ops do not carry what the cases
             * before it removed and added; but the fill runs on the facade case's model, whose
             * largest leaf is a strip of the composed facades (the blank wall it replaced
             * takes more pieces than one op may make) */
            service_compose(&sv, piece, 0, "replace", "rule", "window piece into its rule");
            service_new_model(&sv, m, 0);
            service_compose(&sv, piece, 0, "replace", "node", "window piece into one node");
            service_new_model(&sv, m, 0);
            service_compose(&sv, facade_part, 2, "replace", "node", "facade onto the blank wall");
            service_compose(&sv, piece, 2, "fill", "node", "window piece filling a wall");
        }
    }
    if (runs_part(argc, argv, "search"))
        bench_search(&sv);
    service_close(&sv);
    ag_mesh_free(m);
    return 0;
}
