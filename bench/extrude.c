/* Extrusion benchmark: real Den Haag footprints with built-in styles, generated batches
 * with per-edge profiles, and single large footprints. Prints seconds, failures (each
 * with id and reason) and peak memory. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <time.h>

#include "core/extrude/extrude.h"
#include "core/extrude/style.h"
#include "io/footprints.h"

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

static void print_issues(const ag_footprints_report *r)
{
    for (size_t i = 0; i < r->nfailed; i++)
        printf("    failed %s: %s\n", r->failed[i].id, r->failed[i].reason);
    for (size_t i = 0; i < r->nnot_watertight; i++)
        printf("    not watertight %s: %s\n", r->not_watertight[i].id, r->not_watertight[i].reason);
}

static void run_style(const ag_footprints *f, const char *label, const ag_style *s)
{
    ag_mesh *m = ag_mesh_create();
    ag_footprints_report r;
    ag_error err = {0};
    double t0 = now();
    ag_status st = ag_footprints_extrude(f, s, m, &r, &err);
    double dt = now() - t0;
    if (st != AG_OK) {
        printf("  %-22s error: %s\n", label, err.text);
    } else {
        printf("  %-22s %5zu footprints  %.3f s  failed %zu (%.3f%%)  not watertight %zu  "
               "triangles %zu  peak RSS %ld MB\n",
               label, r.footprints, dt, r.nfailed, 100.0 * r.nfailed / (r.footprints ? r.footprints : 1),
               r.nnot_watertight, r.triangles, peak_kb() / 1024);
        print_issues(&r);
    }
    ag_footprints_report_free(&r);
    ag_mesh_free(m);
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
            if (r.failing_faces) {
                leaky++;
                printf("    not watertight %s: face %d: %s\n", id, (int)r.problems[0].face,
                       r.problems[0].reason);
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

int main(void)
{
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
            for (size_t i = 0; i < sizeof styles / sizeof *styles; i++) {
                ag_style s;
                ag_style_builtin(styles[i], &s, NULL);
                char label[64];
                snprintf(label, sizeof label, "Den Haag %s", styles[i]);
                run_style(f, label, &s);
            }
            ag_footprints_free(f);
        }
    }
    generated_batch(3000);
    big_polygon(1000, "hip");
    big_polygon(1000, "mixed");
    big_polygon(2000, "hip");
    big_polygon(2000, "mixed");
    printf("  peak RSS %ld MB\n", peak_kb() / 1024);
    return 0;
}
