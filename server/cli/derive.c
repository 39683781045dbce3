/* archgram derive GRAMMAR --out FILE.obj|FILE.glb [--compare MESH [--up y|z] [--tolerance M]] */
#include <errno.h>
#include <jansson.h>
#include <libgen.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../core/base/tolerance.h"
#include "../core/proc/proceduralize.h"
#include "../io/glb.h"
#include "../io/grammar_text.h"
#include "../io/terminals.h"
#include "commands.h"

#define USAGE                                                                                 \
    "usage: archgram derive GRAMMAR --out FILE.obj|FILE.glb [--compare MESH [--up y|z] "       \
    "[--tolerance METRES]]\n"

static int usage(void)
{
    fputs(USAGE, stderr);
    return 2;
}

/* The label tolerance the grammar was made with (summary.json next to it, `labeling`), in
 * metres: members of a label share a terminal within it, so the comparison allows it. 0
 * (the comparison's own default, 1e-5 of the diagonal) when there is no summary or the
 * grammar shares terminals between exact copies only (--exact: it derives the input as it
 * was). */
static double grammar_tolerance(const char *dir)
{
    char path[4096];
    if (snprintf(path, sizeof path, "%s/summary.json", dir) >= (int)sizeof path)
        return 0;
    json_t *root = json_load_file(path, 0, NULL);
    json_t *lab = json_object_get(root, "labeling");
    double tol = json_is_true(json_object_get(lab, "exact_copies"))
                     ? 0
                     : json_number_value(json_object_get(lab, "tolerance"));
    json_decref(root);
    return isfinite(tol) && tol > 0 ? tol : 0;
}

static int ends_with(const char *s, const char *suf)
{
    size_t a = strlen(s), b = strlen(suf);
    return a >= b && !strcasecmp(s + a - b, suf);
}

/* OBJ + MTL: one `usemtl` material per label, colours spread over the hue circle. */
static int write_obj_mtl(const ag_mesh *m, const char *path)
{
    char mtl[4096];
    snprintf(mtl, sizeof mtl, "%s", path);
    size_t n = strlen(mtl);
    if (n >= 4)
        mtl[n - 4] = 0;
    strncat(mtl, ".mtl", sizeof mtl - strlen(mtl) - 1);
    FILE *fm = fopen(mtl, "w");
    FILE *f = fopen(path, "w");
    if (!f || !fm) {
        fprintf(stderr, "archgram: cannot write %s: %s\n", !f ? path : mtl, strerror(errno));
        if (f)
            fclose(f);
        if (fm)
            fclose(fm);
        return 1;
    }
    for (size_t g = 0; g < m->ngroups; g++) {
        double h = g * 0.618033988749895, r, gg, b;
        h -= (long)h;
        double x = h * 6;
        int i = (int)x;
        double fr = x - i;
        double v = 0.85, s = 0.55, p = v * (1 - s), q = v * (1 - s * fr), t = v * (1 - s * (1 - fr));
        switch (i % 6) {
        case 0: r = v, gg = t, b = p; break;
        case 1: r = q, gg = v, b = p; break;
        case 2: r = p, gg = v, b = t; break;
        case 3: r = p, gg = q, b = v; break;
        case 4: r = t, gg = p, b = v; break;
        default: r = v, gg = p, b = q; break;
        }
        fprintf(fm, "newmtl %s\nKd %.3f %.3f %.3f\n\n", m->group_names[g], r, gg, b);
    }
    const char *base = strrchr(mtl, '/');
    /* OBJ's convention is y up: archgram's (x, y, z) is written as (x, z, -y) */
    fprintf(f, "# derived by archgram from a split grammar; y up\nmtllib %s\n",
            base ? base + 1 : mtl);
    for (size_t v = 0; v < m->nverts; v++) {
        double y = -m->pos[3 * v + 1];
        fprintf(f, "v %.10g %.10g %.10g\n", m->pos[3 * v], m->pos[3 * v + 2], y == 0 ? 0 : y);
    }
    size_t t = 0;
    for (size_t c = 0; c < m->ncomponents; c++) {
        int32_t g = m->component_group[c];
        const char *name = g >= 0 ? m->group_names[g] : "none";
        fprintf(f, "g %s_%zu\nusemtl %s\n", name, c, name);
        /* derivation emits components in order, each with consecutive triangles */
        while (t < m->ntris && m->tri_component[t] == c) {
            fprintf(f, "f %u %u %u\n", m->tri[3 * t] + 1, m->tri[3 * t + 1] + 1,
                    m->tri[3 * t + 2] + 1);
            t++;
        }
    }
    int bad = ferror(f) | ferror(fm);
    bad |= fclose(f) != 0;
    bad |= fclose(fm) != 0;
    if (bad) {
        fprintf(stderr, "archgram: cannot write %s\n", path);
        return 1;
    }
    return 0;
}

int ag_cli_derive(int argc, char **argv)
{
    if (ag_cli_points_wanted(argc, argv, AG_CLI_POINTS_DERIVE)) /* a point cloud: cli/points.c */
        return ag_cli_points_derive(argc, argv);
    const char *gpath = NULL, *out = NULL, *cmp = NULL;
    ag_up_axis up = AG_UP_DEFAULT;
    double tol = -1;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--out")) {
            if (++i >= argc)
                return usage();
            out = argv[i];
        } else if (!strcmp(argv[i], "--compare")) {
            if (++i >= argc)
                return usage();
            cmp = argv[i];
        } else if (!strcmp(argv[i], "--tolerance")) {
            char *end;
            if (++i >= argc)
                return usage();
            tol = strtod(argv[i], &end);
            if (end == argv[i] || *end || !isfinite(tol) || tol <= 0) {
                fprintf(stderr, "archgram: derive: --tolerance must be a positive number of "
                                "metres, not '%s'\n",
                        argv[i]);
                return 2;
            }
        } else if (!strcmp(argv[i], "--up")) {
            if (++i >= argc || ag_cli_parse_up(argv[i], &up))
                return usage();
        } else if (!strcmp(argv[i], "--help")) {
            fputs(USAGE "  --tolerance M  how far the derivation may lie from MESH (default: the "
                        "label tolerance\n"
                        "                 in summary.json next to GRAMMAR, else 1e-5 of the "
                        "diagonal)\n",
                  stdout);
            return 0;
        } else if (argv[i][0] == '-' && argv[i][1]) {
            fprintf(stderr, "archgram: derive: unknown option %s\n", argv[i]);
            return usage();
        } else if (!gpath) {
            gpath = argv[i];
        } else {
            return usage();
        }
    }
    if (!gpath || !out || !(ends_with(out, ".obj") || ends_with(out, ".glb")))
        return usage();
    ag_error err;
    ag_error_clear(&err);
    ag_grammar *g = NULL;
    long col = 0;
    ag_status st = ag_grammar_text_read_file(gpath, &g, &err, &col);
    if (st) {
        if (st == AG_ERR_PARSE)
            fprintf(stderr, "%s:%ld:%ld: %s\n", gpath, err.element, col, err.text);
        else
            ag_cli_report(gpath, &err);
        return 1;
    }
    char *dcopy = strdup(gpath);
    int rc = 1;
    ag_mesh *m = NULL, *input = NULL;
    if (!dcopy)
        goto done;
    if (ag_terminals_load(g, dirname(dcopy), &err) || ag_grammar_derive(g, NULL, &m, &err)) {
        ag_cli_report(gpath, &err);
        goto done;
    }
    if (ends_with(out, ".glb")) {
        if (ag_glb_write_file(m, out, &err)) {
            ag_cli_report(out, &err);
            goto done;
        }
    } else if (write_obj_mtl(m, out)) {
        goto done;
    }
    printf("%s: %zu triangles, %zu vertices, %zu placed terminals\n", out, m->ntris, m->nverts,
           m->ncomponents);
    rc = 0;
    if (cmp) {
        size_t bytes;
        if (ag_cli_load_mesh(cmp, up, &input, &bytes)) {
            rc = 1;
            goto done;
        }
        ag_fidelity f;
        if (tol < 0) {
            char *dcopy2 = strdup(gpath);
            tol = dcopy2 ? grammar_tolerance(dirname(dcopy2)) : 0;
            free(dcopy2);
        }
        /* the input cut into components as proceduralize cuts it, so that its components
         * pair with the placed terminals */
        ag_mesh *seg = NULL;
        if (ag_segment_run(input, NULL, &seg, NULL, &err)) {
            ag_cli_report(cmp, &err);
            rc = 1;
            goto done;
        }
        ag_mesh_free(input);
        input = seg;
        if (ag_grammar_fidelity(input, m, tol, &f, &err)) {
            ag_cli_report(cmp, &err);
            rc = 1;
            goto done;
        }
        ag_box b = ag_mesh_bounds(input);
        printf("compared with %s: max error %.3g (%.3g of the diagonal), %zu of %zu input "
               "triangles unmatched within %.3g m\n",
               cmp, f.max_error, f.relative, f.unmatched, f.input_triangles,
               tol > 0 ? tol : AG_PROC_FIDELITY * ag_box_diagonal(&b));
        rc = f.unmatched ? 1 : 0;
    }
done:
    free(dcopy);
    ag_mesh_free(m);
    ag_mesh_free(input);
    ag_grammar_free(g);
    return rc;
}
