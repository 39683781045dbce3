/* Proceduralization benchmark: a generated ~200k-triangle building, then every OBJ mesh in
 * ../shared/data. Prints per-stage seconds and the peak resident memory. Not a test. */
#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <time.h>
#include <unistd.h>

#include "core/gen_facade.h"
#include "core/proc/proceduralize.h"
#include "io/grammar_text.h"
#include "io/obj.h"
#include "io/terminals.h"

#define SHARED AG_REPO_DIR "/../shared/data"

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

/* Generates, writes to a temporary OBJ and reads it back, so import is timed on a file. */
static void run_generated(const char *name, const ag_gen_facade_options *go)
{
    ag_mesh *g, *m;
    ag_error err = {0};
    if (ag_gen_facade(go, &g, &err)) {
        printf("%-34s failed: %s\n", name, err.text);
        return;
    }
    char path[] = "/tmp/archgram_bench_XXXXXX";
    int fd = mkstemp(path);
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
    unlink(path);
    if (st) {
        printf("%-34s failed: %s\n", name, err.text);
        return;
    }
    run(name, m, t_import);
    ag_mesh_free(m);
}

int main(void)
{
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
    run_dir(SHARED "/lod3_ingolstadt/obj", AG_UP_Z);
    run_dir(SHARED "/meshes_0ad", AG_UP_Y);
    printf("seconds: import..export are stages; total = all stages without verify (derive and "
           "compare with the input);\nMiB: peak resident memory of the process so far\n");
    return 0;
}
