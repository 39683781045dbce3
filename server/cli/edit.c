/* archgram edit DIR --op OP.json --out DIR2
 *
 * DIR holds a proceduralized model as `archgram proceduralize` (or an earlier edit) writes
 * it: grammar.txt and terminals/. The grammar is derived and proceduralized again, which
 * gives the tree whose node ids the op names (DIR/tree.json lists them). DIR2 receives the
 * edited model's grammar.txt, terminals/, tree.json (ids for the next edit) and summary.json
 * (the solve figures and instances per label). A paste may copy from another proceduralized
 * folder: "source_dir" in the op, relative to the op file's folder (node ids of its tree.json). */
#include <errno.h>
#include <jansson.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "../core/edit/edit.h"
#include "../io/edit_op_json.h"
#include "../io/edit_tree_json.h"
#include "../io/grammar_text.h"
#include "../io/terminals.h"
#include "commands.h"

static int usage(void)
{
    fputs("usage: archgram edit DIR --op OP.json --out DIR2\n", stderr);
    return 2;
}

static int write_json(const char *path, json_t *j)
{
    if (!j || json_dump_file(j, path, JSON_INDENT(1) | JSON_REAL_PRECISION(12))) {
        fprintf(stderr, "archgram: cannot write %s\n", path);
        return 1;
    }
    return 0;
}

/* The proceduralized folder a paste copies from ("source_dir", relative to the op file's
 * folder): read as DIR is, so its node ids are those of its tree.json. Reports and returns
 * non-zero on failure. */
static int load_source(const char *oppath, const char *sdir, ag_grammar **g,
                       ag_edit_model **out, ag_error *err)
{
    char dir[4096], path[4200];
    const char *slash = strrchr(oppath, '/');
    if (sdir[0] == '/' || !slash)
        snprintf(dir, sizeof dir, "%s", sdir);
    else
        snprintf(dir, sizeof dir, "%.*s/%s", (int)(slash - oppath), oppath, sdir);
    struct stat sb;
    if (stat(dir, &sb) || !S_ISDIR(sb.st_mode)) {
        ag_error_set(err, AG_ERR_NOT_FOUND, 0, "source_dir: %s is not a folder", dir);
        ag_cli_report(oppath, err);
        return 1;
    }
    snprintf(path, sizeof path, "%s/grammar.txt", dir);
    if (access(path, R_OK)) {
        ag_error_set(err, AG_ERR_NOT_PROCEDURALIZED, 0,
                     "source_dir: %s is not proceduralized (no grammar.txt; run `archgram "
                     "proceduralize MESH --out %s`)",
                     dir, dir);
        ag_cli_report(oppath, err);
        return 1;
    }
    long col = 0;
    if (ag_grammar_text_read_file(path, g, err, &col) || ag_terminals_load(*g, dir, err) ||
        ag_edit_model_from_grammar(*g, NULL, out, err)) {
        ag_cli_report(path, err);
        return 1;
    }
    return 0;
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
    int rc = 1;
    char path[4096];
    ag_grammar *g = NULL, *sg = NULL;
    ag_edit_model *model = NULL, *edited = NULL, *source = NULL;
    ag_edit_report rep = {0};
    char *text = NULL;
    size_t tlen = 0;
    json_t *summary = NULL;
    double t0 = ag_cli_seconds();

    snprintf(path, sizeof path, "%s/grammar.txt", dir);
    long col = 0;
    if (ag_grammar_text_read_file(path, &g, &err, &col) || ag_terminals_load(g, dir, &err)) {
        ag_cli_report(path, &err);
        goto done;
    }
    if (ag_edit_model_from_grammar(g, NULL, &model, &err)) {
        ag_cli_report(path, &err);
        goto done;
    }
    if (from.model) {
        ag_error_set(&err, AG_ERR_INVALID, 0,
                     "source_model: names a model of the service; an op file names the "
                     "folder to paste from with source_dir");
        ag_cli_report(oppath, &err);
        goto done;
    }
    if (from.dir && load_source(oppath, from.dir, &sg, &source, &err))
        goto done;
    op.source = source ? source->proc : NULL;
    double t_load = ag_cli_seconds() - t0;
    t0 = ag_cli_seconds();
    if (ag_edit_apply(model, &op, &edited, &rep, &err)) {
        /* errors that name an op field are the op file's; the rest are the model's */
        ag_cli_report(err.code == AG_ERR_INVALID || err.code == AG_ERR_NOT_FOUND ? oppath : dir,
                      &err);
        goto done;
    }
    double t_edit = ag_cli_seconds() - t0;
    if (ag_cli_make_dirs(out)) {
        fprintf(stderr, "archgram: cannot create %s: %s\n", out, strerror(errno));
        goto done;
    }
    ag_grammar *ng = edited->proc->grammar;
    if (ag_terminals_write(ng, out, NULL, &err) || ag_grammar_text_print(ng, &text, &tlen, &err)) {
        ag_cli_report(out, &err);
        goto done;
    }
    snprintf(path, sizeof path, "%s/grammar.txt", out);
    FILE *f = fopen(path, "wb");
    int ok = f && fwrite(text, 1, tlen, f) == tlen;
    if (f && fclose(f))
        ok = 0;
    if (!ok) {
        fprintf(stderr, "archgram: cannot write %s: %s\n", path, strerror(errno));
        goto done;
    }
    snprintf(path, sizeof path, "%s/tree.json", out);
    json_t *tree = ag_edit_tree_json(edited->proc);
    int bad = write_json(path, tree);
    json_decref(tree);
    if (bad)
        goto done;
    summary = ag_edit_op_json_report(&rep);
    if (summary) {
        json_object_set_new(summary, "op", ag_edit_op_json_to_ex(&op, &from));
        json_object_set_new(summary, "tree", ag_edit_tree_json_stats(edited->proc));
        json_object_set_new(summary, "seconds",
                            json_pack("{s:f,s:f}", "load", t_load, "edit", t_edit));
    }
    snprintf(path, sizeof path, "%s/summary.json", out);
    if (write_json(path, summary))
        goto done;
    printf("edit: %zu equations, %zu unknowns, solve %.3f ms, max residual %.3g m, "
           "%zu splits, %zu joins -> %s\n",
           rep.equations, rep.unknowns, rep.solve_ms, rep.max_residual, rep.splits, rep.joins,
           out);
    rc = 0;
done:
    json_decref(summary);
    free(text);
    ag_edit_report_clear(&rep);
    ag_edit_model_free(edited);
    ag_edit_model_free(model);
    ag_edit_model_free(source);
    ag_grammar_free(g);
    ag_grammar_free(sg);
    op.source = NULL;
    ag_edit_op_clear(&op);
    ag_edit_op_origin_clear(&from);
    return rc;
}
