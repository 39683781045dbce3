/* archgram extrude: one plan (building description JSON) or a GeoJSON batch with a style
 * into an OBJ or GLB shell, with a JSON report for batches.
 *
 * Every building runs under a budget (--max-events, --timeout, per building) and is
 * checked (closed 2-manifold within reach of its footprint); a batch retries a building
 * that is not good on a simplified footprint, then falls back to a flat roof, then to a
 * block, and reports each one. Ctrl-C or SIGTERM stops the work within milliseconds. */
#include <errno.h>
#include <jansson.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "commands.h"
#include "../app/extrude_batch.h"
#include "../core/extrude/extrude.h"
#include "../core/extrude/style.h"
#include "../core/mesh.h"
#include "../io/footprints.h"
#include "../io/glb.h"
#include "../io/obj.h"
#include "../io/plan_json.h"

/* Per building: the time a footprint of a city may take before it falls back. */
#define DEFAULT_TIMEOUT 10.0

static volatile sig_atomic_t interrupted;

static void on_signal(int sig)
{
    (void)sig;
    interrupted = 1;
}

static int cancelled(void *user)
{
    (void)user;
    return interrupted != 0;
}

static void usage(void)
{
    fprintf(stderr,
            "usage: archgram extrude --plan PLAN.json --out OUT.obj|OUT.glb [budget]\n"
            "       archgram extrude FOOTPRINTS.geojson --style STYLE.json|flat|hip|gable|mansard|overhang\n"
            "                        --out OUT.obj|OUT.glb [--report R.json] [--height-property NAME]\n"
            "                        [--seed N] [--lonlat|--metres] [--threads N] [budget]\n"
            "budget, per building: [--max-events N] (default 100000 + 4000 per corner)\n"
            "                      [--timeout SECONDS] (default %g; 0: none)\n",
            DEFAULT_TIMEOUT);
}

static int ends_with(const char *s, const char *suffix)
{
    size_t a = strlen(s), b = strlen(suffix);
    return a >= b && strcasecmp(s + a - b, suffix) == 0;
}

static ag_status write_mesh(const ag_mesh *m, const char *out, ag_error *err)
{
    if (ends_with(out, ".glb"))
        return ag_glb_write_file(m, out, err);
    return ag_obj_write_file(m, AG_UP_DEFAULT, out, err);
}

static void print_fixes(const char *where, const ag_plan_fixes *fx)
{
    for (size_t i = 0; i < fx->n; i++) {
        const ag_plan_fix *f = &fx->fixes[i];
        if (f->corner >= 0)
            printf("%s: fixed loop %ld corner %ld: %s\n", where, f->loop, f->corner, f->reason);
        else
            printf("%s: fixed loop %ld: %s\n", where, f->loop, f->reason);
    }
}

static int run_plan(const char *plan_path, const char *out, const ag_extrude_options *opt)
{
    ag_error err = {0};
    ag_plan *plan = NULL;
    if (ag_plan_json_read_file(plan_path, &plan, &err) != AG_OK) {
        fprintf(stderr, "archgram extrude: %s: %s\n", plan_path, err.text);
        return 1;
    }
    ag_mesh *m = ag_mesh_create();
    size_t g = 0;
    const char *base = strrchr(plan_path, '/');
    base = base ? base + 1 : plan_path;
    ag_extrude_result r;
    ag_plan_fixes fixes = {0};
    ag_extrude_options o = *opt;
    o.fixes = &fixes;
    ag_status st = m ? ag_mesh_add_group(m, base, &g) : AG_ERR_NOMEM;
    if (st == AG_OK)
        st = ag_extrude_plan_with(plan, &o, m, (int32_t)g, &r, NULL, &err);
    print_fixes(plan_path, &fixes);
    ag_plan_fixes_free(&fixes);
    for (size_t i = 0; st == AG_OK && i < plan->nanchors; i++) {
        const ag_anchor *a = &plan->anchors[i];
        if (a->found)
            printf("anchor %s: (%.4f, %.4f, %.4f) normal (%.3f, %.3f, %.3f) face %d%s%s\n", a->name,
                   a->pos[0], a->pos[1], a->pos[2], a->normal[0], a->normal[1], a->normal[2],
                   (int)a->face, a->mesh > 0 ? " mesh " : "",
                   a->mesh > 0 ? plan->meshes[a->mesh - 1].name : "");
        else
            printf("anchor %s: not instanced (the edge is gone or too short there)\n", a->name);
    }
    size_t placed = 0;
    if (st == AG_OK)
        st = ag_extrude_place_meshes(plan, m, (int32_t)g, &placed, &err);
    if (st == AG_OK && placed)
        printf("meshes placed at anchors: %zu\n", placed);
    ag_plan_free(plan);
    if (st != AG_OK) {
        fprintf(stderr, "archgram extrude: %s: %s%s\n", plan_path,
                err.text[0] ? err.text : ag_status_message(st),
                st == AG_ERR_TOO_LARGE ? " (raise --max-events or --timeout)" : "");
        ag_mesh_free(m);
        return 1;
    }
    if (r.stats.steps || r.stats.steps_skipped)
        printf("plan edits: %zu made, %zu skipped (anchor not on the plan at its height)\n",
               r.stats.steps, r.stats.steps_skipped);
    if (r.stats.irregular)
        fprintf(stderr, "archgram extrude: warning: %zu intersection(s) with nested chains; the "
                        "roof may look odd there\n", r.stats.irregular);
    for (size_t i = 0; i < r.failing_faces && i < AG_EXTRUDE_MAX_PROBLEMS; i++)
        fprintf(stderr, "archgram extrude: face %d: %s\n", (int)r.problems[i].face,
                r.problems[i].reason);
    if (r.defect[0])
        fprintf(stderr, "archgram extrude: the building is not good: %s\n", r.defect);
    st = write_mesh(m, out, &err);
    ag_mesh_free(m);
    if (st != AG_OK) {
        fprintf(stderr, "archgram extrude: %s: %s\n", out, err.text);
        return 1;
    }
    int ok = ag_extrude_result_ok(&r);
    printf("%s: %zu faces, %zu triangles, height %.3f m, %zu events, %.3f s, %s\n", out, r.faces,
           r.triangles, r.top, r.stats.events, r.seconds,
           ok ? "closed 2-manifold" : "NOT a good building (see above)");
    return ok ? 0 : 1;
}

static int run_batch(const char *in, const char *style_arg, const char *out, const char *report,
                     const char *height_prop, long seed, int lonlat,
                     const ag_extrude_batch_options *bo)
{
    ag_error err = {0};
    ag_style style;
    if (ag_style_builtin(style_arg, &style, NULL) != AG_OK &&
        ag_plan_json_read_style_file(style_arg, &style, &err) != AG_OK) {
        fprintf(stderr, "archgram extrude: style %s: %s\n", style_arg,
                err.text[0] ? err.text : "not a built-in style name nor a readable style file");
        return 2;
    }
    if (seed >= 0)
        style.seed = (uint64_t)seed;
    ag_footprints_options fo = {height_prop, lonlat};
    ag_footprints *f = NULL;
    double t0 = ag_cli_seconds();
    if (ag_footprints_read_file(in, &fo, &f, &err) != AG_OK) {
        fprintf(stderr, "archgram extrude: %s: %s\n", in, err.text);
        return 1;
    }
    ag_mesh *m = ag_mesh_create();
    ag_footprints_report r;
    memset(&r, 0, sizeof r);
    ag_status st = m ? ag_extrude_batch(f, &style, bo, m, &r, &err) : AG_ERR_NOMEM;
    double dt = ag_cli_seconds() - t0;
    if (st != AG_OK) {
        fprintf(stderr, "archgram extrude: %s: %s\n", in,
                st == AG_ERR_CANCELLED ? "interrupted: nothing written" : err.text);
        ag_footprints_report_free(&r);
        ag_mesh_free(m);
        ag_footprints_free(f);
        return 1;
    }
    st = write_mesh(m, out, &err);
    int rc = st == AG_OK ? 0 : 1;
    if (st != AG_OK)
        fprintf(stderr, "archgram extrude: %s: %s\n", out, err.text);
    if (report) {
        json_t *j = ag_footprints_report_json(&r);
        if (j && json_object_update_new(j, json_pack("{s:f,s:s,s:b,s:[f,f],s:I}", "seconds", dt,
                                                     "style", style.name, "lonlat", f->lonlat,
                                                     "origin", f->origin[0], f->origin[1],
                                                     "skipped_features",
                                                     (json_int_t)f->skipped)) != 0) {
            json_decref(j);
            j = NULL;
        }
        if (!j || json_dump_file(j, report, JSON_INDENT(2)) != 0) {
            fprintf(stderr, "archgram extrude: cannot write %s\n", report);
            rc = 1;
        }
        json_decref(j);
    }
    printf("%s: %zu footprints, %zu succeeded, %zu fell back, %zu failed, %zu triangles, %.3f s\n",
           out, r.footprints, r.succeeded, r.nfallbacks, r.nfailed, r.triangles, dt);
    for (size_t i = 0; i < r.nfixed; i++)
        printf("  fixed %s: %s\n", r.fixed[i].id, r.fixed[i].reason);
    for (size_t i = 0; i < r.nfallbacks; i++) {
        const ag_footprint_issue *x = &r.fallbacks[i];
        if (x->built == AG_BUILT_SIMPLIFIED)
            fprintf(stderr, "  fell back %s: simplified (boundary moved up to %.3g m): %s\n",
                    x->id, x->moved, x->reason);
        else
            fprintf(stderr, "  fell back %s: %s: %s\n", x->id, ag_built_name(x->built), x->reason);
    }
    for (size_t i = 0; i < r.nfailed; i++)
        fprintf(stderr, "  failed %s: %s\n", r.failed[i].id, r.failed[i].reason);
    ag_footprints_report_free(&r);
    ag_mesh_free(m);
    ag_footprints_free(f);
    return rc;
}

/* A non-negative number for a flag; -1 when it is not one. */
static double number_arg(const char *s)
{
    char *end = NULL;
    errno = 0;
    double v = strtod(s, &end);
    return errno || end == s || *end || !(v >= 0) ? -1 : v;
}

int ag_cli_extrude(int argc, char **argv)
{
    const char *plan = NULL, *out = NULL, *style = NULL, *report = NULL, *input = NULL;
    const char *height_prop = NULL;
    long seed = -1;
    int lonlat = 0;
    ag_extrude_batch_options bo;
    memset(&bo, 0, sizeof bo);
    bo.extrude.budget.max_seconds = DEFAULT_TIMEOUT;
    bo.extrude.budget.cancelled = cancelled;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        int more = i + 1 < argc;
        if (strcmp(a, "--plan") == 0 && more)
            plan = argv[++i];
        else if (strcmp(a, "--out") == 0 && more)
            out = argv[++i];
        else if (strcmp(a, "--style") == 0 && more)
            style = argv[++i];
        else if (strcmp(a, "--report") == 0 && more)
            report = argv[++i];
        else if (strcmp(a, "--height-property") == 0 && more)
            height_prop = argv[++i];
        else if (strcmp(a, "--seed") == 0 && more)
            seed = strtol(argv[++i], NULL, 10);
        else if (strcmp(a, "--lonlat") == 0)
            lonlat = 1;
        else if (strcmp(a, "--metres") == 0 || strcmp(a, "--meters") == 0)
            lonlat = -1;
        else if ((strcmp(a, "--max-events") == 0 || strcmp(a, "--timeout") == 0 ||
                  strcmp(a, "--threads") == 0) && more) {
            double v = number_arg(argv[++i]);
            int whole = strcmp(a, "--timeout") != 0;
            if (v < 0 || (whole && v != floor(v))) {
                fprintf(stderr, "archgram extrude: %s needs a non-negative %s, not '%s'\n", a,
                        whole ? "whole number" : "number of seconds", argv[i]);
                return 2;
            }
            if (strcmp(a, "--max-events") == 0)
                bo.extrude.budget.max_events = (size_t)v;
            else if (strcmp(a, "--timeout") == 0)
                bo.extrude.budget.max_seconds = v > 0 ? v : -1; /* 0: none */
            else
                bo.threads = (size_t)v;
        } else if (a[0] != '-' && !input)
            input = a;
        else {
            usage();
            return 2;
        }
    }
    if (!out || (!plan && !input) || (plan && input)) {
        usage();
        return 2;
    }
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
    if (plan)
        return run_plan(plan, out, &bo.extrude);
    return run_batch(input, style ? style : "hip", out, report, height_prop, seed, lonlat, &bo);
}
