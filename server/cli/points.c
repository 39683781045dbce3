/* Point models in the CLI: the point branches of `archgram proceduralize` and `derive`, run
 * when the input is a point cloud or a point grammar (`archgram edit` of a point model's folder
 * is cli/edit.c's, over the same folder workspace).
 *
 *   archgram proceduralize CLOUD --out DIR [--template BOX]... [--roi BOX]... [--no-auto]
 *                          [--threshold F] [--coarse-threshold F] [--json]
 *   archgram derive DIR/grammar.txt --out CLOUD.ply|.las|.xyz [--compare CLOUD] [--double]
 *
 * proceduralize is the use case of app/usecase_points.h over a folder (app/folder_ws.h, its
 * point operations app/points_folder_ws.h); derive reads the grammar with its PLY terminals and writes the
 * derived cloud in the input's coordinates. BOX is XMIN,YMIN,ZMIN,XMAX,YMAX,ZMAX in the cloud's
 * own coordinates. */
#include <jansson.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "../app/points_folder_ws.h"
#include "../app/usecase_points.h"
#include "../core/points/pointmodel.h"
#include "../io/edit_op_json.h"
#include "commands.h"

#define MAX_BOXES 64

int ag_cli_parse_cloud_box(const char *s, double box[6])
{
    char *end;
    for (int k = 0; k < 6; k++) {
        box[k] = strtod(s, &end);
        if (end == s || (k < 5 && *end != ',') || (k == 5 && *end))
            return -1;
        s = end + 1;
    }
    return box[0] <= box[3] && box[1] <= box[4] && box[2] <= box[5] ? 0 : -1;
}

/* The positional arguments of a command line whose options take one value unless listed in
 * flags (options without a value). */
static const char *positional(int argc, char **argv, const char *const *flags, int nth)
{
    int seen = 0;
    for (int i = 1; i < argc; i++) {
        if (argv[i][0] == '-' && argv[i][1]) {
            int flag = 0;
            for (const char *const *f = flags; *f && !flag; f++)
                flag = !strcmp(argv[i], *f);
            if (!flag)
                i++;
            continue;
        }
        if (seen++ == nth)
            return argv[i];
    }
    return NULL;
}

static const char *const proc_flags[] = {"--keep-groups", "--no-auto", "--json", "--help", NULL};
static const char *const plain_flags[] = {"--help", "--double", NULL};

int ag_cli_points_wanted(int argc, char **argv, ag_cli_points_command cmd)
{
    if (cmd == AG_CLI_POINTS_PROCEDURALIZE) {
        const char *in = positional(argc, argv, proc_flags, 0);
        return in && ag_cli_is_cloud_file(in);
    }
    const char *in = positional(argc, argv, plain_flags, 0);
    if (!in)
        return 0;
    return ag_points_grammar_file_is_points(in);
}

static int proc_usage(FILE *f)
{
    fputs("usage: archgram proceduralize CLOUD --out DIR [--template BOX]... [--roi BOX]...\n"
          "                              [--no-auto] [--threshold F] [--coarse-threshold F] "
          "[--json]\n"
          "  CLOUD                 a point cloud (PLY without faces, LAS, LAZ, XYZ)\n"
          "  --template BOX        a box around one repeated element (a window); its copies in\n"
          "                        the same facade get its label (may be given several times)\n"
          "  --roi BOX             segment the points in BOX again, finer (in order)\n"
          "  --no-auto             no automatic repetition (only the templates)\n"
          "  --threshold F         refinement plane threshold, a fraction of the diagonal (0.01)\n"
          "  --coarse-threshold F  first pass threshold, a fraction of the diagonal (0.025)\n"
          "  BOX is XMIN,YMIN,ZMIN,XMAX,YMAX,ZMAX in the cloud's coordinates.\n"
          "DIR gets grammar.txt, terminals/*.ply, tree.json and summary.json.\n",
          f);
    return f == stdout ? 0 : 2;
}

static int parse_fraction(const char *s, double *v)
{
    char *end;
    *v = strtod(s, &end);
    return *end || !(*v > 0 && *v < 1) ? -1 : 0;
}

int ag_cli_points_proceduralize(int argc, char **argv)
{
    const char *in = NULL, *dir = NULL;
    double tb[MAX_BOXES][6], rb[MAX_BOXES][6];
    int nt = 0, nr = 0, as_json = 0;
    ag_usecase_points_proceduralize_params p = {0};
    ag_proceduralize_cloud_options *o = &p.options;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        int more = i + 1 < argc;
        if (!strcmp(a, "--help"))
            return proc_usage(stdout);
        if (!strcmp(a, "--out") && more) {
            dir = argv[++i];
        } else if ((!strcmp(a, "--template") || !strcmp(a, "--roi")) && more) {
            int t = a[2] == 't';
            int *n = t ? &nt : &nr;
            if (*n == MAX_BOXES || ag_cli_parse_cloud_box(argv[++i], t ? tb[*n] : rb[*n])) {
                fprintf(stderr, "archgram: proceduralize: %s takes XMIN,YMIN,ZMIN,XMAX,YMAX,ZMAX "
                                "(at most %d boxes), not '%s'\n",
                        a, MAX_BOXES, argv[i]);
                return 2;
            }
            (*n)++;
        } else if (!strcmp(a, "--threshold") && more) {
            if (parse_fraction(argv[++i], &o->segment.fine_threshold)) {
                fprintf(stderr, "archgram: proceduralize: --threshold takes a fraction of the "
                                "diagonal between 0 and 1, not '%s'\n",
                        argv[i]);
                return 2;
            }
        } else if (!strcmp(a, "--coarse-threshold") && more) {
            if (parse_fraction(argv[++i], &o->segment.coarse_threshold)) {
                fprintf(stderr, "archgram: proceduralize: --coarse-threshold takes a fraction of "
                                "the diagonal between 0 and 1, not '%s'\n",
                        argv[i]);
                return 2;
            }
        } else if (!strcmp(a, "--no-auto")) {
            o->no_auto = 1;
        } else if (!strcmp(a, "--json")) {
            as_json = 1;
        } else if (a[0] == '-' && a[1]) {
            fprintf(stderr, "archgram: proceduralize: unknown or incomplete option %s\n", a);
            return proc_usage(stderr);
        } else if (!in) {
            in = a;
        } else {
            return proc_usage(stderr);
        }
    }
    if (!in || !dir)
        return proc_usage(stderr);
    /* boxes are in the cloud's coordinates (the use case moves them to its local frame) */
    ag_folder_ws w;
    ag_folder_ws_init(&w, &(ag_folder_ws_options){.cloud_path = in, .out_dir = dir});
    ag_box templates[MAX_BOXES], rois[MAX_BOXES];
    p.boxes_in_input = 1;
    for (int k = 0; k < nt; k++)
        templates[k] = (ag_box){{tb[k][0], tb[k][1], tb[k][2]}, {tb[k][3], tb[k][4], tb[k][5]}};
    for (int k = 0; k < nr; k++)
        rois[k] = (ag_box){{rb[k][0], rb[k][1], rb[k][2]}, {rb[k][3], rb[k][4], rb[k][5]}};
    o->templates = nt ? templates : NULL;
    o->ntemplates = (size_t)nt;
    o->rois = nr ? rois : NULL;
    o->nrois = (size_t)nr;
    ag_error err;
    ag_error_clear(&err);
    ag_usecase_points_proceduralize_result r;
    ag_status s = ag_usecase_points_proceduralize_run(&w.ws, &p, &r, &err);
    ag_workspace_close(&w.ws);
    if (s != AG_OK) {
        ag_cli_report(w.blamed ? w.blame : in, &err);
        return 1;
    }
    if (as_json) {
        json_t *j = json_object();
        json_object_set_new(j, "points", json_integer((json_int_t)r.points));
        json_object_set_new(j, "segments", json_integer((json_int_t)r.segments));
        json_object_set_new(j, "elements", json_integer((json_int_t)r.elements));
        json_object_set_new(j, "labels", json_integer((json_int_t)r.labels));
        json_object_set_new(j, "terminals", json_integer((json_int_t)r.terminals));
        json_object_set_new(j, "placements", json_integer((json_int_t)r.placements));
        json_object_set_new(j, "rules", json_integer((json_int_t)r.rules));
        json_object_set_new(j, "patterns", json_integer((json_int_t)r.patterns));
        json_object_set_new(j, "coverage", json_real(r.fidelity.coverage));
        json_object_set_new(j, "precision", json_real(r.fidelity.precision));
        json_object_set_new(j, "seconds", json_real(r.total_s));
        json_dumpf(j, stdout, JSON_INDENT(2) | JSON_PRESERVE_ORDER | JSON_REAL_PRECISION(6));
        putchar('\n');
        json_decref(j);
    } else {
        printf("%s: %zu points, %zu segments (%zu planes, %zu clusters, %zu elements), %zu labels, "
               "%zu terminals, %zu placements, %zu rules, %zu patterns; grammar %zu + terminals "
               "%zu bytes (input %zu); derived %zu points cover %.4f of the input (precision "
               "%.4f within %.3g m); %.3f s\n",
               in, r.points, r.segments, r.planes, r.clusters, r.elements, r.labels, r.terminals,
               r.placements, r.rules, r.patterns, r.grammar_bytes, r.terminal_bytes,
               w.input_bytes, r.derived_points, r.fidelity.coverage, r.fidelity.precision,
               r.fidelity.tolerance, r.total_s);
    }
    return 0;
}

int ag_cli_points_derive(int argc, char **argv)
{
    const char *gpath = NULL, *out = NULL, *cmp = NULL;
    int dbl = 0;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--out") && i + 1 < argc)
            out = argv[++i];
        else if (!strcmp(argv[i], "--compare") && i + 1 < argc)
            cmp = argv[++i];
        else if (!strcmp(argv[i], "--double"))
            dbl = 1;
        else if (argv[i][0] == '-' && argv[i][1]) {
            fprintf(stderr, "archgram: derive: unknown or incomplete option %s\n", argv[i]);
            return 2;
        } else if (!gpath)
            gpath = argv[i];
        else
            return 2;
    }
    if (!gpath || !out) {
        fputs("usage: archgram derive GRAMMAR --out CLOUD.ply|.las|.xyz [--compare CLOUD] "
              "[--double]\n",
              stderr);
        return 2;
    }
    if (!ag_cli_is_cloud_output(out)) {
        fprintf(stderr, "archgram: derive: %s: a point grammar derives a cloud: write .ply, .las "
                        "or .xyz\n",
                out);
        return 2;
    }
    ag_error err;
    ag_error_clear(&err);
    ag_pointmodel *pm = NULL;
    long col = 0;
    ag_status st = ag_points_folder_read_grammar(gpath, &pm, &err, &col);
    if (st) {
        if (st == AG_ERR_PARSE && err.element > 0)
            fprintf(stderr, "%s:%ld:%ld: %s\n", gpath, err.element, col, err.text);
        else
            ag_cli_report(gpath, &err);
        return 1;
    }
    ag_cloud *d = NULL, *input = NULL;
    ag_pointmodel_derive_info info;
    int rc = 1;
    if ((st = ag_pointmodel_derive(pm, 0, &d, &info, &err))) {
        ag_cli_report(gpath, &err);
        goto done;
    }
    if ((rc = ag_cli_write_cloud(d, out, dbl)))
        goto done;
    printf("%s: %zu points from %zu placements of %zu terminals (%zu stretched, %zu dropped at "
           "seams)\n",
           out, d->n, pm->nplacements, pm->nterminals, info.stretched, info.seam_dropped);
    if (cmp) {
        if (ag_cli_load_cloud(cmp, &input)) {
            rc = 1;
            goto done;
        }
        ag_pointmodel_fidelity f;
        if (ag_pointmodel_compare(input, d, 2 * pm->spacing, &f, &err)) {
            ag_cli_report(cmp, &err);
            rc = 1;
            goto done;
        }
        printf("compared with %s: %.4f of its %zu points within %.3g m of a derived point, %.4f "
               "of the %zu derived points within it of an input point\n",
               cmp, f.coverage, f.input, f.tolerance, f.precision, f.derived);
    }
done:
    ag_cloud_free(d);
    ag_cloud_free(input);
    ag_pointmodel_free(pm);
    return rc;
}
