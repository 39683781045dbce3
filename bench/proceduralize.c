/* Proceduralization benchmark: a generated ~200k-triangle building and a generated 2M-triangle
 * block (20 buildings of 100k triangles), each in process (per-stage seconds, peak resident
 * memory) and as the whole `archgram proceduralize` process (wall and CPU seconds, the figure
 * a user waits for), then every OBJ mesh in ../shared/data. Not a test.
 *
 * build/bench/proceduralize [--generated] [--keep DIR]
 *   --generated  the generated meshes only
 *   --keep DIR   also keep each generated mesh as DIR/<name>.obj, to profile the CLI on it */
#include <dirent.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "core/gen_facade.h"
#include "core/proc/proceduralize.h"
#include "io/grammar_text.h"
#include "io/obj.h"
#include "io/terminals.h"

#define SHARED AG_REPO_DIR "/../shared/data"

static const char *keep_dir; /* --keep DIR */

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
}

static long peak_mib(void)
{
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    return ru.ru_maxrss / 1024;
}

static void header(void)
{
    printf("%-34s %8s %6s %6s %6s | %7s %7s %7s %7s %7s %7s %7s | %7s %7s %9s %6s\n", "mesh",
           "tris", "comps", "labels", "rules", "import", "segment", "label", "tree", "rules",
           "pattern", "export", "total", "verify", "rel.err", "MiB");
}

static void run(const char *name, ag_mesh *m, double t_import)
{
    ag_proceduralize_options o = {.verify = 1};
    ag_proceduralize_result *r;
    ag_error err = {0};
    double t0 = now();
    if (ag_proceduralize_run(m, &o, &r, &err)) {
        printf("%-34s failed: %s\n", name, err.text);
        return;
    }
    /* text and terminal files in memory, as the export would write them */
    double t1 = now();
    char *text;
    size_t len, tb = 0;
    if (ag_grammar_text_print(r->grammar, &text, &len, &err) == AG_OK)
        free(text);
    for (size_t i = 0; i < r->grammar->nterminals; i++) {
        char *t;
        size_t n;
        if (ag_terminals_format(&r->grammar->terminals[i], &t, &n, &err) == AG_OK) {
            tb += n;
            free(t);
        }
    }
    double t_write = now() - t1;
    double *s = r->seconds;
    double total = t_import + (t1 - t0) - s[AG_STAGE_VERIFY] + t_write;
    printf("%-34s %8zu %6zu %6zu %6zu | %7.3f %7.3f %7.3f %7.3f %7.3f %7.3f %7.3f | %7.3f %7.3f %9.2e "
           "%6ld\n",
           name, m->ntris, r->mesh->ncomponents, r->labels->nlabels, r->grammar->nrules, t_import,
           s[AG_STAGE_SEGMENT], s[AG_STAGE_LABEL], s[AG_STAGE_TREE], s[AG_STAGE_RULES],
           s[AG_STAGE_PATTERNS], s[AG_STAGE_EXPORT] + t_write, total, s[AG_STAGE_VERIFY],
           r->fidelity.relative, peak_mib());
    fflush(stdout);
    ag_proceduralize_result_free(r);
}

static void run_dir(const char *dir, ag_up_axis up)
{
    DIR *d = opendir(dir);
    if (!d) {
        printf("(skipping %s: absent)\n", dir);
        return;
    }
    char **names = NULL;
    size_t n = 0;
    struct dirent *e;
    while ((e = readdir(d))) {
        size_t l = strlen(e->d_name);
        if (l > 4 && !strcmp(e->d_name + l - 4, ".obj")) {
            names = realloc(names, (n + 1) * sizeof *names);
            names[n++] = strdup(e->d_name);
        }
    }
    closedir(d);
    for (size_t i = 0; i < n; i++)
        for (size_t j = i + 1; j < n; j++)
            if (strcmp(names[j], names[i]) < 0) {
                char *t = names[i];
                names[i] = names[j];
                names[j] = t;
            }
    for (size_t i = 0; i < n; i++) {
        char path[1024];
        snprintf(path, sizeof path, "%s/%s", dir, names[i]);
        ag_obj_read_options ro = {.up = up};
        ag_mesh *m;
        ag_error err = {0};
        double t0 = now();
        if (ag_obj_read_file(path, &ro, &m, &err)) {
            printf("%-34s import failed: %s\n", names[i], err.text);
        } else {
            run(names[i], m, now() - t0);
            ag_mesh_free(m);
        }
        free(names[i]);
    }
    free(names);
}

/* `archgram proceduralize path --up z --out <temporary folder>` as a user runs it: wall and
 * CPU seconds of the whole process (CPU as well, the machine may be shared). */
static void run_cli(const char *name, const char *path)
{
    char dir[] = "/tmp/archgram_bench_out_XXXXXX";
    if (!mkdtemp(dir))
        return;
    struct rusage before, after;
    getrusage(RUSAGE_CHILDREN, &before);
    double t0 = now();
    pid_t pid = fork();
    if (pid == 0) {
        int devnull = open("/dev/null", O_WRONLY);
        if (devnull >= 0)
            dup2(devnull, STDOUT_FILENO);
        execl(AG_REPO_DIR "/build/archgram", "archgram", "proceduralize", path, "--up", "z",
              "--out", dir, (char *)NULL);
        _exit(127);
    }
    int status = 0;
    if (pid > 0)
        waitpid(pid, &status, 0);
    double wall = now() - t0;
    getrusage(RUSAGE_CHILDREN, &after);
    double cpu = (after.ru_utime.tv_sec - before.ru_utime.tv_sec) +
                 (after.ru_utime.tv_usec - before.ru_utime.tv_usec) * 1e-6 +
                 (after.ru_stime.tv_sec - before.ru_stime.tv_sec) +
                 (after.ru_stime.tv_usec - before.ru_stime.tv_usec) * 1e-6;
    if (pid < 0 || !WIFEXITED(status) || WEXITSTATUS(status))
        printf("%-34s archgram proceduralize failed (status %d)\n", name, status);
    else
        printf("%-34s whole process: %.2f s wall, %.2f s CPU, peak %ld MiB\n", name, wall, cpu,
               after.ru_maxrss / 1024);
    char cmd[256];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    if (system(cmd)) {
    }
}

/* Writes g to a temporary OBJ and reads it back, so import is timed on a file; then the
 * whole CLI process on that file. Takes g. */
static void run_mesh_file(const char *name, ag_mesh *g)
{
    ag_error err = {0};
    ag_mesh *m;
    char path[] = "/tmp/archgram_bench_XXXXXX.obj";
    int fd = mkstemps(path, 4);
    if (fd < 0) {
        ag_mesh_free(g);
        return;
    }
    close(fd);
    ag_status st = ag_obj_write_file(g, AG_UP_Z, path, &err);
    ag_mesh_free(g);
    ag_obj_read_options ro = {.up = AG_UP_Z};
    double t0 = now();
    if (st == AG_OK)
        st = ag_obj_read_file(path, &ro, &m, &err);
    double t_import = now() - t0;
    if (st) {
        printf("%-34s failed: %s\n", name, err.text);
        unlink(path);
        return;
    }
    run(name, m, t_import);
    ag_mesh_free(m);
    run_cli(name, path);
    if (keep_dir) {
        char kept[1024], *k;
        snprintf(kept, sizeof kept, "%s/%s.obj", keep_dir, name);
        for (k = kept + strlen(keep_dir) + 1; *k; k++)
            if (*k == ' ' || *k == '(' || *k == ')')
                *k = '_';
        if (rename(path, kept))
            printf("%-34s could not keep it as %s\n", name, kept);
    }
    unlink(path);
}

static void run_generated(const char *name, const ag_gen_facade_options *go)
{
    ag_mesh *g;
    ag_error err = {0};
    if (ag_gen_facade(go, &g, &err)) {
        printf("%-34s failed: %s\n", name, err.text);
        return;
    }
    run_mesh_file(name, g);
}

/* A city block: n copies of one building side by side on a grid (60 m apart), each group
 * renamed per building, so the block has n times its components. */
static void run_block(const char *name, const ag_gen_facade_options *go, unsigned n)
{
    ag_mesh *g, *b = ag_mesh_create();
    ag_error err = {0};
    if (!b || ag_gen_facade(go, &g, &err)) {
        printf("%-34s failed: %s\n", name, b ? err.text : "out of memory");
        ag_mesh_free(b);
        return;
    }
    ag_status st = ag_mesh_reserve(b, n * g->nverts, n * g->ntris);
    for (unsigned k = 0; k < n && st == AG_OK; k++) {
        size_t v0 = b->nverts, c0 = b->ncomponents, g0 = b->ngroups;
        for (size_t i = 0; i < g->ngroups && st == AG_OK; i++) {
            char gn[256];
            size_t idx;
            snprintf(gn, sizeof gn, "b%u_%s", k, g->group_names[i]);
            st = ag_mesh_add_group(b, gn, &idx);
        }
        for (size_t c = 0; c < g->ncomponents && st == AG_OK; c++) {
            size_t idx;
            int32_t gr = g->component_group[c];
            st = ag_mesh_add_component(b, gr >= 0 ? (int32_t)(g0 + (size_t)gr) : -1, &idx);
        }
        double dx = 60.0 * (k % 5), dy = 60.0 * (k / 5);
        for (size_t v = 0; v < g->nverts && st == AG_OK; v++)
            st = ag_mesh_add_vertex(b, g->pos[3 * v] + dx, g->pos[3 * v + 1] + dy,
                                    g->pos[3 * v + 2]);
        for (size_t t = 0; t < g->ntris && st == AG_OK; t++)
            st = ag_mesh_add_triangle(b, (uint32_t)(v0 + g->tri[3 * t]),
                                      (uint32_t)(v0 + g->tri[3 * t + 1]),
                                      (uint32_t)(v0 + g->tri[3 * t + 2]),
                                      (uint32_t)(c0 + g->tri_component[t]));
    }
    ag_mesh_free(g);
    if (st) {
        printf("%-34s failed: out of memory\n", name);
        ag_mesh_free(b);
        return;
    }
    run_mesh_file(name, b);
}

int main(int argc, char **argv)
{
    int generated_only = 0;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--generated")) {
            generated_only = 1;
        } else if (!strcmp(argv[i], "--keep") && i + 1 < argc) {
            keep_dir = argv[++i];
        } else {
            fprintf(stderr, "usage: %s [--generated] [--keep DIR]\n", argv[0]);
            return 2;
        }
    }
    header();
    /* 4 facades of 40 x 20 / 30 x 20 windows: ~235k triangles, one group per element */
    ag_gen_facade_options go = {.cols = 40, .rows = 20, .side_cols = 30, .back = 1, .left = 1,
                                .annex = 1};
    run_generated("generated building (groups)", &go);
    /* without groups every box is a component: ~200k triangles, ~17k components */
    go.no_groups = 1;
    go.cols = 34;
    go.side_cols = 26;
    run_generated("generated building (no groups)", &go);
    /* 20 buildings of ~100k triangles and 166 groups each (160 windows of 624 triangles):
     * 1,998,480 triangles in 3,320 groups, 156,920 components once segmentation splits the
     * groups into their loose parts */
    ag_gen_facade_options bo = {.cols = 8, .rows = 5, .side_cols = 8, .back = 1, .left = 1,
                                .annex = 1, .bars = 45};
    run_block("generated block (20 buildings)", &bo, 20);
    if (generated_only)
        return 0;
    run_dir(SHARED "/lod3_ingolstadt/obj", AG_UP_Z);
    run_dir(SHARED "/meshes_0ad", AG_UP_Y);
    printf("seconds: import..export are stages; total = all stages without verify (derive and "
           "compare with the input);\nMiB: peak resident memory of the process so far\n");
    return 0;
}
