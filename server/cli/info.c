/* archgram info FILE [--up y|z] [--json] */
#include <jansson.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../io/meshjson.h"
#include "commands.h"

static int usage(void)
{
    fputs("usage: archgram info FILE [--up y|z] [--json]\n", stderr);
    return 2;
}

int ag_cli_info(int argc, char **argv)
{
    const char *file = NULL;
    ag_up_axis up = AG_UP_DEFAULT;
    int as_json = 0;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--json")) {
            as_json = 1;
        } else if (!strcmp(argv[i], "--up")) {
            if (++i >= argc || ag_cli_parse_up(argv[i], &up)) {
                fputs("archgram: --up takes y or z\n", stderr);
                return 2;
            }
        } else if (!strcmp(argv[i], "--help")) {
            fputs("usage: archgram info FILE [--up y|z] [--json]\n", stdout);
            return 0;
        } else if (argv[i][0] == '-' && argv[i][1]) {
            fprintf(stderr, "archgram: info: unknown option %s\n", argv[i]);
            return usage();
        } else if (!file) {
            file = argv[i];
        } else {
            return usage();
        }
    }
    if (!file)
        return usage();
    if (ag_cli_is_cloud_file(file)) /* point clouds have their own summary */
        return ag_cli_cloud_info(file, as_json);
    ag_mesh *m;
    size_t bytes;
    if (ag_cli_load_mesh(file, up, &m, &bytes))
        return 1;
    json_t *j = ag_meshjson_summary(m);
    if (!j) {
        fputs("archgram: out of memory\n", stderr);
        ag_mesh_free(m);
        return 1;
    }
    if (as_json) {
        json_object_set_new(j, "file", json_string(file));
        json_object_set_new(j, "bytes", json_integer((json_int_t)bytes));
        json_dumpf(j, stdout, JSON_INDENT(2) | JSON_PRESERVE_ORDER | JSON_REAL_PRECISION(15));
        putchar('\n');
    } else {
        ag_box b = ag_mesh_bounds(m);
        printf("file        %s\n", file);
        printf("bytes       %zu\n", bytes);
        printf("vertices    %zu\n", m->nverts);
        printf("triangles   %zu\n", m->ntris);
        printf("components  %zu\n", m->ncomponents);
        printf("groups      %zu\n", m->ngroups);
        printf("bounds      min %.6g %.6g %.6g  max %.6g %.6g %.6g (z up, metres)\n", b.min[0],
               b.min[1], b.min[2], b.max[0], b.max[1], b.max[2]);
        printf("size        %.6g x %.6g x %.6g, diagonal %.6g\n", b.max[0] - b.min[0],
               b.max[1] - b.min[1], b.max[2] - b.min[2], ag_box_diagonal(&b));
    }
    json_decref(j);
    ag_mesh_free(m);
    return ferror(stdout) ? 1 : 0;
}
