/* Resize benchmark: least-squares resizes on generated walls of bricks sized for about 2k,
 * 20k and 200k equations (running bond, so neighbours overlap partially and touch), then on
 * the largest real meshes in ../shared/data. Per model: equations and unknowns, the first
 * solve (equations, factorization, solve), a drag re-solve with a new target and the
 * factorization kept, the whole committed edit (solve, emission, re-proceduralization) as the
 * CLI makes it (read back through the grammar) and as the service makes it (no read-back),
 * and the peak resident memory. Then generated buildings of about 20k, 200k and 2M triangles
 * (windows on four facades) through a committed resize as the service makes it, phase by
 * phase: the edited tree (solve and layout), the new model (rebuild.h: no
 * re-proceduralization), the model state (grammar printed and read back), the stored tree
 * (served tree and kept model), the mesh blob, and the commit: the version written to a
 * database of its own and committed (the op log and the broadcast are measured through the
 * service by bench/edit_ws.js). Last, split, remove, paste and join on the
 * same buildings: the edited tree rebuilt (ids kept) against the mesh path they took before.
 * Not a test. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <time.h>

#include <unistd.h>

#include "app/heap.h"
#include "app/store_ws.h"
#include "app/model_kept.h"
#include "app/model_state.h"
#include "core/edit/edit.h"
#include "core/gen_facade.h"
#include "io/meshblob.h"
#include "io/obj.h"
#include "store/db.h"
#include "store/models.h"
#include "edit_targets.h"

#define SHARED AG_REPO_DIR "/../shared/data"

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

static long peak_mib(void)
{
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    return ru.ru_maxrss / 1024;
}

static void add_box(ag_mesh *m, const double lo[3], const double hi[3], int32_t group)
{
    size_t c;
    ag_mesh_add_component(m, group, &c);
    uint32_t b = (uint32_t)m->nverts;
    for (int i = 0; i < 8; i++)
        ag_mesh_add_vertex(m, i & 1 ? hi[0] : lo[0], i & 2 ? hi[1] : lo[1], i & 4 ? hi[2] : lo[2]);
    static const int f[12][3] = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                                 {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
    for (int i = 0; i < 12; i++)
        ag_mesh_add_triangle(m, b + f[i][0], b + f[i][1], b + f[i][2], (uint32_t)c);
}

/* nx bricks per course, nz courses, alternate courses shifted by half a brick; bricks come
 * in three lengths so that they are not all one pattern. */
static ag_mesh *brick_wall(int nx, int nz)
{
    ag_mesh *m = ag_mesh_create();
    static const double len[3] = {0.24, 0.30, 0.36};
    for (int z = 0; z < nz; z++) {
        double x = z & 1 ? -0.12 : 0;
        for (int i = 0; i < nx; i++) {
            char name[32];
            size_t g;
            snprintf(name, sizeof name, "b%d_%d", z, i);
            ag_mesh_add_group(m, name, &g);
            double l = len[(i * 7 + z * 3) % 3];
            double lo[3] = {x, 0, z * 0.07}, hi[3] = {x + l, 0.115, z * 0.07 + 0.07};
            add_box(m, lo, hi, (int32_t)g);
            x += l;
        }
    }
    return m;
}

/* The visible top-level node with the most neighbours: the one whose resize reaches most. */
static int32_t busiest_node(const ag_splittree *t)
{
    size_t *deg = calloc(t->nnodes, sizeof *deg);
    for (size_t k = 0; k < t->nadj; k++) {
        deg[t->adj[2 * k]]++;
        deg[t->adj[2 * k + 1]]++;
    }
    int32_t best = -1;
    for (size_t n = 0; n < t->nnodes; n++)
        if (t->nodes[n].kind == AG_NODE_COMPONENT && (best < 0 || deg[n] > deg[best]))
            best = (int32_t)n;
    free(deg);
    return best;
}

static void run(const char *name, const ag_mesh *m)
{
    ag_error err = {0};
    double t0 = now_ms();
    ag_edit_model *model = NULL;
    if (ag_edit_model_create(m, NULL, &model, &err)) {
        printf("%-28s proceduralize failed: %s\n", name, err.text);
        return;
    }
    double t_proc = now_ms() - t0;
    const ag_splittree *t = model->proc->tree;
    int32_t node = busiest_node(t);
    if (node < 0) {
        printf("%-28s no visible node\n", name);
        ag_edit_model_free(model);
        return;
    }
    /* local mode over the whole building: the area is everything reachable */
    ag_edit_op op = {.kind = AG_EDIT_RESIZE, .node = node, .has_scale = 1,
                     .scale = {1.3, 1, 1.1}, .mode = AG_EDIT_LOCAL, .has_region = 1,
                     .region = t->nodes[0].box};
    ag_edit_report rep = {0};
    ag_box *boxes = NULL;
    t0 = now_ms();
    if (ag_edit_preview(model, &op, &boxes, &rep, &err)) {
        printf("%-28s resize failed: %s\n", name, err.text);
        ag_edit_model_free(model);
        return;
    }
    double t_first = now_ms() - t0;
    free(boxes);
    /* drag: ten new targets, the factorization kept */
    double t_drag = 0;
    for (int k = 1; k <= 10; k++) {
        op.scale[0] = 1.3 + 0.02 * k;
        t0 = now_ms();
        if (ag_edit_preview(model, &op, &boxes, NULL, &err)) {
            printf("%-28s drag failed: %s\n", name, err.text);
            break;
        }
        t_drag = fmax(t_drag, now_ms() - t0);
        free(boxes);
    }
    t0 = now_ms();
    ag_edit_model *out = NULL;
    ag_edit_report rep2 = {0};
    double t_apply = -1;
    if (!ag_edit_apply(model, &op, &out, &rep2, &err))
        t_apply = now_ms() - t0;
    else
        printf("(%s: the commit failed: %s)\n", name, err.text);
    /* the service's commit: the kept model is not read back through its grammar */
    ag_edit_model_free(out);
    out = NULL;
    ag_edit_report_clear(&rep2);
    double t_service = -1;
    t0 = now_ms();
    if (!ag_edit_apply_ex(model, &op, 0, &out, &rep2, &err))
        t_service = now_ms() - t0;
    printf("%-28s %8zu %8zu %8zu | %9.2f %9.2f %9.3f %10.1f %10.1f %9.1f | %8.2g %5ld\n", name,
           m->ntris, rep.equations, rep.unknowns, t_proc, t_first, t_drag, t_apply, t_service,
           rep.solve_ms, rep.max_residual_rel, peak_mib());
    ag_edit_report_clear(&rep);
    ag_edit_report_clear(&rep2);
    ag_edit_model_free(out);
    ag_edit_model_free(model);
}

/* A store of its own for a building's edits (a temporary database, removed when closed): the
 * commit's share of an edit as the service makes it, apart from the socket and the op log. */
typedef struct {
    char dir[256], path[300];
    ag_db *db;
    int64_t model, version;
} bench_store;

static int store_open(bench_store *b, const ag_mesh *m)
{
    memset(b, 0, sizeof *b);
    const char *tmp = getenv("TMPDIR");
    snprintf(b->dir, sizeof b->dir, "%s/archgram-bench-edit-XXXXXX", tmp && tmp[0] ? tmp : P_tmpdir);
    if (!mkdtemp(b->dir))
        return 0;
    snprintf(b->path, sizeof b->path, "%s/edit.db", b->dir);
    ag_error err = {0};
    if (ag_db_open(b->path, NULL, &b->db, &err) != AG_OK || ag_db_begin(b->db, &err) != AG_OK ||
        ag_store_ws_insert_model(b->db, "bench", m, NULL, 0, NULL, &b->model, &err) != AG_OK ||
        ag_db_commit(b->db, &err) != AG_OK) {
        printf("(no store for the commit figures: %s)\n", err.text);
        ag_db_close(b->db);
        b->db = NULL;
        return 0;
    }
    b->version = 1;
    return 1;
}

static void store_close(bench_store *b)
{
    if (!b->dir[0])
        return;
    ag_db_close(b->db);
    char f[320];
    static const char *const ext[] = {"", "-wal", "-shm"};
    for (int i = 0; i < 3; i++) {
        snprintf(f, sizeof f, "%s%s", b->path, ext[i]);
        unlink(f);
    }
    rmdir(b->dir);
}

/* One edit's state stored as a new version and committed (the mesh encoded and the tree
 * printed meanwhile, the state before kept for undo, as commit_change does): its ms, or -1. */
static double store_state(bench_store *b, const ag_model_state *st)
{
    if (!b->db)
        return -1;
    ag_error err = {0};
    double a = now_ms();
    int64_t v = 0;
    ag_status s = ag_db_begin(b->db, &err);
    if (s == AG_OK)
        s = ag_models_bump_version(b->db, b->model, b->version, &v, &err);
    if (s == AG_OK)
        s = ag__store_ws_put_state(b->db, b->model, v, st, "{}", 1, &err);
    s = s == AG_OK ? ag_db_commit(b->db, &err) : (ag_db_rollback(b->db), s);
    if (s != AG_OK) {
        printf("(storing failed: %s)\n", err.text);
        return -1;
    }
    b->version = v;
    return now_ms() - a;
}

/* A committed resize on a generated building, phase by phase, as the service makes it: one
 * window 0.2 m taller in global mode (every window of its rule follows), then the front wall
 * 1.5x wider in global mode. */
static void run_structural(const char *name, const ag_model_state *st);

static void run_generated(const char *name, const ag_gen_facade_options *go, int repeat,
                          int structural)
{
    ag_mesh *m = NULL;
    ag_error err = {0};
    if (ag_gen_facade(go, &m, &err)) {
        printf("%-28s generation failed: %s\n", name, err.text);
        return;
    }
    double t0 = now_ms();
    ag_edit_model *made = NULL;
    ag_model_state st;
    if (ag_edit_model_create(m, NULL, &made, &err) || ag_model_state_make(&made, 0, &st, &err)) {
        printf("%-28s proceduralize failed: %s\n", name, err.text);
        ag_edit_model_free(made);
        ag_mesh_free(m);
        return;
    }
    double t_proc = now_ms() - t0;
    bench_store store;
    store_open(&store, st.em->proc->mesh);
    const ag_splittree *t = st.em->proc->tree;
    int32_t win = -1, wall = -1;
    double wall_area = 0;
    for (size_t n = 0; n < t->nnodes; n++) {
        const ag_box *b = &t->nodes[n].box;
        if (t->nodes[n].kind != AG_NODE_COMPONENT)
            continue;
        double dx = b->max[0] - b->min[0], dz = b->max[2] - b->min[2];
        if (win < 0 && dx < 2 && dz < 3 && dx > 0.5)
            win = (int32_t)n;
        if (dx * dz > wall_area && b->max[1] - b->min[1] < 1) {
            wall_area = dx * dz;
            wall = (int32_t)n;
        }
    }
    for (int k = 0; k < 2 * repeat && win > 0 && wall > 0; k++) {
        ag_edit_op op = {.kind = AG_EDIT_RESIZE, .mode = AG_EDIT_GLOBAL};
        if (k % 2 == 0) {
            op.node = win;
            op.has_box = 1;
            op.box = t->nodes[win].box;
            op.box.max[2] += 0.2;
        } else {
            op.node = wall;
            op.has_scale = 1;
            op.scale[0] = 1.5, op.scale[1] = op.scale[2] = 1;
        }
        ag_edit_report rep = {0};
        ag_edit_model *out = NULL;
        double a = now_ms();
        ag_status s = ag_edit_apply_ex(st.em, &op, 0, &out, &rep, &err);
        double t_edit = now_ms() - a;
        ag_model_state next;
        a = now_ms();
        if (!s)
            s = ag_model_state_make(&out, 0, &next, &err);
        double t_state = now_ms() - a;
        if (s) {
            printf("%-28s %s failed: %s\n", name, k % 2 ? "wall x1.5" : "window taller", err.text);
            ag_edit_model_free(out);
            ag_edit_report_clear(&rep);
            break;
        }
        a = now_ms();
        char *tree = ag_model_kept_tree_text(next.em);
        double t_tree = now_ms() - a;
        a = now_ms();
        uint8_t *blob = NULL;
        size_t len = 0;
        ag_meshblob_encode(next.em->proc->mesh, &blob, &len);
        double t_blob = now_ms() - a;
        double t_store = store_state(&store, &next);
        printf("%-28s %8zu %8zu %-14s | %8.0f | %7.1f %7.1f %7.1f %7.1f %7.1f %7.1f | %7.1f | "
               "%6zu %6zu %5ld\n",
               name, m->ntris, next.em->proc->mesh->ntris, k % 2 ? "wall x1.5" : "window +0.2 m",
               t_proc, rep.solve_ms, t_edit, t_state, t_tree, t_blob, t_store,
               t_edit + t_state + t_store, tree ? strlen(tree) >> 10 : 0, len >> 10, peak_mib());
        free(tree);
        free(blob);
        ag_model_state_clear(&next);
        ag_edit_report_clear(&rep);
    }
    store_close(&store);
    if (structural)
        run_structural(name, &st);
    ag_model_state_clear(&st);
    ag_mesh_free(m);
}

/* Split, remove, paste and join on a generated building as the service makes them: the edited
 * tree rebuilt (node ids kept) against the mesh path they took before (the operation's mesh
 * proceduralized again, every node renumbered). Per op: edit ms (new model), state ms (grammar
 * printed and read back), the mesh path's edit ms, and how many visible nodes' ids still name
 * a node of the same box after each. */
/* Visible nodes of a whose id names a visible node of b with the same box (*visible: of a). */
static size_t same_ids(const ag_splittree *a, const ag_splittree *b, size_t *visible)
{
    size_t same = 0;
    *visible = 0;
    for (size_t n = 0; n < a->nnodes; n++) {
        if (a->nodes[n].kind != AG_NODE_COMPONENT)
            continue;
        (*visible)++;
        if (n >= b->nnodes || b->nodes[n].kind != AG_NODE_COMPONENT)
            continue;
        int eq = 1;
        for (int k = 0; k < 3 && eq; k++)
            eq = fabs(a->nodes[n].box.min[k] - b->nodes[n].box.min[k]) < 1e-9 &&
                 fabs(a->nodes[n].box.max[k] - b->nodes[n].box.max[k]) < 1e-9;
        same += eq;
    }
    return same;
}

static void run_structural(const char *name, const ag_model_state *st)
{
    const ag_splittree *t = st->em->proc->tree;
    int32_t wall, w[2];
    bench_pick_windows_and_wall(t, w, &wall);
    if (wall < 0 || w[0] < 0 || w[1] < 0) {
        printf("%-28s no wall or windows to edit\n", name);
        return;
    }
    const ag_box *W = &t->nodes[wall].box;
    ag_edit_op ops[4] = {
        {.kind = AG_EDIT_SPLIT, .node = wall, .axis = 0, .at = 0.5 * (W->min[0] + W->max[0])},
        {.kind = AG_EDIT_REMOVE, .nnodes = 1, .nodes = &w[0]},
        {.kind = AG_EDIT_PASTE, .node = w[1], .nnodes = 1, .nodes = &w[0],
         .placement = AG_EDIT_REPLACE, .fit = AG_EDIT_DERIVE},
        {.kind = AG_EDIT_JOIN, .nnodes = 2, .nodes = w},
    };
    static const char *const what[4] = {"split wall", "remove window", "paste window",
                                        "join 2 windows"};
    ag_edit_model *em = st->em;
    for (int k = 0; k < 4; k++) {
        ag_error err = {0};
        ag_edit_model *out = NULL;
        double a = now_ms();
        ag_status s = ag_edit_apply_ex(em, &ops[k], 0, &out, NULL, &err);
        double t_edit = now_ms() - a;
        ag_model_state next;
        a = now_ms();
        if (!s)
            s = ag_model_state_make(&out, 0, &next, &err);
        double t_state = now_ms() - a;
        if (s) {
            printf("%-28s %s failed: %s\n", name, what[k], err.text);
            ag_edit_model_free(out);
            continue;
        }
        size_t after = next.em->proc->mesh->ntris, old = 0;
        size_t kept = same_ids(t, next.em->proc->tree, &old);
        ag_model_state_clear(&next);
        a = now_ms();
        s = ag_edit_apply_ex(em, &ops[k], AG_EDIT_MESH_PATH, &out, NULL, &err);
        double t_mesh = now_ms() - a;
        size_t kept_mesh = s ? 0 : same_ids(t, out->proc->tree, &old);
        ag_edit_model_free(out);
        if (s)
            printf("%-28s %s (mesh path) failed: %s\n", name, what[k], err.text);
        printf("%-28s %8zu %8zu %-15s | %7.1f %7.1f | %9.1f | %6zu %6zu of %6zu\n", name,
               st->em->proc->mesh->ntris, after, what[k], t_edit, t_state, t_mesh, kept,
               kept_mesh, old);
    }
}

static void run_file(const char *path, ag_up_axis up)
{
    ag_obj_read_options ro = {.up = up};
    ag_mesh *m = NULL;
    ag_error err = {0};
    if (ag_obj_read_file(path, &ro, &m, &err)) {
        printf("(skipping %s: %s)\n", path, err.text);
        return;
    }
    const char *name = strrchr(path, '/');
    run(name ? name + 1 : path, m);
    ag_mesh_free(m);
}

/* The generated buildings (20k, 200k and 2M triangles). */
static const struct {
    const char *name, *key;
    ag_gen_facade_options go;
} gens[] = {
    {"generated ~20k triangles", "20k", {.cols = 12, .rows = 6, .side_cols = 8, .back = 1, .left = 1}},
    {"generated ~200k triangles", "200k",
     {.cols = 40, .rows = 20, .side_cols = 30, .back = 1, .left = 1, .annex = 1}},
    {"generated ~2M triangles", "2M",
     {.cols = 40, .rows = 20, .side_cols = 30, .back = 1, .left = 1, .annex = 1, .bars = 56}},
};

int main(int argc, char **argv)
{
    ag_heap_keep_large_blocks(); /* as archgramd runs */
    /* edit --write-obj 20k|200k|2M PATH: one generated building as a z-up OBJ (bench/edit_ws.js
     * sends it to the service) */
    if (argc == 4 && !strcmp(argv[1], "--write-obj")) {
        for (size_t i = 0; i < sizeof gens / sizeof *gens; i++) {
            if (strcmp(argv[2], gens[i].key))
                continue;
            ag_mesh *m = NULL;
            ag_error err = {0};
            ag_status s = ag_gen_facade(&gens[i].go, &m, &err);
            if (!s)
                s = ag_obj_write_file(m, AG_UP_Z, argv[3], &err);
            ag_mesh_free(m);
            if (s)
                fprintf(stderr, "edit: %s\n", err.text);
            return s ? 1 : 0;
        }
        fprintf(stderr, "edit: --write-obj takes 20k, 200k or 2M\n");
        return 2;
    }
    /* edit --generated 20k|200k|2M [N]: only that building's committed resizes, N times each
     * (to profile them) */
    if ((argc == 3 || argc == 4) && !strcmp(argv[1], "--generated")) {
        for (size_t i = 0; i < sizeof gens / sizeof *gens; i++)
            if (!strcmp(argv[2], gens[i].key)) {
                run_generated(gens[i].name, &gens[i].go, argc == 4 ? atoi(argv[3]) : 1, 1);
                return 0;
            }
        fprintf(stderr, "edit: --generated takes 20k, 200k or 2M\n");
        return 2;
    }
    printf("%-28s %8s %8s %8s | %9s %9s %9s %10s %10s %9s | %8s %5s\n", "model", "tris",
           "equations", "unknowns", "proc ms", "first ms", "drag ms", "commit ms", "service ms",
           "solve ms", "residual", "MiB");
    static const struct {
        int nx, nz;
    } walls[] = {{22, 18}, {70, 52}, {220, 166}};
    for (size_t i = 0; i < sizeof walls / sizeof *walls; i++) {
        char name[64];
        snprintf(name, sizeof name, "bricks %dx%d", walls[i].nx, walls[i].nz);
        ag_mesh *m = brick_wall(walls[i].nx, walls[i].nz);
        run(name, m);
        ag_mesh_free(m);
    }
    run_file(SHARED "/lod3_ingolstadt/obj/4018267.obj", AG_UP_Z);
    run_file(SHARED "/meshes_0ad/ptol_edfu_struct.obj", AG_UP_Y);

    printf("\ncommitted resize as the service makes it (ms): solve; edit = edited tree + new "
           "model; state = grammar printed and read back; tree = stored tree text; blob = mesh "
           "blob; commit = the version stored in a database and committed (tree and blob made "
           "meanwhile, the state before kept); total = edit + state + commit (the op log and "
           "the broadcast: bench/edit_ws.js)\n");
    printf("%-28s %8s %8s %-14s | %8s | %7s %7s %7s %7s %7s %7s | %7s | %6s %6s %5s\n",
           "building", "tris", "after", "edit", "proc ms", "solve", "edit", "state", "tree", "blob",
           "commit", "total", "treeKB", "blobKB", "MiB");
    for (size_t i = 0; i < sizeof gens / sizeof *gens; i++)
        run_generated(gens[i].name, &gens[i].go, 1, 0);

    printf("\nsplit, remove, paste, join as the service makes them (ms): edit = edited tree + "
           "new model (ids kept); state = grammar printed and read back; mesh path = the "
           "operation's mesh proceduralized again, as before\n");
    printf("%-28s %8s %8s %-15s | %7s %7s | %9s | visible ids naming the same box: kept, "
           "mesh path, of\n",
           "building", "tris", "after", "edit", "edit", "state", "mesh path");
    for (size_t i = 0; i < sizeof gens / sizeof *gens; i++)
        run_generated(gens[i].name, &gens[i].go, 0, 1);
    return 0;
}
