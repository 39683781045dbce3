/* archgram part save | compose | info — the parts library from the command line.
 *
 *   archgram part save DIR --node N --name NAME [--tag T]... [--description D] --out PART.agpart
 *   archgram part compose DIR --part PART.agpart [--name NAME] --target N
 *                         --mode replace|insert|fill [--scope node|rule] --out DIR2
 *   archgram part info PART.agpart [--json]
 *
 * DIR is a proceduralized model as `archgram proceduralize --out` or `archgram edit --out`
 * writes it (grammar.txt, terminals/, tree.json): it is read as `archgram edit` reads it, so
 * node ids are those of DIR/tree.json. compose writes DIR2 in the same layout, with
 * summary.json describing the composition. A bundle of several parts needs --name. */
#include <errno.h>
#include <jansson.h>
#include <libgen.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../core/edit/edit.h"
#include "../core/parts/compose.h"
#include "../core/parts/part.h"
#include "../app/folder_ws.h"
#include "../app/model_tree.h"
#include "../io/grammar_text.h"
#include "../io/part_bundle.h"
#include "../io/terminals.h"
#include "commands.h"

#define SAVE_USAGE "usage: archgram part save DIR --node N --name NAME [--tag T]... " \
                   "[--description D] --out PART.agpart\n"
#define COMPOSE_USAGE "usage: archgram part compose DIR --part PART.agpart [--name NAME] " \
                      "--target N --mode replace|insert|fill [--scope node|rule] --out DIR2\n"
#define INFO_USAGE "usage: archgram part info PART.agpart [--json]\n"

static int usage(void)
{
    fputs(SAVE_USAGE COMPOSE_USAGE INFO_USAGE, stderr);
    return 2;
}

static int parse_node(const char *s, int32_t *out)
{
    char *e;
    errno = 0;
    long v = strtol(s, &e, 10);
    if (errno || *e || e == s || v < 0 || v > INT32_MAX)
        return -1;
    *out = (int32_t)v;
    return 0;
}

/* Reads DIR as `archgram edit` does: its grammar derived and proceduralized again. */
static int load_model(const char *dir, ag_grammar **g, ag_edit_model **model)
{
    char path[4200];
    ag_error err;
    ag_error_clear(&err);
    snprintf(path, sizeof path, "%s/grammar.txt", dir);
    long col = 0;
    if (ag_grammar_text_read_file(path, g, &err, &col)) {
        if (err.code == AG_ERR_PARSE)
            fprintf(stderr, "archgram: %s:%ld:%ld: %s\n", path, err.element, col, err.text);
        else
            ag_cli_report(path, &err);
        return 1;
    }
    if (ag_terminals_load(*g, dir, &err) || ag_edit_model_from_grammar(*g, NULL, model, &err)) {
        ag_cli_report(path, &err);
        return 1;
    }
    return 0;
}

static int cmd_save(int argc, char **argv)
{
    const char *dir = NULL, *name = NULL, *desc = NULL, *out = NULL;
    const char *tags[AG_PART_TAGS_MAX + 1];
    size_t ntags = 0;
    int32_t node = -1;
    int have_node = 0;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        int has = i + 1 < argc;
        if (!strcmp(a, "--node") && has) {
            if (parse_node(argv[++i], &node)) {
                fprintf(stderr, "archgram: part save: --node takes a node id of tree.json, not "
                                "'%s'\n", argv[i]);
                return 2;
            }
            have_node = 1;
        } else if (!strcmp(a, "--name") && has) {
            name = argv[++i];
        } else if (!strcmp(a, "--description") && has) {
            desc = argv[++i];
        } else if (!strcmp(a, "--tag") && has) {
            if (ntags == AG_PART_TAGS_MAX) {
                fprintf(stderr, "archgram: part save: at most %d tags\n", AG_PART_TAGS_MAX);
                return 2;
            }
            tags[ntags++] = argv[++i];
        } else if (!strcmp(a, "--out") && has) {
            out = argv[++i];
        } else if (!strcmp(a, "--help")) {
            fputs(SAVE_USAGE, stdout);
            return 0;
        } else if (a[0] == '-' && a[1]) {
            fprintf(stderr, "archgram: part save: unknown option or missing value %s\n", a);
            fputs(SAVE_USAGE, stderr);
            return 2;
        } else if (!dir) {
            dir = a;
        } else {
            fputs(SAVE_USAGE, stderr);
            return 2;
        }
    }
    if (!dir || !have_node || !name || !out) {
        fputs(SAVE_USAGE, stderr);
        return 2;
    }
    ag_grammar *g = NULL;
    ag_edit_model *model = NULL;
    ag_part *part = NULL;
    int rc = 1;
    double t0 = ag_cli_seconds();
    if (load_model(dir, &g, &model))
        goto done;
    double t_load = ag_cli_seconds() - t0;
    /* provenance names the model by its folder's name, not by a path of this machine */
    char src[4096];
    snprintf(src, sizeof src, "%s", dir);
    size_t sl = strlen(src);
    while (sl > 1 && src[sl - 1] == '/')
        src[--sl] = 0;
    ag_part_meta meta = {.name = name, .description = desc, .tags = tags, .ntags = ntags,
                         .source = basename(src)};
    ag_error err;
    ag_error_clear(&err);
    t0 = ag_cli_seconds();
    if (ag_part_extract(model->proc, node, &meta, &part, &err)) {
        ag_cli_report(dir, &err);
        goto done;
    }
    double t_save = ag_cli_seconds() - t0;
    const ag_part *one[1] = {part};
    if (ag_part_bundle_write_file(one, 1, out, &err)) {
        ag_cli_report(out, &err);
        goto done;
    }
    printf("part save: '%s' from node %d: %zu nodes, %zu rules, %zu terminals, box %.4g x %.4g "
           "x %.4g m; load %.3f s, save %.1f ms -> %s\n",
           part->name, (int)node, part->nnodes, part->grammar->nrules, part->grammar->nterminals,
           part->box.max[0] - part->box.min[0], part->box.max[1] - part->box.min[1],
           part->box.max[2] - part->box.min[2], t_load, 1e3 * t_save, out);
    rc = 0;
done:
    ag_part_free(part);
    ag_edit_model_free(model);
    ag_grammar_free(g);
    return rc;
}

static int read_bundle(const char *path, ag_part ***parts, size_t *n)
{
    ag_error err;
    ag_error_clear(&err);
    if (ag_part_bundle_read_file(path, parts, n, &err)) {
        fprintf(stderr, "archgram: %s: %s\n", path, err.text[0] ? err.text
                                                                : ag_status_message(err.code));
        return 1;
    }
    return 0;
}

static int write_dir(const char *out, ag_grammar *g, const ag_compose_report *rep,
                     const ag_compose_op *op, const ag_part *part, double seconds)
{
    ag_error err;
    ag_error_clear(&err);
    char *text = NULL;
    size_t tlen = 0;
    char path[4200];
    ag_edit_model *back = NULL;
    json_t *summary = NULL;
    int rc = 1;
    if (ag_folder_ws_make_dirs(out)) {
        fprintf(stderr, "archgram: cannot create %s: %s\n", out, strerror(errno));
        return 1;
    }
    if (ag_terminals_write(g, out, NULL, &err) || ag_grammar_text_print(g, &text, &tlen, &err)) {
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
    /* tree.json: the ids a later edit or compose names (the grammar read back) */
    if (ag_edit_model_from_grammar(g, NULL, &back, &err)) {
        ag_cli_report(path, &err);
        goto done;
    }
    snprintf(path, sizeof path, "%s/tree.json", out);
    json_t *tree = ag_model_tree_folder(back);
    int bad = !tree || json_dump_file(tree, path, JSON_INDENT(1) | JSON_REAL_PRECISION(12));
    json_decref(tree);
    if (bad) {
        fprintf(stderr, "archgram: cannot write %s\n", path);
        goto done;
    }
    summary = json_pack(
        "{s:{s:s,s:I,s:s,s:s},s:{s:s,s:I,s:s},s:s,s:s,s:I,s:[I,I,I],s:i,s:[f,f,f],"
        "s:{s:I,s:I,s:I,s:I,s:I,s:I,s:I},s:{s:I,s:I,s:I,s:I},s:o,s:{s:f}}",
        "op", "kind", "compose", "target", (json_int_t)op->target, "mode",
        ag_compose_mode_name(op->mode), "scope", ag_compose_scope_name(op->scope), "part",
        "name", part->name, "version", (json_int_t)part->version, "root", part->root, "root_rule",
        rep->root, "target_rule", rep->target_rule, "instances", (json_int_t)rep->instances,
        "counts", (json_int_t)rep->counts[0], (json_int_t)rep->counts[1],
        (json_int_t)rep->counts[2], "turn", 90 * rep->turn, "fitted", rep->fitted[0],
        rep->fitted[1], rep->fitted[2], "grammar", "rules_added", (json_int_t)rep->rules_added,
        "rules_shared", (json_int_t)rep->rules_shared, "terminals_added",
        (json_int_t)rep->terminals_added, "terminals_shared", (json_int_t)rep->terminals_shared,
        "renamed", (json_int_t)rep->renamed, "cloned", (json_int_t)rep->cloned,
        "expanded_cells", (json_int_t)rep->expanded_cells, "fit", "elements",
        (json_int_t)rep->fit.elements, "equations", (json_int_t)rep->fit.equations, "rigid",
        (json_int_t)rep->fit.rigid, "rigid_relaxed", (json_int_t)rep->fit.rigid_relaxed, "tree",
        ag_model_tree_folder_stats(back), "seconds", "compose", seconds);
    snprintf(path, sizeof path, "%s/summary.json", out);
    if (!summary || json_dump_file(summary, path, JSON_INDENT(1) | JSON_REAL_PRECISION(12))) {
        fprintf(stderr, "archgram: cannot write %s\n", path);
        goto done;
    }
    rc = 0;
done:
    json_decref(summary);
    ag_edit_model_free(back);
    free(text);
    return rc;
}

static int cmd_compose(int argc, char **argv)
{
    const char *dir = NULL, *ppath = NULL, *pname = NULL, *out = NULL;
    ag_compose_op op = {.target = -1, .mode = -1, .scope = AG_COMPOSE_NODE};
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        int has = i + 1 < argc;
        if (!strcmp(a, "--part") && has) {
            ppath = argv[++i];
        } else if (!strcmp(a, "--name") && has) {
            pname = argv[++i];
        } else if (!strcmp(a, "--target") && has) {
            if (parse_node(argv[++i], &op.target)) {
                fprintf(stderr, "archgram: part compose: --target takes a node id of "
                                "tree.json, not '%s'\n", argv[i]);
                return 2;
            }
        } else if (!strcmp(a, "--mode") && has) {
            if ((op.mode = ag_compose_mode_parse(argv[++i])) < 0) {
                fputs("archgram: part compose: --mode takes replace, insert or fill\n", stderr);
                return 2;
            }
        } else if (!strcmp(a, "--scope") && has) {
            if ((op.scope = ag_compose_scope_parse(argv[++i])) < 0) {
                fputs("archgram: part compose: --scope takes node or rule\n", stderr);
                return 2;
            }
        } else if (!strcmp(a, "--out") && has) {
            out = argv[++i];
        } else if (!strcmp(a, "--help")) {
            fputs(COMPOSE_USAGE, stdout);
            return 0;
        } else if (a[0] == '-' && a[1]) {
            fprintf(stderr, "archgram: part compose: unknown option or missing value %s\n", a);
            fputs(COMPOSE_USAGE, stderr);
            return 2;
        } else if (!dir) {
            dir = a;
        } else {
            fputs(COMPOSE_USAGE, stderr);
            return 2;
        }
    }
    if (!dir || !ppath || op.target < 0 || op.mode < 0 || !out) {
        fputs(COMPOSE_USAGE, stderr);
        return 2;
    }
    ag_part **parts = NULL;
    size_t np = 0;
    ag_grammar *g = NULL, *composed = NULL;
    ag_edit_model *model = NULL;
    int rc = 1;
    if (read_bundle(ppath, &parts, &np))
        return 1;
    const ag_part *part = NULL;
    for (size_t i = 0; i < np; i++)
        if (pname ? !strcmp(parts[i]->name, pname) : np == 1)
            part = parts[i];
    if (!part) {
        if (pname)
            fprintf(stderr, "archgram: %s: no part named '%s'\n", ppath, pname);
        else
            fprintf(stderr, "archgram: %s: the bundle holds %zu parts; name one with --name\n",
                    ppath, np);
        goto done;
    }
    if (load_model(dir, &g, &model))
        goto done;
    ag_error err;
    ag_error_clear(&err);
    ag_compose_report rep;
    double t0 = ag_cli_seconds();
    if (ag_compose(model->proc, part, &op, &composed, &rep, &err)) {
        ag_cli_report(dir, &err);
        goto done;
    }
    double t = ag_cli_seconds() - t0;
    if (write_dir(out, composed, &rep, &op, part, t))
        goto done;
    printf("part compose: %s; %.1f ms -> %s\n", rep.message, 1e3 * t, out);
    rc = 0;
done:
    ag_grammar_free(composed);
    ag_edit_model_free(model);
    ag_grammar_free(g);
    ag_part_bundle_free(parts, np);
    return rc;
}

static int cmd_info(int argc, char **argv)
{
    const char *path = NULL;
    int as_json = 0;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--json"))
            as_json = 1;
        else if (!strcmp(argv[i], "--help")) {
            fputs(INFO_USAGE, stdout);
            return 0;
        } else if (argv[i][0] == '-' && argv[i][1]) {
            fprintf(stderr, "archgram: part info: unknown option %s\n", argv[i]);
            return 2;
        } else if (!path)
            path = argv[i];
        else {
            fputs(INFO_USAGE, stderr);
            return 2;
        }
    }
    if (!path) {
        fputs(INFO_USAGE, stderr);
        return 2;
    }
    ag_part **parts = NULL;
    size_t np = 0;
    if (read_bundle(path, &parts, &np))
        return 1;
    json_t *arr = json_array();
    for (size_t i = 0; i < np; i++) {
        const ag_part *p = parts[i];
        size_t tris = 0, visible = 0;
        for (size_t k = 0; k < p->grammar->nterminals; k++)
            tris += p->grammar->terminals[k].ntris;
        for (size_t k = 0; k < p->nnodes; k++)
            visible += p->nodes[k].kind == AG_NODE_COMPONENT;
        double size[3];
        for (int a = 0; a < 3; a++)
            size[a] = p->box.max[a] - p->box.min[a];
        if (as_json) {
            json_t *tags = json_array();
            for (size_t k = 0; k < p->ntags; k++)
                json_array_append_new(tags, json_string(p->tags[k]));
            json_array_append_new(
                arr, json_pack("{s:s,s:I,s:s?,s:o,s:s?,s:I,s:s,s:[f,f,f],s:I,s:I,s:I,s:I,s:I}",
                               "name", p->name, "version", (json_int_t)p->version, "description",
                               p->description, "tags", tags, "source", p->source, "source_node",
                               (json_int_t)p->source_node, "root", p->root, "size", size[0],
                               size[1], size[2], "nodes", (json_int_t)p->nnodes, "visible",
                               (json_int_t)visible, "rules", (json_int_t)p->grammar->nrules,
                               "terminals", (json_int_t)p->grammar->nterminals,
                               "terminal_triangles", (json_int_t)tris));
            continue;
        }
        printf("%s (version %u)%s%s\n", p->name, p->version, p->description ? ": " : "",
               p->description ? p->description : "");
        printf("  tags:");
        for (size_t k = 0; k < p->ntags; k++)
            printf(" %s", p->tags[k]);
        printf("%s\n", p->ntags ? "" : " none");
        printf("  from: %s, node %d\n", p->source ? p->source : "(unknown)", (int)p->source_node);
        printf("  root rule %s, %.4g x %.4g x %.4g m, facing %d\n", p->root, size[0], size[1],
               size[2], 90 * p->facing);
        printf("  %zu nodes (%zu visible), %zu rules, %zu terminals of %zu triangles\n", p->nnodes,
               visible, p->grammar->nrules, p->grammar->nterminals, tris);
    }
    if (as_json) {
        char *s = json_dumps(arr, JSON_INDENT(1) | JSON_REAL_PRECISION(12));
        if (s)
            puts(s);
        free(s);
    }
    json_decref(arr);
    ag_part_bundle_free(parts, np);
    return 0;
}

int ag_cli_part(int argc, char **argv)
{
    if (argc < 2)
        return usage();
    if (!strcmp(argv[1], "save"))
        return cmd_save(argc - 1, argv + 1);
    if (!strcmp(argv[1], "compose"))
        return cmd_compose(argc - 1, argv + 1);
    if (!strcmp(argv[1], "info"))
        return cmd_info(argc - 1, argv + 1);
    if (!strcmp(argv[1], "--help")) {
        fputs(SAVE_USAGE COMPOSE_USAGE INFO_USAGE, stdout);
        return 0;
    }
    fprintf(stderr, "archgram: part: unknown subcommand '%s'\n", argv[1]);
    return usage();
}
