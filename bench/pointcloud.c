/* Point cloud benchmark: per-stage seconds and peak memory of reading, normals and
 * segmentation on the real clouds in ../shared/data and on generated buildings of 100k,
 * 500k and 1.8M points (area-uniform sampling with noise), and of cutting the AHN3 tile;
 * then of the whole pipeline (segmentation with its normals, repetition, consensus, tree,
 * grammar: core/points/proceduralize_cloud.h) on the same clouds, and of the consensus
 * models of 54 same-label windows of the 1.8M-point building (Algorithm 1, each member
 * registered once to the base).
 * Each case runs in a child process so that its peak resident memory is its own. Each
 * case prints wall seconds per stage, then a line of processor seconds per stage: on a
 * shared machine wall time also counts the waiting for a processor. Not a test. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/time.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "core/points/consensus.h"
#include "core/points/cut.h"
#include "core/points/proceduralize_cloud.h"
#include "core/points/gen_building.h"
#include "core/points/segment_cloud.h"
#include "io/cloud_import.h"
#include "io/footprints.h"

#define SHARED AG_REPO_DIR "/../shared/data"

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
}

static void header(void)
{
    printf("%-28s %9s %7s |", "cloud", "points", "read");
    for (int s = 0; s < AG_SEGMENT_CLOUD_STAGES; s++)
        printf(" %8s", ag_segment_cloud_stage_name(s));
    printf(" | %8s %8s %7s %6s %6s\n", "segment", "cpu", "planes", "found", "MiB");
}

static int cmp_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
}

/* Planes of the truth found as segments (>= 50 % of the plane in one segment, >= 80 % of it
 * the plane's), as in ../shared/tools/scoreboard. */
static int found_planes(const ag_cloud *c, const char *truth_name, const int32_t *seg, int *ntruth)
{
    const ag_cloud_property *t = ag_cloud_find(c, truth_name);
    *ntruth = 0;
    if (!t)
        return -1;
    int T = 0;
    size_t S = 0;
    for (size_t i = 0; i < c->n; i++) {
        int v = (int)ag_cloud_get(t, i);
        if (v + 1 > T)
            T = v + 1;
        if (seg[i] >= 0 && (size_t)seg[i] + 1 > S)
            S = (size_t)seg[i] + 1;
    }
    size_t *tsize = calloc((size_t)T + 1, sizeof *tsize), *ssize = calloc(S + 1, sizeof *ssize);
    uint64_t *pairs = malloc((c->n + 1) * sizeof *pairs);
    size_t np = 0;
    for (size_t i = 0; i < c->n; i++) {
        int v = (int)ag_cloud_get(t, i);
        if (v >= 0)
            tsize[v]++;
        if (seg[i] >= 0)
            ssize[seg[i]]++;
        if (v >= 0 && seg[i] >= 0)
            pairs[np++] = (uint64_t)v << 32 | (uint32_t)seg[i];
    }
    /* counting by sorting the (plane, segment) pairs */
    qsort(pairs, np, sizeof *pairs, cmp_u64);
    int found = 0;
    size_t *best = calloc((size_t)T + 1, sizeof *best), *bests = calloc((size_t)T + 1, sizeof *bests);
    for (size_t i = 0; i < np;) {
        size_t j = i;
        while (j < np && pairs[j] == pairs[i])
            j++;
        int v = (int)(pairs[i] >> 32);
        if (j - i > best[v]) {
            best[v] = j - i;
            bests[v] = pairs[i] & 0xFFFFFFFFu;
        }
        i = j;
    }
    for (int v = 0; v < T; v++) {
        if (!tsize[v])
            continue;
        (*ntruth)++;
        found += best[v] * 2 >= tsize[v] && best[v] * 5 >= ssize[bests[v]] * 4;
    }
    free(tsize);
    free(ssize);
    free(pairs);
    free(best);
    free(bests);
    return found;
}

static void segment_case(const char *name, ag_cloud *c, double t_read, const char *truth)
{
    ag_segment_cloud_result *r;
    ag_error err = {0};
    double t0 = now();
    if (ag_segment_cloud_run(c, NULL, &r, &err)) {
        printf("%-28s failed: %s\n", name, err.text);
        return;
    }
    double t = now() - t0;
    int ntruth = 0, found = truth ? found_planes(c, truth, r->segment, &ntruth) : -1;
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    double cpu = ru.ru_utime.tv_sec + ru.ru_utime.tv_usec * 1e-6 + ru.ru_stime.tv_sec + ru.ru_stime.tv_usec * 1e-6;
    printf("%-28s %9zu %7.3f |", name, c->n, t_read);
    for (int s = 0; s < AG_SEGMENT_CLOUD_STAGES; s++)
        printf(" %8.3f", r->seconds[s]);
    char f[32] = "-";
    if (found >= 0)
        snprintf(f, sizeof f, "%d/%d", found, ntruth);
    printf(" | %8.3f %8.3f %7zu %6s %6ld\n", t, cpu, r->nplanes, f, ru.ru_maxrss / 1024);
    double total_cpu = 0;
    printf("%-28s %9s %7s |", "  (processor seconds)", "", "");
    for (int s = 0; s < AG_SEGMENT_CLOUD_STAGES; s++) {
        printf(" %8.3f", r->cpu_seconds[s]);
        total_cpu += r->cpu_seconds[s];
    }
    printf(" | %8.3f\n", total_cpu);
    fflush(stdout);
    ag_segment_cloud_free(r);
}

static void generated(size_t points)
{
    ag_gen_building_options o = {.points = points, .cols = 10, .rows = 4, .side_cols = 4,
                                 .width = 40, .depth = 16, .height = 13, .noise = 0.01,
                                 .origin = {486512, 5719877, 40}, .rotation = 23, .seed = 1};
    ag_error err = {0};
    ag_cloud *c;
    double t0 = now();
    if (ag_gen_building(&o, &c, &err)) {
        printf("generated %zu: %s\n", points, err.text);
        return;
    }
    char name[64];
    snprintf(name, sizeof name, "generated %zuk", points / 1000);
    segment_case(name, c, now() - t0, "plane");
    ag_cloud_free(c);
}

static void real(const char *name, const char *path, const char *truth)
{
    if (access(path, R_OK)) {
        printf("%-28s skipped: %s is absent\n", name, path);
        return;
    }
    ag_error err = {0};
    ag_cloud *c;
    double t0 = now();
    if (ag_cloud_import_file(path, &c, &err)) {
        printf("%-28s failed: %s\n", name, err.text);
        return;
    }
    segment_case(name, c, now() - t0, truth);
    ag_cloud_free(c);
}

static void cut_ahn3(void)
{
    const char *tile = SHARED "/pointcloud_ahn3_delft/ahn3_cropped_1.laz";
    const char *bgt = SHARED "/pointcloud_ahn3_delft/bgt_pand_footprints.geojson";
    if (access(tile, R_OK) || access(bgt, R_OK)) {
        printf("cut AHN3: skipped (../shared/data absent)\n");
        return;
    }
    ag_error err = {0};
    ag_cloud *c;
    double t0 = now();
    if (ag_cloud_import_file(tile, &c, &err)) {
        printf("cut AHN3: %s\n", err.text);
        return;
    }
    double t_read = now() - t0;
    ag_footprints_options fo = {.lonlat = -1};
    ag_footprints *fp;
    if (ag_footprints_read_file(bgt, &fo, &fp, &err)) {
        printf("cut AHN3: %s\n", err.text);
        ag_cloud_free(c);
        return;
    }
    ag_cut_footprint *cf = calloc(fp->n, sizeof *cf);
    double **loops = NULL;
    size_t total = 0, li = 0;
    for (size_t k = 0; k < fp->n; k++)
        total += fp->items[k].nloops;
    loops = calloc(total + 1, sizeof *loops);
    for (size_t k = 0; k < fp->n; k++) {
        const ag_footprint *f = &fp->items[k];
        cf[k] = (ag_cut_footprint){f->nloops, f->sizes, (const double *const *)(loops + li)};
        for (size_t l = 0; l < f->nloops; l++, li++) {
            loops[li] = malloc(2 * f->sizes[l] * sizeof **loops);
            for (size_t v = 0; v < f->sizes[l]; v++) {
                loops[li][2 * v] = f->loops[l][2 * v] + fp->origin[0] - c->offset[0];
                loops[li][2 * v + 1] = f->loops[l][2 * v + 1] + fp->origin[1] - c->offset[1];
            }
        }
    }
    int32_t *owner = malloc(c->n * sizeof *owner);
    ag_cut_stats *st = calloc(fp->n, sizeof *st);
    double t1 = now();
    ag_status s = ag_cut_assign(c, cf, fp->n, NULL, owner, st, &err);
    double t_cut = now() - t1;
    size_t kept = 0, with = 0;
    for (size_t k = 0; k < fp->n; k++) {
        kept += st[k].kept;
        with += st[k].kept > 0;
    }
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    if (s == AG_OK)
        printf("cut AHN3 tile: %zu points read (LAZ decoded) in %.3f s, %zu footprints cut in %.3f s: "
               "%zu with points, %zu points kept; peak %ld MiB\n",
               c->n, t_read, fp->n, t_cut, with, kept, ru.ru_maxrss / 1024);
    else
        printf("cut AHN3: %s\n", err.text);
    for (size_t l = 0; l < total; l++)
        free(loops[l]);
    free(loops);
    free(cf);
    free(owner);
    free(st);
    ag_footprints_free(fp);
    ag_cloud_free(c);
}

static double cpu_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
}

static double peak_mib(void)
{
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    return (double)ru.ru_maxrss / 1024;
}

static void pipeline_header(void)
{
    printf("%-28s %9s %7s %8s |", "cloud", "points", "read", "normals");
    for (int s = 0; s < AG_PCLOUD_STAGES; s++)
        printf(" %9s", ag_proceduralize_cloud_stage_name(s));
    printf(" | %8s %6s %6s %6s %6s\n", "total", "labels", "terms", "places", "MiB");
}

static void pipeline_case(const char *name, ag_cloud *c, double t_read)
{
    ag_proceduralize_cloud_result *r;
    ag_error err = {0};
    double t0 = now();
    if (ag_proceduralize_cloud_run(c, NULL, &r, &err)) {
        printf("%-28s failed: %s\n", name, err.text);
        return;
    }
    double t = now() - t0;
    printf("%-28s %9zu %7.3f %8.3f |", name, c->n, t_read, r->seg->seconds[AG_SEGMENT_CLOUD_NORMALS]);
    for (int s = 0; s < AG_PCLOUD_STAGES; s++)
        printf(" %9.3f", r->seconds[s]);
    printf(" | %8.3f %6zu %6zu %6zu %6.0f\n", t, r->ncompletion, r->model->nterminals,
           r->model->nplacements, peak_mib());
    printf("%-28s %9s %7s %8.3f |", "  (processor seconds)", "", "",
           r->seg->cpu_seconds[AG_SEGMENT_CLOUD_NORMALS]);
    double cpu = 0;
    for (int s = 0; s < AG_PCLOUD_STAGES; s++) {
        printf(" %9.3f", r->cpu_seconds[s]);
        cpu += r->cpu_seconds[s];
    }
    printf(" | %8.3f\n", cpu);
    fflush(stdout);
    ag_proceduralize_cloud_free(r);
}

static ag_gen_building_options bench_building(size_t points)
{
    return (ag_gen_building_options){.points = points, .cols = 10, .rows = 4, .side_cols = 4,
                                     .width = 40, .depth = 16, .height = 13, .noise = 0.01,
                                     .origin = {486512, 5719877, 40}, .rotation = 23, .seed = 1};
}

static void pipeline_generated(const void *arg)
{
    size_t points = *(const size_t *)arg;
    ag_gen_building_options o = bench_building(points);
    ag_error err = {0};
    ag_cloud *c;
    double t0 = now();
    if (ag_gen_building(&o, &c, &err)) {
        printf("generated %zu: %s\n", points, err.text);
        return;
    }
    char name[64];
    snprintf(name, sizeof name, "generated %zuk", points / 1000);
    pipeline_case(name, c, now() - t0);
    ag_cloud_free(c);
}

static void pipeline_real(const char *name, const char *path)
{
    if (access(path, R_OK)) {
        printf("%-28s skipped: %s is absent\n", name, path);
        return;
    }
    ag_error err = {0};
    ag_cloud *c;
    double t0 = now();
    if (ag_cloud_import_file(path, &c, &err)) {
        printf("%-28s failed: %s\n", name, err.text);
        return;
    }
    pipeline_case(name, c, now() - t0);
    ag_cloud_free(c);
}

static void run_pipeline_cgal(const void *arg)
{
    (void)arg;
    pipeline_real("CGAL building.ply", SHARED "/pointcloud_cgal_building/building.ply");
}

/* Consensus of 54 windows of one size (the generator's truth: windows 0..53 are the front's
 * 40, the right side's 8 and 6 of the back's) in the 1.8M-point building. */
static void consensus_54(const void *arg)
{
    (void)arg;
    ag_gen_building_options o = bench_building(1800000);
    ag_error err = {0};
    ag_cloud *c;
    if (ag_gen_building(&o, &c, &err)) {
        printf("consensus: %s\n", err.text);
        return;
    }
    /* kNN normals as the pipeline has them */
    ag_segment_cloud_result *sr;
    if (ag_segment_cloud_run(c, NULL, &sr, &err)) {
        printf("consensus: %s\n", err.text);
        return;
    }
    const ag_cloud_property *wp = ag_cloud_find(c, "window");
    const int32_t *win = wp->values;
    enum { K = 54 };
    uint32_t start[K + 1] = {0};
    for (size_t i = 0; i < c->n; i++)
        if (win[i] >= 0 && win[i] < K)
            start[win[i] + 1]++;
    for (int w = 0; w < K; w++)
        start[w + 1] += start[w];
    uint32_t *idx = malloc(start[K] * sizeof *idx), fill[K];
    memcpy(fill, start, sizeof fill);
    ag_box boxes[K];
    for (int w = 0; w < K; w++)
        boxes[w] = ag_box_empty();
    for (size_t i = 0; i < c->n; i++)
        if (win[i] >= 0 && win[i] < K) {
            idx[fill[win[i]]++] = (uint32_t)i;
            ag_box_extend_point(&boxes[win[i]], c->xyz + 3 * i);
        }
    ag_consensus_options co = {.spacing = sr->spacing};
    ag_consensus_model m;
    double t0 = now(), c0 = cpu_now();
    ag_status s = ag_consensus_build(c, idx, start, boxes, K, NULL, &co, &m, &err);
    double t = now() - t0, tc = cpu_now() - c0;
    if (s)
        printf("consensus: %s\n", err.text);
    else
        printf("consensus of %d same-label windows (%u points) of the %zu-point building: %.3f s "
               "(processor %.3f s), "
               "%zu merged, %zu -> %zu points (pooled %zu); peak %.0f MiB\n",
               K, start[K], c->n, t, tc, m.merged, m.points_before, m.points_after, m.pooled,
               peak_mib());
    if (!s)
        ag_consensus_model_clear(&m);
    free(idx);
    ag_segment_cloud_free(sr);
    ag_cloud_free(c);
}

/* Runs one case in a child so that its peak memory is measured alone. */
static void isolated(void (*fn)(const void *), const void *arg)
{
    fflush(stdout);
    pid_t pid = fork();
    if (pid == 0) {
        fn(arg);
        fflush(stdout);
        _exit(0);
    }
    int status;
    if (pid > 0)
        waitpid(pid, &status, 0);
}

static void run_generated(const void *arg) { generated(*(const size_t *)arg); }
static void run_cgal(const void *arg)
{
    (void)arg;
    real("CGAL building.ply", SHARED "/pointcloud_cgal_building/building.ply", "segment_index");
}
static void run_urban(const void *arg)
{
    (void)arg;
    real("CGAL urban.las", SHARED "/pointcloud_cgal_building/urban.las", NULL);
}
static void run_cut(const void *arg)
{
    (void)arg;
    cut_ahn3();
}

int main(void)
{
    printf("bench/pointcloud: seconds per stage (wall; below, processor), the segmentation's total\n"
           "(wall, and processor time of the whole case), planes found against the truth, peak\n"
           "resident MiB of the case\n");
    header();
    isolated(run_cgal, NULL);
    isolated(run_urban, NULL);
    static const size_t sizes[] = {100000, 500000, 1800000};
    for (size_t i = 0; i < sizeof sizes / sizeof sizes[0]; i++)
        isolated(run_generated, &sizes[i]);
    isolated(run_cut, NULL);
    printf("\nthe whole pipeline (core/points/proceduralize_cloud.h): seconds per stage (wall;\n"
           "below, processor), normals being part of segment; consensus labels, terminals,\n"
           "placements, peak resident MiB of the case\n");
    pipeline_header();
    isolated(run_pipeline_cgal, NULL);
    for (size_t i = 0; i < sizeof sizes / sizeof sizes[0]; i++)
        isolated(pipeline_generated, &sizes[i]);
    printf("\n");
    isolated(consensus_54, NULL);
    return 0;
}
