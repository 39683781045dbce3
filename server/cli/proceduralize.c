/* archgram proceduralize IN --out DIR [--up auto|y|z] [--unit U] [--tolerance REL] [--exact]
 *                          [--keep-groups]
 *
 * The proceduralize use case (app/usecase_proceduralize.h) from a mesh file into a folder
 * workspace (app/folder_ws.h): DIR/grammar.txt, terminals/, tree.json, summary.json. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../app/folder_ws.h"
#include "../app/usecase_proceduralize.h"
#include "commands.h"

#define USAGE                                                                                 \
    "usage: archgram proceduralize IN --out DIR [--up auto|y|z] [--unit U] [--tolerance REL]\n" \
    "                              [--exact] [--keep-groups]\n"

static int usage(void)
{
    fputs(USAGE, stderr);
    return 2;
}

int ag_cli_proceduralize(int argc, char **argv)
{
    if (ag_cli_points_wanted(argc, argv, AG_CLI_POINTS_PROCEDURALIZE)) /* a point cloud: cli/points.c */
        return ag_cli_points_proceduralize(argc, argv);
    const char *in = NULL, *dir = NULL;
    ag_up_axis up = AG_UP_DEFAULT;
    /* a grammar that misses triangles is still written, for a person to look at (exit 1) */
    ag_usecase_proceduralize_params p = {.save_unfaithful = 1};
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--out")) {
            if (++i >= argc)
                return usage();
            dir = argv[i];
        } else if (!strcmp(argv[i], "--up")) {
            if (++i >= argc || ag_cli_parse_up(argv[i], &up)) {
                fputs("archgram: --up takes auto, y or z\n", stderr);
                return 2;
            }
        } else if (!strcmp(argv[i], "--unit")) {
            if (++i >= argc || ag_units_named(argv[i], &p.label.metres_per_unit)) {
                fputs("archgram: --unit takes " AG_UNITS_NAMES "\n", stderr);
                return 2;
            }
        } else if (!strcmp(argv[i], "--tolerance")) {
            char *e;
            if (++i >= argc || (p.label.tolerance = strtod(argv[i], &e), *e) ||
                !(p.label.tolerance > 0 && p.label.tolerance < 0.1)) {
                fputs("archgram: --tolerance takes a number in (0, 0.1)\n", stderr);
                return 2;
            }
        } else if (!strcmp(argv[i], "--exact")) {
            p.label.exact_copies = 1;
        } else if (!strcmp(argv[i], "--keep-groups")) {
            p.segment.keep_groups = 1;
        } else if (!strcmp(argv[i], "--help")) {
            fputs(USAGE
                  "  --up auto|y|z    the file's up axis (auto: the format's, else the "
                  "content's)\n"
                  "  --unit U         the length unit of the file's coordinates: " AG_UNITS_NAMES
                  "\n                   (default: metres or millimetres, decided from the "
                  "content; FBX is read in m)\n"
                  "  --tolerance REL  labels and shared terminals, relative to the diagonal "
                  "(default 2e-4, at most 5 mm)\n"
                  "  --exact          share terminals between exact copies only: every "
                  "instance derives as it was\n"
                  "  --keep-groups    never split a group into its loose parts\n",
                  stdout);
            return 0;
        } else if (argv[i][0] == '-' && argv[i][1]) {
            fprintf(stderr, "archgram: proceduralize: unknown option %s\n", argv[i]);
            return usage();
        } else if (!in) {
            in = argv[i];
        } else {
            return usage();
        }
    }
    if (!in || !dir)
        return usage();

    ag_folder_ws w;
    ag_folder_ws_init(&w, &(ag_folder_ws_options){.mesh_path = in, .up = up, .out_dir = dir});
    ag_error err;
    ag_error_clear(&err);
    ag_usecase_proceduralize_result r;
    ag_status s = ag_usecase_proceduralize_run(&w.ws, &p, &r, &err);
    ag_workspace_close(&w.ws);
    if (s != AG_OK) {
        ag_cli_report(w.blamed ? w.blame : in, &err);
        return 1;
    }
    printf("%s: %zu triangles, %zu components, %zu labels (%zu variants), %zu rules, %zu patterns, "
           "%zu terminals; grammar %zu + terminals %zu bytes (input %zu); "
           "max error %.3g (%.3g of the diagonal), %zu unmatched; %.3f s\n",
           in, r.triangles, r.components, r.labels, r.variants, r.rules, r.patterns, r.terminals,
           r.grammar_bytes, r.terminal_bytes, w.input_bytes, r.fidelity.max_error,
           r.fidelity.relative, r.fidelity.unmatched, r.total_s);
    printf("%s: up axis %s (%s, score %.2f); label tolerance %.3g %s (units %s, %s)%s\n", in,
           w.up.axis == AG_UP_Z ? "z" : "y", ag_import_up_basis_name(w.up.basis),
           w.up.evidence.score, r.label_tolerance, r.units.name, r.units.name,
           r.units.given ? "request" : "content", p.label.exact_copies ? ", exact copies" : "");
    if (r.fidelity.unmatched) {
        fprintf(stderr, "archgram: %s: the grammar does not reproduce %zu input triangles\n", in,
                r.fidelity.unmatched);
        return 1;
    }
    return 0;
}
