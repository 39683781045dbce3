/* archgram segment CLOUD --out SEG.ply [--roi BOX]... [--template BOX]... [--auto]
 *                  [--threshold F] [--coarse-threshold F] [--recompute-normals] [--json]
 * Segments a point cloud into planes and clusters (§3.1), then marks repetitions (§3.2: the
 * copies of each template box in its facade, and with --auto the automatic elements), and
 * writes every input point, in input order, with its properties and int properties segment,
 * label and piece (a template's copies share its label). */
#include <jansson.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../core/points/repeat.h"
#include "../core/points/segment_cloud.h"
#include "commands.h"

#define MAX_ROI 16

static int usage(FILE *f)
{
    fputs("usage: archgram segment CLOUD --out SEG.ply|SEG.las [--roi XMIN,YMIN,ZMIN,XMAX,YMAX,ZMAX]...\n"
          "                        [--template XMIN,YMIN,ZMIN,XMAX,YMAX,ZMAX]... [--auto]\n"
          "                        [--threshold F] [--coarse-threshold F] [--recompute-normals]\n"
          "                        [--double] [--json]\n"
          "  --threshold F         refinement plane threshold, a fraction of the diagonal (0.01)\n"
          "  --coarse-threshold F  first pass threshold, a fraction of the diagonal (0.025)\n"
          "  --roi BOX             segment the points in BOX again, finer (input coordinates;\n"
          "                        may be given several times, applied in order)\n"
          "  --template BOX        a box around one repeated element (a window): its copies in\n"
          "                        the same facade become elements with its label (input\n"
          "                        coordinates; may be given several times)\n"
          "  --auto                mark the repeated elements found without a template too\n"
          "  --recompute-normals   use kNN normals even when the cloud has its own\n"
          "  --double              write absolute double coordinates instead of float + offset\n",
          f);
    return f == stdout ? 0 : 2;
}

static int parse_fraction(const char *s, double *v)
{
    char *end;
    *v = strtod(s, &end);
    return *end || !(*v > 0 && *v < 1) ? -1 : 0;
}


/* Replaces (or adds) an int32 property with the given values. */
static int set_ids(ag_cloud *c, const char *name, const int32_t *values)
{
    ag_cloud_remove_property(c, name);
    size_t i;
    ag_error err;
    if (ag_cloud_add_property(c, name, AG_SCALAR_INT32, &i, &err) != AG_OK) {
        fprintf(stderr, "archgram segment: %s\n", err.text);
        return -1;
    }
    memcpy(c->props[i].values, values, c->n * sizeof *values);
    return 0;
}

int ag_cli_segment(int argc, char **argv)
{
    const char *in = NULL, *out = NULL;
    double rois[MAX_ROI][6], tmpl[MAX_ROI][6];
    const char *tmpl_arg[MAX_ROI];
    int nroi = 0, ntmpl = 0, as_json = 0, dbl = 0, autorep = 0;
    ag_segment_cloud_options o = {0};
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        int more = i + 1 < argc;
        if (!strcmp(a, "--help"))
            return usage(stdout);
        if (!strcmp(a, "--out") && more) {
            out = argv[++i];
        } else if (!strcmp(a, "--threshold") && more) {
            if (parse_fraction(argv[++i], &o.fine_threshold)) {
                fprintf(stderr, "archgram segment: --threshold takes a fraction of the diagonal "
                                "between 0 and 1, not '%s'\n",
                        argv[i]);
                return 2;
            }
        } else if (!strcmp(a, "--coarse-threshold") && more) {
            if (parse_fraction(argv[++i], &o.coarse_threshold)) {
                fprintf(stderr, "archgram segment: --coarse-threshold takes a fraction of the "
                                "diagonal between 0 and 1, not '%s'\n",
                        argv[i]);
                return 2;
            }
        } else if (!strcmp(a, "--roi") && more) {
            if (nroi == MAX_ROI || ag_cli_parse_cloud_box(argv[++i], rois[nroi])) {
                fprintf(stderr, "archgram segment: --roi takes XMIN,YMIN,ZMIN,XMAX,YMAX,ZMAX "
                                "(at most %d boxes), not '%s'\n",
                        MAX_ROI, argv[i]);
                return 2;
            }
            nroi++;
        } else if (!strcmp(a, "--template") && more) {
            if (ntmpl == MAX_ROI || ag_cli_parse_cloud_box(argv[++i], tmpl[ntmpl])) {
                fprintf(stderr, "archgram segment: --template takes XMIN,YMIN,ZMIN,XMAX,YMAX,ZMAX "
                                "(at most %d boxes), not '%s'\n",
                        MAX_ROI, argv[i]);
                return 2;
            }
            tmpl_arg[ntmpl++] = argv[i];
        } else if (!strcmp(a, "--auto")) {
            autorep = 1;
        } else if (!strcmp(a, "--recompute-normals")) {
            o.recompute_normals = 1;
        } else if (!strcmp(a, "--double")) {
            dbl = 1;
        } else if (!strcmp(a, "--json")) {
            as_json = 1;
        } else if (a[0] == '-' && a[1]) {
            fprintf(stderr, "archgram segment: unknown or incomplete option %s\n", a);
            return usage(stderr);
        } else if (!in) {
            in = a;
        } else {
            return usage(stderr);
        }
    }
    if (!in || !out)
        return usage(stderr);
    if (!ag_cli_is_cloud_output(out)) {
        fprintf(stderr, "archgram segment: %s: write .ply or .las\n", out);
        return 2;
    }
    double t0 = ag_cli_seconds();
    ag_cloud *c;
    if (ag_cli_load_cloud(in, &c))
        return 1;
    double t_read = ag_cli_seconds() - t0;
    ag_error err;
    ag_error_clear(&err);
    ag_segment_cloud_result *r = NULL;
    ag_status st = ag_segment_cloud_run(c, &o, &r, &err);
    for (int k = 0; st == AG_OK && k < nroi; k++) {
        double mn[3], mx[3];
        for (int a = 0; a < 3; a++) {
            mn[a] = rois[k][a] - c->offset[a];
            mx[a] = rois[k][3 + a] - c->offset[a];
        }
        st = ag_segment_cloud_refine(c, r, mn, mx, &o, &err);
    }
    size_t matches = 0;
    double t_rep = ag_cli_seconds();
    for (int k = 0; st == AG_OK && k < ntmpl; k++) {
        ag_box b;
        for (int a = 0; a < 3; a++) {
            b.min[a] = tmpl[k][a] - c->offset[a];
            b.max[a] = tmpl[k][3 + a] - c->offset[a];
        }
        ag_repeat_report rep = {0};
        st = ag_repeat_template(c, r, &b, NULL, &rep, &err);
        if (st != AG_OK) {
            fprintf(stderr, "%s: --template %s: %s\n", in, tmpl_arg[k], err.text);
            ag_segment_cloud_free(r);
            ag_cloud_free(c);
            return 1;
        }
        matches += rep.nmatches;
        ag_repeat_report_clear(&rep);
    }
    if (st == AG_OK && autorep)
        st = ag_repeat_auto(c, r, NULL, NULL, &err);
    t_rep = ag_cli_seconds() - t_rep;
    if (st != AG_OK) {
        ag_cli_report(in, &err);
        ag_segment_cloud_free(r);
        ag_cloud_free(c);
        return 1;
    }
    int rc = set_ids(c, "segment", r->segment) || set_ids(c, "label", r->label) ||
                     set_ids(c, "piece", r->piece)
                 ? 1
                 : 0;
    double t1 = ag_cli_seconds();
    if (!rc)
        rc = ag_cli_write_cloud(c, out, dbl);
    double t_write = ag_cli_seconds() - t1;
    size_t none = 0;
    for (size_t i = 0; i < r->n; i++)
        none += r->segment[i] < 0;
    if (!rc) {
        if (as_json) {
            json_t *j = json_object(), *sec = json_object();
            json_object_set_new(j, "points", json_integer((json_int_t)r->n));
            json_object_set_new(j, "segments", json_integer((json_int_t)ag_segment_cloud_in_use(r)));
            json_object_set_new(j, "planes", json_integer((json_int_t)r->nplanes));
            json_object_set_new(j, "clusters", json_integer((json_int_t)r->nclusters));
            json_object_set_new(j, "pieces", json_integer((json_int_t)r->npieces));
            json_object_set_new(j, "elements", json_integer((json_int_t)r->nelements));
            json_object_set_new(j, "template_matches", json_integer((json_int_t)matches));
            json_object_set_new(j, "labels", json_integer((json_int_t)r->nlabels));
            json_object_set_new(j, "unsegmented", json_integer((json_int_t)none));
            json_object_set_new(j, "diagonal", json_real(r->diagonal));
            json_object_set_new(j, "spacing", json_real(r->spacing));
            json_object_set_new(j, "coarse_threshold", json_real(r->coarse_threshold));
            json_object_set_new(j, "fine_threshold", json_real(r->fine_threshold));
            json_object_set_new(j, "cluster_tolerance", json_real(r->cluster_tolerance));
            json_object_set_new(sec, "read", json_real(t_read));
            for (int s = 0; s < AG_SEGMENT_CLOUD_STAGES; s++)
                json_object_set_new(sec, ag_segment_cloud_stage_name(s), json_real(r->seconds[s]));
            json_object_set_new(sec, "repeat", json_real(t_rep));
            json_object_set_new(sec, "write", json_real(t_write));
            json_object_set_new(j, "seconds", sec);
            json_dumpf(j, stdout, JSON_INDENT(2) | JSON_PRESERVE_ORDER | JSON_REAL_PRECISION(6));
            putchar('\n');
            json_decref(j);
        } else {
            printf("%zu points: %zu planes, %zu clusters, %zu elements (%zu pieces), %zu labels, "
                   "%zu unsegmented\n",
                   r->n, r->nplanes, r->nclusters, r->nelements, r->npieces, r->nlabels, none);
            if (ntmpl)
                printf("templates: %d, %zu matches (the templates included)\n", ntmpl, matches);
            printf("seconds: read %.3f", t_read);
            for (int s = 0; s < AG_SEGMENT_CLOUD_STAGES; s++)
                printf(", %s %.3f", ag_segment_cloud_stage_name(s), r->seconds[s]);
            printf(", repeat %.3f, write %.3f\n", t_rep, t_write);
        }
    }
    ag_segment_cloud_free(r);
    ag_cloud_free(c);
    return rc;
}
