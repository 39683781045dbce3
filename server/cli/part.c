/* archgram part save | compose | info — the parts library from the command line.
 *
 *   archgram part save DIR --node N --name NAME [--tag T]... [--description D] --out PART.agpart
 *   archgram part compose DIR --part PART.agpart [--name NAME] --target N
 *                         --mode replace|insert|fill [--scope node|rule] --out DIR2
 *   archgram part info PART.agpart [--json]
 *
 * save and compose are the app's use cases (app/usecase_save_part.h, app/usecase_compose.h)
 * over folder workspaces (app/folder_ws.h). DIR is a proceduralized model as `archgram
 * proceduralize --out` or `archgram edit --out` writes it (grammar.txt, terminals/,
 * tree.json): it is read as `archgram edit` reads it, so node ids are those of DIR/tree.json.
 * compose writes DIR2 in the same layout, with summary.json describing the composition. A
 * bundle of several parts needs --name. */
#include <errno.h>
#include <jansson.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../app/folder_ws.h"
#include "../app/usecase_compose.h"
#include "../app/usecase_save_part.h"
#include "../core/parts/compose.h"
#include "../core/parts/part.h"
#include "../io/part_bundle.h"
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
    ag_part_meta meta = {.name = name, .description = desc, .tags = tags, .ntags = ntags};
    ag_folder_ws w;
    ag_folder_ws_init(&w, &(ag_folder_ws_options){.in_dir = dir, .bundle_out = out});
    ag_usecase_save_part_result r;
    ag_error err;
    ag_error_clear(&err);
    ag_status s = ag_usecase_save_part_run(
        &w.ws, &(ag_usecase_save_part_params){.nodes = &node, .nnodes = 1, .meta = &meta}, &r,
        &err);
    ag_workspace_close(&w.ws);
    if (s != AG_OK) {
        ag_cli_report(w.blamed ? w.blame : dir, &err);
        return 1;
    }
    printf("part save: '%s' from node %d: %zu nodes, %zu rules, %zu terminals, box %.4g x %.4g "
           "x %.4g m; load %.3f s, save %.1f ms -> %s\n",
           name, (int)r.node, r.nodes, r.rules, r.terminals, r.size[0], r.size[1], r.size[2],
           r.load_ms / 1e3, r.save_ms, out);
    return 0;
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
    ag_folder_ws w;
    ag_folder_ws_init(&w, &(ag_folder_ws_options){.in_dir = dir, .out_dir = out});
    ag_part_ref ref = {.path = ppath, .name = pname};
    ag_usecase_compose_result r;
    ag_error err;
    ag_error_clear(&err);
    ag_status s =
        ag_usecase_compose_run(&w.ws, &(ag_usecase_compose_params){.part = &ref, .op = op}, &r,
                               &err);
    ag_workspace_close(&w.ws);
    if (s != AG_OK) {
        ag_cli_report(w.blamed ? w.blame : dir, &err);
        return 1;
    }
    printf("part compose: %s; rewrite %.1f ms, new state %.1f ms -> %s\n", r.report.message,
           r.compose_ms, r.state_ms, out);
    return 0;
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
