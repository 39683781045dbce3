/* archgram edit DIR --op OP.json --out DIR2
 *
 * The edit use case (app/usecase_edit.h) between two folder workspaces (app/folder_ws.h).
 * DIR holds a proceduralized model as `archgram proceduralize` (or an earlier edit) writes
 * it: grammar.txt and terminals/. The grammar is derived and proceduralized again, which
 * gives the tree whose node ids the op names (DIR/tree.json lists them). DIR2 receives the
 * edited model's grammar.txt, terminals/, tree.json (ids for the next edit) and summary.json
 * (the solve figures and instances per label). A paste may copy from another proceduralized
 * folder: "source_dir" in the op, relative to the op file's folder (node ids of its tree.json).
 * A point model's folder (its grammar names PLY terminals, app/points_folder_ws.h) is edited
 * by the point edit use case (app/usecase_points.h) over the same workspace. */
#include <stdio.h>
#include <string.h>

#include "../app/folder_ws.h"
#include "../app/points_folder_ws.h"
#include "../app/usecase_edit.h"
#include "../app/usecase_points.h"
#include "../io/edit_op_json.h"
#include "commands.h"

static int usage(void)
{
    fputs("usage: archgram edit DIR --op OP.json --out DIR2\n", stderr);
    return 2;
}

int ag_cli_edit(int argc, char **argv)
{
    const char *dir = NULL, *oppath = NULL, *out = NULL;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--op")) {
            if (++i >= argc)
                return usage();
            oppath = argv[i];
        } else if (!strcmp(argv[i], "--out")) {
            if (++i >= argc)
                return usage();
            out = argv[i];
        } else if (!strcmp(argv[i], "--help")) {
            fputs("usage: archgram edit DIR --op OP.json --out DIR2\n", stdout);
            return 0;
        } else if (argv[i][0] == '-' && argv[i][1]) {
            fprintf(stderr, "archgram: edit: unknown option %s\n", argv[i]);
            return usage();
        } else if (!dir) {
            dir = argv[i];
        } else {
            return usage();
        }
    }
    if (!dir || !oppath || !out)
        return usage();

    ag_error err;
    ag_error_clear(&err);
    ag_edit_op op;
    ag_edit_op_origin from;
    if (ag_edit_op_json_read_file_ex(oppath, &op, &from, &err)) {
        ag_cli_report(oppath, &err);
        return 1;
    }
    ag_folder_ws w;
    ag_folder_ws_init(&w, &(ag_folder_ws_options){.in_dir = dir, .op_path = oppath,
                                                  .out_dir = out});
    ag_usecase_edit_result r = {0};
    ag_usecase_points_edit_result pr = {0};
    int points = ag_points_folder_is_point_model(dir);
    ag_status s = points ? ag_usecase_points_edit_run(
                               &w.ws, &(ag_usecase_points_edit_params){&op, &from}, &pr, &err)
                         : ag_usecase_edit_run(&w.ws, &(ag_usecase_edit_params){&op, &from}, &r,
                                               &err);
    ag_workspace_close(&w.ws);
    const ag_edit_report *rep = points ? &pr.report : &r.report;
    if (s != AG_OK) {
        /* errors that name an op field are the op file's; the rest are the model's */
        const char *file = w.blamed                                    ? w.blame
                           : s == AG_ERR_INVALID || s == AG_ERR_NOT_FOUND ? oppath
                                                                          : dir;
        ag_cli_report(file, &err);
    } else {
        char placements[48] = "";
        if (points)
            snprintf(placements, sizeof placements, ", %zu placements", pr.placements);
        printf("edit: %zu equations, %zu unknowns, solve %.3f ms, max residual %.3g m, "
               "%zu splits, %zu joins%s -> %s\n",
               rep->equations, rep->unknowns, rep->solve_ms, rep->max_residual, rep->splits,
               rep->joins, placements, out);
        ag_edit_report_clear(points ? &pr.report : &r.report);
    }
    ag_edit_op_clear(&op);
    ag_edit_op_origin_clear(&from);
    return s == AG_OK ? 0 : 1;
}
