/* Extrusion benchmark: real Den Haag footprints with built-in styles (one thread and every
 * core) and against CGAL's skeleton of the same polygons (the oracle, when built: whole
 * process and skeletons alone, as ratios), generated batches with per-edge profiles, an
 * adversarial integer-grid stress batch, and single large footprints. Prints seconds,
 * buildings that fell back or failed (each with id and reason) and peak memory. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <time.h>
#include <unistd.h>

#include "app/extrude_batch.h"
#include "core/extrude/extrude.h"
#include "core/extrude/predicates.h"
#include "core/extrude/style.h"
#include "io/footprints.h"
#include "io/plan_write.h"
#include "../tests/unit/extrude_grid_profiles.h"

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
}

static long peak_kb(void)
{
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    return ru.ru_maxrss;
}

/* Why a building is not good (a failing shell face or a defect of its triangles), or NULL. */
static const char *not_good(const ag_extrude_result *r)
{
    if (r->failing_faces)
        return r->problems[0].reason;
    return r->defect[0] ? r->defect : NULL;
}

static void print_issues(const ag_footprints_report *r)
{
    for (size_t i = 0; i < r->nfailed; i++)
        printf("    failed %s: %s\n", r->failed[i].id, r->failed[i].reason);
    for (size_t i = 0; i < r->nfallbacks; i++)
        printf("    fell back %s (%s): %s\n", r->fallbacks[i].id, ag_built_name(r->fallbacks[i].built),
               r->fallbacks[i].reason);
    for (size_t i = 0; i < r->nnot_watertight; i++)
        printf("    not watertight %s: %s\n", r->not_watertight[i].id, r->not_watertight[i].reason);
}

/* One batch with `threads` threads (0: every core); returns the seconds. */
static double run_style(const ag_footprints *f, const char *label, const ag_style *s,
                        size_t threads)
{
    ag_mesh *m = ag_mesh_create();
    ag_footprints_report r;
    ag_error err = {0};
    ag_extrude_batch_options bo = {.threads = threads};
    double t0 = now();
    ag_status st = ag_extrude_batch(f, s, &bo, m, &r, &err);
    double dt = now() - t0;
    if (st != AG_OK) {
        printf("  %-22s error: %s\n", label, err.text);
    } else {
        printf("  %-22s %5zu footprints  %.3f s  as styled %zu  fell back %zu  failed %zu  "
               "not watertight %zu  triangles %zu  events %zu  peak RSS %ld MB\n",
               label, r.footprints, dt, r.succeeded, r.nfallbacks, r.nfailed, r.nnot_watertight,
               r.triangles, r.events, peak_kb() / 1024);
        print_issues(&r);
    }
    ag_footprints_report_free(&r);
    ag_mesh_free(m);
    return dt;
}

/* --- against CGAL ------------------------------------------------------------------------- */

/* CPU seconds (user + system) of the children waited for so far. */
static double children_cpu(void)
{
    struct rusage ru;
    getrusage(RUSAGE_CHILDREN, &ru);
    return ru.ru_utime.tv_sec + ru.ru_utime.tv_usec * 1e-6 + ru.ru_stime.tv_sec +
           ru.ru_stime.tv_usec * 1e-6;
}

/* Wall-clock seconds of a command (best of `runs`), -1 when it fails; *cpu (may be NULL)
 * gets the CPU seconds of the best run (the shell's included, a millisecond). */
static double time_command(const char *cmd, int runs, double *cpu)
{
    double best = -1;
    for (int i = 0; i < runs; i++) {
        double c0 = children_cpu(), t0 = now();
        int rc = system(cmd);
        double dt = now() - t0, dc = children_cpu() - c0;
        if (rc != 0)
            return -1;
        if (best < 0 || dt < best) {
            best = dt;
            if (cpu)
                *cpu = dc;
        }
    }
    return best;
}

/* The oracle's own loop time (its summary line's loop_wall_s) for a polygon file. */
static double oracle_loop(const char *oracle, const char *polys)
{
    char cmd[2048];
    snprintf(cmd, sizeof cmd, "'%s' '%s'", oracle, polys);
    FILE *p = popen(cmd, "r");
    if (!p)
        return -1;
    char line[1024];
    double loop = -1;
    while (fgets(line, sizeof line, p)) {
        const char *k = strstr(line, "loop_wall_s=");
        if (line[0] == '#' && k)
            loop = atof(k + strlen("loop_wall_s="));
    }
    pclose(p);
    return loop;
}

/* Den Haag with uniform 45° roofs against CGAL's unweighted skeleton of the same polygons
 * (the footprints as read, each outer ring with its holes): the whole process (archgram
 * reading GeoJSON and writing OBJ; CGAL reading its polygon text), and the skeletons
 * alone (our batch in process; CGAL's own loop). */
static void against_cgal(const char *geojson, const ag_footprints *f)
{
    const char *oracle = AG_REPO_DIR "/build/oracle/cgal_skeleton";
    const char *cli = AG_REPO_DIR "/build/archgram";
    FILE *probe = fopen(oracle, "rb");
    if (!probe) {
        printf("  against CGAL: %s is not built (make builds it from ../shared/tools/"
               "cgal_skeleton): skipped\n", oracle);
        return;
    }
    fclose(probe);
    const char *tmp = getenv("TMPDIR");
    char polys[512], out[512];
    snprintf(polys, sizeof polys, "%s/ag_bench_polys_%d.txt", tmp && tmp[0] ? tmp : P_tmpdir,
             (int)getpid());
    snprintf(out, sizeof out, "%s/ag_bench_out_%d.obj", tmp && tmp[0] ? tmp : P_tmpdir,
             (int)getpid());
    FILE *pf = fopen(polys, "w");
    if (!pf)
        return;
    size_t npoly = 0;
    for (size_t i = 0; i < f->n; i++) {
        const ag_footprint *fp = &f->items[i];
        for (size_t L = 0; L < fp->nloops; L++) {
            double a = 0;
            const double *xy = fp->loops[L];
            for (size_t k = 0, j = fp->sizes[L] - 1; k < fp->sizes[L]; j = k++)
                a += xy[2 * j] * xy[2 * k + 1] - xy[2 * k] * xy[2 * j + 1];
            if (a <= 0)
                continue; /* holes follow their outer ring */
            fprintf(pf, "P p%zu_%zu\n", i, L);
            for (size_t H = L; H < fp->nloops; H++) {
                if (H != L) {
                    double b = 0;
                    const double *h = fp->loops[H];
                    for (size_t k = 0, j = fp->sizes[H] - 1; k < fp->sizes[H]; j = k++)
                        b += h[2 * j] * h[2 * k + 1] - h[2 * k] * h[2 * j + 1];
                    if (b >= 0 || !ag_pred_point_in_polygon(xy, fp->sizes[L], h[0], h[1]))
                        continue;
                }
                fprintf(pf, "L %zu\n", fp->sizes[H]);
                for (size_t k = 0; k < fp->sizes[H]; k++)
                    fprintf(pf, "%.17g %.17g 45\n", fp->loops[H][2 * k], fp->loops[H][2 * k + 1]);
            }
            fprintf(pf, "E\n");
            npoly++;
        }
    }
    fclose(pf);
    char cmd[2048];
    snprintf(cmd, sizeof cmd, "'%s' '%s' > /dev/null", oracle, polys);
    double cg_cpu = 0, cpu[2] = {0, 0};
    double cg = time_command(cmd, 5, &cg_cpu);
    double cg_loop = oracle_loop(oracle, polys);
    double ours[2];
    for (int t = 0; t < 2; t++) {
        snprintf(cmd, sizeof cmd, "'%s' extrude '%s' --style hip --threads %d --out '%s' > /dev/null 2>&1",
                 cli, geojson, t ? 0 : 1, out);
        ours[t] = time_command(cmd, 5, &cpu[t]);
    }
    ag_style s;
    ag_style_builtin("hip", &s, NULL);
    double batch[2];
    for (int t = 0; t < 2; t++) {
        ag_mesh *m = ag_mesh_create();
        ag_footprints_report r;
        ag_error err = {0};
        ag_extrude_batch_options bo = {.threads = t ? 0 : 1};
        double t0 = now();
        ag_extrude_batch(f, &s, &bo, m, &r, &err);
        batch[t] = now() - t0;
        ag_footprints_report_free(&r);
        ag_mesh_free(m);
    }
    long cpus = sysconf(_SC_NPROCESSORS_ONLN);
    printf("  against CGAL 5.5 (unweighted skeleton, EPICK) on the same %zu Den Haag polygons, "
           "best of 5:\n", npoly);
    printf("    whole process: CGAL %.3f s; archgram hip, 1 thread %.3f s (ratio %.2f), %ld "
           "cores %.3f s (ratio %.2f)\n", cg, ours[0], ours[0] / cg, cpus, ours[1], ours[1] / cg);
    printf("    whole process, CPU seconds (the same runs): CGAL %.3f s; archgram hip, 1 thread "
           "%.3f s (ratio %.2f), %ld cores %.3f s\n", cg_cpu, cpu[0], cpu[0] / cg_cpu, cpus,
           cpu[1]);
    printf("    skeletons alone: CGAL's loop %.3f s; archgram's batch (with its checks), 1 thread "
           "%.3f s (ratio %.2f), %ld cores %.3f s (ratio %.2f)\n", cg_loop, batch[0],
           batch[0] / cg_loop, cpus, batch[1], batch[1] / cg_loop);
    remove(polys);
    remove(out);
}

/* --- generated batches ------------------------------------------------------------------- */

static uint64_t rng = 88172645463325252ULL;
static double rnd(void)
{
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return (double)(rng >> 11) / 9007199254740992.0;
}

/* A footprint from a small family: rectangle, L, U, T, cross, convex blob, star. */
static size_t gen_shape(double *xy, double ox, double oy)
{
    int kind = (int)(rnd() * 7);
    double w = 6 + rnd() * 14, h = 5 + rnd() * 10, a = rnd() * 2 * M_PI;
    double pts[64];
    size_t n = 0;
#define P(x, y) (pts[2 * n] = (x), pts[2 * n + 1] = (y), n++)
    double t = 2 + rnd() * (h / 2 - 1.5);
    if (t > w / 3 - 0.5)
        t = w / 3 - 0.5; /* keeps U and T shapes simple */
    switch (kind) {
    case 0:
        P(0, 0); P(w, 0); P(w, h); P(0, h);
        break;
    case 1:
        P(0, 0); P(w, 0); P(w, t); P(t, t); P(t, h); P(0, h);
        break;
    case 2:
        P(0, 0); P(w, 0); P(w, h); P(w - t, h); P(w - t, t); P(t, t); P(t, h); P(0, h);
        break;
    case 3:
        P(0, 0); P(w, 0); P(w, t); P(w / 2 + t / 2, t); P(w / 2 + t / 2, h); P(w / 2 - t / 2, h);
        P(w / 2 - t / 2, t); P(0, t);
        break;
    case 4: {
        double c = w / 3;
        P(c, 0); P(2 * c, 0); P(2 * c, c); P(3 * c, c); P(3 * c, 2 * c); P(2 * c, 2 * c);
        P(2 * c, 3 * c); P(c, 3 * c); P(c, 2 * c); P(0, 2 * c); P(0, c); P(c, c);
        break;
    }
    case 5: {
        int k = 5 + (int)(rnd() * 10);
        for (int i = 0; i < k; i++) {
            double ang = 2 * M_PI * (i + 0.3 * rnd()) / k;
            P(w / 2 * cos(ang), h / 2 * sin(ang));
        }
        break;
    }
    default: {
        int k = 6 + (int)(rnd() * 10);
        for (int i = 0; i < k; i++) {
            double ang = 2 * M_PI * i / k, r = (i % 2 ? 0.6 : 1.0) * w / 2 * (0.9 + 0.2 * rnd());
            P(r * cos(ang), r * sin(ang));
        }
        break;
    }
    }
#undef P
    for (size_t i = 0; i < n; i++) {
        double x = pts[2 * i], y = pts[2 * i + 1];
        xy[2 * i] = ox + x * cos(a) - y * sin(a);
        xy[2 * i + 1] = oy + x * sin(a) + y * cos(a);
    }
    return n;
}

static void add_profiles(ag_plan *p, double h)
{
    ag_profile_point hip[] = {{0, 0}, {0, h}, {1, h + 1}};
    ag_profile_point steep[] = {{0, 0}, {0, h}, {0.5, h + 1}};
    ag_profile_point wall[] = {{0, 0}, {0, h + 1}};
    ag_profile_point mansard[] = {{0, 0}, {0, h}, {0.9, h + 2.5}, {3.65, h + 3.5}};
    ag_profile_point over[] = {{0, 0}, {0, h}, {-0.5, h + 0.15}, {0.5, h + 1.15}};
    ag_profile_point batter[] = {{0, 0}, {0.2, h}, {1.2, h + 1}};
    ag_plan_add_profile(p, "hip", hip, 3, NULL, NULL, NULL);
    ag_plan_add_profile(p, "steep", steep, 3, NULL, NULL, NULL);
    ag_plan_add_profile(p, "wall", wall, 2, NULL, NULL, NULL);
    ag_plan_add_profile(p, "mansard", mansard, 4, NULL, NULL, NULL);
    ag_plan_add_profile(p, "overhang", over, 4, NULL, NULL, NULL);
    ag_plan_add_profile(p, "batter", batter, 3, NULL, NULL, NULL);
    ag_profile_point soffit[] = {{0, 0}, {0, h}, {-0.5, h}, {0.5, h + 1}};
    ag_profile_point terrace[] = {{0, 0}, {0, h}, {1, h}, {1, h + 2}, {2, h + 3}};
    ag_plan_add_profile(p, "soffit", soffit, 4, NULL, NULL, NULL);
    ag_plan_add_profile(p, "terrace", terrace, 5, NULL, NULL, NULL);
}
#define NPROFILES 8

static void generated_batch(size_t count)
{
    ag_mesh *m = ag_mesh_create();
    size_t failed = 0, leaky = 0, tris = 0;
    double xy[128];
    int32_t prof[64];
    double t0 = now();
    for (size_t i = 0; i < count; i++) {
        size_t n = gen_shape(xy, (double)(i % 60) * 40, (double)(i / 60) * 40);
        ag_plan *p = ag_plan_create();
        add_profiles(p, 3 + rnd() * 6);
        /* one profile family per building, with the wall profile mixed in on some edges */
        int base = (int)(rnd() * NPROFILES);
        for (size_t k = 0; k < n; k++)
            prof[k] = rnd() < 0.15 ? 2 : (rnd() < 0.2 ? (int)(rnd() * NPROFILES) : base);
        ag_plan_add_loop(p, xy, n, prof, NULL);
        ag_error err = {0};
        ag_extrude_result r;
        char id[32];
        snprintf(id, sizeof id, "gen%zu", i);
        size_t g = 0;
        ag_mesh_add_group(m, id, &g);
        ag_status st = ag_extrude_plan(p, m, (int32_t)g, &r, NULL, &err);
        if (st != AG_OK) {
            failed++;
            printf("    failed %s: %s\n", id, err.text);
        } else {
            tris += r.triangles;
            if (not_good(&r)) {
                leaky++;
                printf("    not good %s: %s\n", id, not_good(&r));
            }
        }
        ag_plan_free(p);
    }
    double dt = now() - t0;
    printf("  %-22s %5zu footprints  %.3f s  failed %zu (%.3f%%)  not watertight %zu  "
           "triangles %zu  peak RSS %ld MB\n",
           "generated, per-edge", count, dt, failed, 100.0 * failed / count, leaky, tris,
           peak_kb() / 1024);
    ag_mesh_free(m);
}

/* Offset events with an inside boundary (a parapet ring around a hip roof) on generated
 * footprints: walls to h + 1 then 45 deg in; at h a gap opens between 0.2..0.6 m and
 * 0.5..2.6 m inside, the ring's inner face rises 1 m then leans out (a ridged parapet),
 * the inner shell is a 45 deg hip. */
static void inside_batch(size_t count)
{
    size_t failed = 0, leaky = 0, tris = 0, gaps = 0;
    double xy[128];
    double t0 = now();
    for (size_t i = 0; i < count; i++) {
        size_t n = gen_shape(xy, 0, 0);
        double h = 3 + rnd() * 6;
        ag_plan *p = ag_plan_create();
        ag_profile_point wall[] = {{0, 0}, {0, h + 1}, {1, h + 2}};
        ag_profile_point in[] = {{0, 0}, {0, 1}, {1, 2}}, roof[] = {{0, 0}, {1, 1}};
        ag_plan_add_profile(p, "wall", wall, 3, NULL, NULL, NULL);
        ag_plan_add_profile(p, "parapet", in, 3, NULL, NULL, NULL);
        ag_plan_add_profile(p, "roof", roof, 2, NULL, NULL, NULL);
        ag_plan_add_loop(p, xy, n, NULL, NULL);
        ag_plan_offset o;
        memset(&o, 0, sizeof o);
        o.z = h;
        o.profile = o.side = -1;
        o.has_gap = 1;
        o.gap_from = 0.2 + rnd() * 0.4;
        o.gap_to = o.gap_from + 0.3 + rnd() * 2;
        o.inside = 1;
        o.inner = 2;
        ag_plan_add_offset(p, &o, NULL);
        ag_mesh *m = ag_mesh_create();
        ag_error err = {0};
        ag_extrude_result r;
        ag_status st = ag_extrude_plan(p, m, -1, &r, NULL, &err);
        if (st != AG_OK) {
            failed++;
            printf("    failed inside%zu: %s\n", i, err.text);
        } else {
            tris += r.triangles;
            gaps += r.stats.offset_gaps;
            if (not_good(&r)) {
                leaky++;
                printf("    not good inside%zu: %s\n", i, not_good(&r));
            }
        }
        ag_mesh_free(m);
        ag_plan_free(p);
    }
    double dt = now() - t0;
    printf("  %-22s %5zu footprints  %.3f s  failed %zu  not watertight %zu  gaps %zu  "
           "triangles %zu\n",
           "inside boundaries", count, dt, failed, leaky, gaps, tris);
}

static void big_polygon(size_t n, const char *prof_kind)
{
    double *xy = malloc(2 * n * sizeof *xy);
    uint64_t keep = rng;
    for (size_t i = 0; i < n; i++) {
        double a = 2 * M_PI * i / n, r = 40 + 8 * rnd();
        xy[2 * i] = r * cos(a);
        xy[2 * i + 1] = r * sin(a);
    }
    rng = keep;
    ag_plan *p = ag_plan_create();
    add_profiles(p, 6);
    int32_t *pr = malloc(n * sizeof *pr);
    for (size_t i = 0; i < n; i++)
        pr[i] = strcmp(prof_kind, "hip") == 0 ? 0 : (int32_t)(i % NPROFILES == 2 ? 0 : i % NPROFILES);
    ag_plan_add_loop(p, xy, n, pr, NULL);
    ag_mesh *m = ag_mesh_create();
    ag_extrude_result r;
    ag_error err = {0};
    double t0 = now();
    ag_status st = ag_extrude_plan(p, m, -1, &r, NULL, &err);
    double dt = now() - t0;
    char label[64];
    snprintf(label, sizeof label, "%zu-vertex (%s)", n, prof_kind);
    if (st != AG_OK)
        printf("  %-22s failed: %s (%.3f s)\n", label, err.text, dt);
    else
        printf("  %-22s %.3f s  triangles %zu  faces %zu  not watertight faces %zu  peak RSS %ld MB\n",
               label, dt, r.triangles, r.faces, r.failing_faces, peak_kb() / 1024);
    ag_mesh_free(m);
    ag_plan_free(p);
    free(xy);
    free(pr);
}


/* --- adversarial integer-grid stress ------------------------------------------------------- */

/* Shapes on an integer grid with profiles whose heights and widths are whole metres: many
 * events fall at exactly the same height and point (ties, coincident and collinear edges,
 * flat intervals that end exactly where edges meet). Plans that validation rejects
 * (polyominoes pinched at a corner) are counted apart. */
static uint64_t srng = 0x9E3779B97F4A7C15ULL;
static double srnd(void)
{
    srng ^= srng << 13;
    srng ^= srng >> 7;
    srng ^= srng << 17;
    return (double)(srng >> 11) / 9007199254740992.0;
}

/* A polyomino grown on a G x G grid of cells `cell` metres wide; its boundary as loops.
 * Returns the number of loops written (xy: all corners, starts[]: loop starts). */
static size_t grid_shape(double cell, int G, double *xy, size_t *starts, size_t *nloops_out)
{
    unsigned char in[16][16] = {{0}};
    int cnt = 1 + (int)(srnd() * (G * G * 0.6));
    in[G / 2][G / 2] = 1;
    for (int k = 1; k < cnt; k++) {
        for (int tries = 0; tries < 100; tries++) {
            int x = (int)(srnd() * G), y = (int)(srnd() * G);
            if (in[x][y])
                continue;
            int nb = (x > 0 && in[x - 1][y]) || (x + 1 < G && in[x + 1][y]) ||
                     (y > 0 && in[x][y - 1]) || (y + 1 < G && in[x][y + 1]);
            if (nb) {
                in[x][y] = 1;
                break;
            }
        }
    }
    /* directed boundary edges, interior on the left: unit steps */
    int ex[4 * 256][4];
    int ne = 0;
    for (int x = 0; x < G; x++)
        for (int y = 0; y < G; y++) {
            if (!in[x][y])
                continue;
            if (y == 0 || !in[x][y - 1]) { ex[ne][0] = x; ex[ne][1] = y; ex[ne][2] = x + 1; ex[ne][3] = y; ne++; }
            if (x == G - 1 || !in[x + 1][y]) { ex[ne][0] = x + 1; ex[ne][1] = y; ex[ne][2] = x + 1; ex[ne][3] = y + 1; ne++; }
            if (y == G - 1 || !in[x][y + 1]) { ex[ne][0] = x + 1; ex[ne][1] = y + 1; ex[ne][2] = x; ex[ne][3] = y + 1; ne++; }
            if (x == 0 || !in[x - 1][y]) { ex[ne][0] = x; ex[ne][1] = y + 1; ex[ne][2] = x; ex[ne][3] = y; ne++; }
        }
    unsigned char used[4 * 256] = {0};
    size_t n = 0, nl = 0;
    for (int s = 0; s < ne; s++) {
        if (used[s])
            continue;
        starts[nl++] = n;
        int cur = s;
        while (!used[cur]) {
            used[cur] = 1;
            xy[2 * n] = ex[cur][0] * cell;
            xy[2 * n + 1] = ex[cur][1] * cell;
            n++;
            /* next: an unused edge starting at this end; prefer the left turn at pinches */
            int best = -1, bestturn = 99;
            for (int t = 0; t < ne; t++)
                if (!used[t] && ex[t][0] == ex[cur][2] && ex[t][1] == ex[cur][3]) {
                    int dx1 = ex[cur][2] - ex[cur][0], dy1 = ex[cur][3] - ex[cur][1];
                    int dx2 = ex[t][2] - ex[t][0], dy2 = ex[t][3] - ex[t][1];
                    int cr = dx1 * dy2 - dy1 * dx2;
                    int turn = cr > 0 ? 0 : cr == 0 ? 1 : 2;
                    if (turn < bestturn) {
                        bestturn = turn;
                        best = t;
                    }
                }
            if (best < 0)
                break;
            cur = best;
        }
    }
    starts[nl] = n;
    *nloops_out = nl;
    return n;
}

/* A star-shaped polygon through integer points around a centre. */
static size_t star_shape(double cell, double *xy)
{
    int k = 5 + (int)(srnd() * 12);
    double pts[64][3];
    int n = 0;
    for (int i = 0; i < k; i++) {
        int x = (int)(srnd() * 13) - 6, y = (int)(srnd() * 13) - 6;
        if (x == 0 && y == 0)
            continue;
        double a = atan2(y - 0.31, x - 0.17);
        int dup = 0;
        for (int j = 0; j < n; j++)
            if (fabs(pts[j][2] - a) < 1e-12)
                dup = 1;
        if (dup)
            continue;
        pts[n][0] = x * cell;
        pts[n][1] = y * cell;
        pts[n][2] = a;
        n++;
    }
    for (int i = 1; i < n; i++)
        for (int j = i; j > 0 && pts[j][2] < pts[j - 1][2]; j--)
            for (int c = 0; c < 3; c++) {
                double t = pts[j][c];
                pts[j][c] = pts[j - 1][c];
                pts[j - 1][c] = t;
            }
    for (int i = 0; i < n; i++) {
        xy[2 * i] = pts[i][0];
        xy[2 * i + 1] = pts[i][1];
    }
    return (size_t)n;
}

/* For a building whose edge is shared by more than two faces: 1 when every such edge of its
 * triangles (corners welded on a 1e-6 m lattice; the stress plans lie on a metre grid) is
 * used equally often each way, so parts of the solid touch along it (no closed 2-manifold
 * can have that edge), 0 when some edge is used more often one way than the other (a
 * defect of the shell). */
typedef struct {
    int64_t a[3], b[3];
} bench_edge;
static int cmp_bench_edge(const void *x, const void *y)
{
    const bench_edge *e = x, *f = y;
    int64_t u[6] = {e->a[0] >> 1, e->a[1], e->a[2], e->b[0], e->b[1], e->b[2]};
    int64_t v[6] = {f->a[0] >> 1, f->a[1], f->a[2], f->b[0], f->b[1], f->b[2]};
    for (int k = 0; k < 6; k++)
        if (u[k] != v[k])
            return u[k] < v[k] ? -1 : 1;
    return (int)(e->a[0] & 1) - (int)(f->a[0] & 1);
}
static int only_touching(const ag_mesh *m)
{
    bench_edge *E = malloc((3 * m->ntris + 1) * sizeof *E);
    if (!E)
        return 0;
    size_t n = 0;
    for (size_t t = 0; t < m->ntris; t++)
        for (int k = 0; k < 3; k++) {
            const double *p = &m->pos[3 * m->tri[3 * t + k]];
            const double *q = &m->pos[3 * m->tri[3 * t + (k + 1) % 3]];
            bench_edge e;
            memset(&e, 0, sizeof e);
            int rev = 0;
            for (int d = 0; d < 3 && !rev; d++) {
                int64_t pa = llround(p[d] * 1e6), qa = llround(q[d] * 1e6);
                if (pa != qa) {
                    rev = pa > qa ? 1 : -1;
                }
            }
            if (!rev)
                continue;
            const double *lo = rev < 0 ? p : q, *hi = rev < 0 ? q : p;
            for (int d = 0; d < 3; d++) {
                e.a[d] = llround(lo[d] * 1e6);
                e.b[d] = llround(hi[d] * 1e6);
            }
            /* the direction in the lowest bit of the first coordinate pair's slot */
            e.a[0] = e.a[0] * 2 + (rev > 0);
            E[n++] = e;
        }
    qsort(E, n, sizeof *E, cmp_bench_edge);
    int ok = 1;
    for (size_t i = 0; i < n && ok;) {
        /* the entries of one undirected edge: both directions sit next to each other */
        size_t j = i, fw = 0, bw = 0;
        int64_t a0 = E[i].a[0] >> 1;
        while (j < n && (E[j].a[0] >> 1) == a0 && memcmp(E[j].a + 1, E[i].a + 1, 2 * sizeof(int64_t)) == 0 &&
               memcmp(E[j].b, E[i].b, sizeof E[i].b) == 0) {
            if (E[j].a[0] & 1)
                bw++;
            else
                fw++;
            j++;
        }
        if (fw != bw)
            ok = 0;
        i = j;
    }
    free(E);
    return ok;
}

/* --grid-dump N: the description of stress plan N (before validation) goes to this file */
static long dump_index = -1;
static const char *dump_path = NULL;

static void grid_stress_with(size_t count, int repair);
static void grid_stress(size_t count)
{
    if (!dump_path)
        grid_stress_with(count, 0);
    grid_stress_with(count, 1);
}

/* repair: with the post inter-chain winding-rule repair (the default) or without */
static void grid_stress_with(size_t count, int repair)
{
    srng = 0x9E3779B97F4A7C15ULL;
    size_t w_invalid = 0, w_repairs = 0, w_refused = 0, w_dropped = 0, w_good = 0;
    size_t f_levels = 0, f_rebuilt = 0, f_left = 0, touching = 0;
    size_t failed = 0, leaky = 0, rejected = 0, leaky_nested = 0, good_nested = 0;
    size_t kinds[2] = {0, 0}, leaky_kind[2] = {0, 0};
    size_t cause[5][2] = {{0}}; /* overlap / open / shared edge / fold / other, elsewhere or at h */
    static double xy[2 * 1200];
    size_t starts[300];
    static int32_t prof[1200];
    double t0 = now();
    for (size_t i = 0; i < count; i++) {
        size_t n, nl = 1;
        int kind = (int)(srnd() * 2);
        if (kind == 0) {
            n = grid_shape(1 + (int)(srnd() * 3), 4 + (int)(srnd() * 5), xy, starts, &nl);
        } else {
            n = star_shape(1 + (int)(srnd() * 2), xy);
            starts[0] = 0;
            starts[1] = n;
        }
        ag_plan *p = ag_plan_create();
        double h = 1 + (int)(srnd() * 3);
        grid_profiles(p, h);
        int mode = (int)(srnd() * 3), base = (int)(srnd() * 8);
        for (size_t k = 0; k < n; k++)
            prof[k] = mode == 0 ? 6 : mode == 1 ? base : (int)(srnd() * 8);
        for (size_t l = 0; l < nl; l++)
            ag_plan_add_loop(p, xy + 2 * starts[l], starts[l + 1] - starts[l], prof + starts[l], NULL);
        if ((long)i == dump_index) {
            json_t *doc = NULL;
            if (ag_plan_write_json(p, &doc, NULL) == AG_OK)
                json_dump_file(doc, dump_path, JSON_INDENT(1));
            json_decref(doc);
        }
        if (dump_path && (long)i != dump_index) {
            ag_plan_free(p); /* only the plan asked for is written and extruded */
            continue;
        }
        ag_mesh *m = ag_mesh_create();
        ag_extrude_result r;
        ag_error err = {0};
        ag_extrude_options eo = {0};
        eo.no_winding_repair = !repair;
        ag_status st = ag_extrude_plan_with(p, &eo, m, -1, &r, NULL, &err);
        if (st == AG_OK) {
            w_invalid += r.stats.winding_invalid;
            w_repairs += r.stats.winding_repairs;
            f_levels += r.stats.flat_levels;
            f_rebuilt += r.stats.flat_rebuilt;
            f_left += r.stats.flat_left;
            w_refused += r.stats.winding_refused;
            w_dropped += r.stats.winding_pieces_dropped;
            w_good += r.stats.winding_repairs && !not_good(&r);
            if (r.stats.winding_repairs)
                printf("    rebuilt by the winding rule grid%zu: %s\n", i,
                       not_good(&r) ? not_good(&r) : "good");
        }
        if (st == AG_ERR_INVALID || st == AG_ERR_EMPTY) {
            rejected++;
        } else if (st != AG_OK) {
            failed++;
            printf("    failed grid%zu: %s\n", i, err.text);
        } else if (not_good(&r)) {
            leaky++;
            /* by cause: the defect's kind, and whether it lies at the height of the
             * horizontal profile segments (every flat step of a stress plan is at h) */
            const char *why = not_good(&r);
            int kind_i = strstr(why, "overlaps itself") ? 0 : strstr(why, "is open") ? 1
                         : strstr(why, "more than two") ? 2 : strstr(why, "folded") ? 3 : 4;
            const char *zs = strchr(why, '(');
            double wx, wy, wz;
            int at_h = zs && sscanf(zs, "(%lf, %lf, %lf)", &wx, &wy, &wz) == 3 &&
                       fabs(wz - h) < 1e-6;
            cause[kind_i][at_h]++;
            if (kind_i == 2)
                touching += only_touching(m);
            leaky_nested += r.stats.irregular > 0;
            leaky_kind[kind]++;
            if (repair) {
                /* what the plan has, for sorting the failures by cause: the profiles its
                 * edges use and the height of the defect against the step height h */
                static const char *const pname[] = {"hip", "steep", "wall", "r2", "over",
                                                    "soffit", "r45", "terrace"};
                char used[96] = "";
                unsigned mask = 0;
                for (size_t k = 0; k < n; k++)
                    mask |= 1u << prof[k];
                for (int b = 0; b < 8; b++)
                    if (mask & (1u << b)) {
                        strcat(used, used[0] ? "+" : "");
                        strcat(used, pname[b]);
                    }
                printf("    not good grid%zu (%s, %zu nested intersections, %zu winding repairs, "
                       "%zu refused, %zu of %zu flat heights left; h %g, profiles %s): %s\n", i,
                       kind ? "star" : "grid", r.stats.irregular, r.stats.winding_repairs,
                       r.stats.winding_refused, r.stats.flat_left, r.stats.flat_levels, h, used,
                       not_good(&r));
            }
        } else {
            good_nested += r.stats.irregular > 0;
        }
        kinds[kind] += st == AG_OK;
        ag_mesh_free(m);
        ag_plan_free(p);
    }
    double dt = now() - t0;
    size_t valid = count - rejected;
    printf("  %-22s %5zu plans  %.3f s  rejected by validation %zu  failed %zu  not watertight %zu "
           "(%.3f%% of %zu valid)\n",
           repair ? "integer-grid stress" : "grid, no winding repair", count, dt, rejected, failed, leaky,
           100.0 * (failed + leaky) / (valid ? valid : 1), valid);
    printf("    not good: %zu of %zu grid shapes, %zu of %zu stars; %zu of them with nested "
           "intersections (as are %zu good ones)\n", leaky_kind[0], kinds[0], leaky_kind[1],
           kinds[1], leaky_nested, good_nested);
    printf("    by cause (at the flat steps' height / elsewhere): winding other than once %zu / "
           "%zu, open %zu / %zu, an edge of more than two faces %zu / %zu, a horizontal face "
           "folded %zu / %zu, other %zu / %zu\n",
           cause[0][1], cause[0][0], cause[1][1], cause[1][0], cause[2][1], cause[2][0],
           cause[3][1], cause[3][0], cause[4][1], cause[4][0]);
    printf("    of the edges of more than two faces: %zu buildings whose parts only touch along "
           "edges (as many faces each way: no closed 2-manifold has them), %zu with a defect\n",
           touching, cause[2][0] + cause[2][1] - touching);
    if (repair)
        printf("    winding rule: %zu levels with crossing chains, %zu rebuilt (%zu pieces removed), "
               "%zu refused; %zu plans with a rebuild are good\n", w_invalid, w_repairs, w_dropped,
               w_refused, w_good);
    printf("    heights with two flat faces or more: %zu, rebuilt as the plans' difference "
           "%zu, left %zu\n", f_levels, f_rebuilt, f_left);
}

int main(int argc, char **argv)
{
    /* --cgal: only the comparison with CGAL on Den Haag */
    int only_cgal = argc > 1 && strcmp(argv[1], "--cgal") == 0;
    /* --grid: only the integer-grid stress plans */
    if (argc > 3 && strcmp(argv[1], "--grid-dump") == 0) {
        dump_index = atol(argv[2]);
        dump_path = argv[3];
    }
    if (argc > 1 && (strcmp(argv[1], "--grid") == 0 || dump_path)) {
        grid_stress(20000);
        return 0;
    }
    const char *path = AG_REPO_DIR "/../shared/data/footprints_denhaag_lod2/denhaag_tile01_footprints.geojson";
    printf("extrude benchmark\n");
    ag_footprints *f = NULL;
    ag_error err = {0};
    FILE *probe = fopen(path, "rb");
    if (!probe) {
        printf("  Den Haag footprints not found (%s): skipped\n", path);
    } else {
        fclose(probe);
        double t0 = now();
        if (ag_footprints_read_file(path, NULL, &f, &err) != AG_OK) {
            printf("  reading Den Haag failed: %s\n", err.text);
        } else {
            printf("  Den Haag: %zu footprints read in %.3f s\n", f->n, now() - t0);
            const char *styles[] = {"hip", "gable", "overhang", "mansard", "flat"};
            for (size_t i = 0; !only_cgal && i < sizeof styles / sizeof *styles; i++) {
                ag_style s;
                ag_style_builtin(styles[i], &s, NULL);
                char label[64];
                snprintf(label, sizeof label, "Den Haag %s", styles[i]);
                run_style(f, label, &s, 1);
                snprintf(label, sizeof label, "Den Haag %s, all cores", styles[i]);
                run_style(f, label, &s, 0);
            }
            against_cgal(path, f);
            ag_footprints_free(f);
        }
    }
    if (only_cgal)
        return 0;
    generated_batch(3000);
    grid_stress(20000);
    big_polygon(1000, "hip");
    big_polygon(1000, "mixed");
    big_polygon(2000, "hip");
    big_polygon(2000, "mixed");
    inside_batch(2000);
    printf("  peak RSS %ld MB\n", peak_kb() / 1024);
    return 0;
}
