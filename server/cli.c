/* archgram — the command-line tool: one dispatcher, one file per subcommand. */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

#include "app/threads.h"
#include "app/usecase_import.h"
#include "cli/commands.h"

#define ARCHGRAM_VERSION "0.1.0"

static const struct {
    const char *name;
    int (*run)(int argc, char **argv);
    const char *usage;
} commands[] = {
    {"info", ag_cli_info, "info FILE [--up y|z|auto] [--json]  counts, groups and bounds of a mesh"},
    {"convert", ag_cli_convert, "convert IN OUT [--up y|z|auto]  convert a mesh (OUT: .obj or .glb)"},
    {"proceduralize", ag_cli_proceduralize,
     "proceduralize IN --out DIR [--up y|z|auto]  split grammar + terminals + summary.json"},
    {"derive", ag_cli_derive, "derive GRAMMAR --out FILE.obj|FILE.glb  derive a grammar into a mesh"},
    {"edit", ag_cli_edit, "edit DIR --op OP.json --out DIR2     apply one edit op to a proceduralized model"},
    {"part", ag_cli_part, "part save|compose|info ...          the parts library (archgram part --help)"},
    {"fmt", ag_cli_fmt, "fmt GRAMMAR                     print a grammar in canonical form"},
    {"extrude", ag_cli_extrude, "extrude --plan PLAN.json | FOOTPRINTS.geojson --style S --out OUT  roofs and shells"},
    {"segment", ag_cli_segment, "segment CLOUD --out SEG.ply [--roi BOX] [--threshold F]  planes and clusters of a point cloud"},
    {"cut", ag_cli_cut, "cut TILE --footprints F.geojson --out DIR   one point cloud per building footprint"},
};

#define NCOMMANDS (sizeof commands / sizeof commands[0])

static void usage(FILE *f)
{
    fputs("usage: archgram COMMAND [ARGS...]\n"
          "       archgram --help | --version\n\ncommands:\n",
          f);
    for (size_t i = 0; i < NCOMMANDS; i++)
        fprintf(f, "  %s\n", commands[i].usage);
    fputs("\n--up names the input's up axis; without it (or with auto) the file says it where "
          "its format can,\nelse its content decides (reported as `up axis ...`); archgram "
          "works z-up.\n",
          f);
}

/* An empty file names nothing: the message says what it is about. */
void ag_cli_report(const char *file, const ag_error *err)
{
    const char *text = err->text[0] ? err->text : ag_status_message(err->code);
    if (!file || !*file) { /* the message names what it is about */
        fprintf(stderr, "archgram: %s\n", text);
    } else if (err->code == AG_ERR_PARSE && err->element > 0) {
        /* GCC style file:line: — drop the reader's own "line N: " prefix. */
        char prefix[32];
        int n = snprintf(prefix, sizeof prefix, "line %ld: ", err->element);
        if (n > 0 && strncmp(text, prefix, (size_t)n) == 0)
            text += n;
        fprintf(stderr, "archgram: %s:%ld: %s\n", file, err->element, text);
    } else {
        fprintf(stderr, "archgram: %s: %s\n", file, text);
    }
}

int ag_cli_parse_up(const char *value, ag_up_axis *up)
{
    if (value && (!strcmp(value, "y") || !strcmp(value, "Y")))
        *up = AG_UP_Y;
    else if (value && (!strcmp(value, "z") || !strcmp(value, "Z")))
        *up = AG_UP_Z;
    else if (value && !strcmp(value, "auto"))
        *up = AG_UP_DEFAULT;
    else
        return -1;
    return 0;
}

double ag_cli_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
}

int ag_cli_load_mesh(const char *path, ag_up_axis up, ag_mesh **out, size_t *bytes)
{
    ag_error err;
    ag_error_clear(&err);
    /* the person's own file: what it refers to is read from next to it */
    ag_mesh_source src = {.path = path, .up = up, .own_file = 1};
    ag_mesh_file file;
    ag_status st = ag_usecase_import_read(&src, NULL, NULL, out, &file, &err);
    *bytes = file.len;
    ag_usecase_import_release(&file);
    if (st != AG_OK) {
        ag_cli_report(path, &err);
        return 1;
    }
    return 0;
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        usage(stderr);
        return 2;
    }
    if (!strcmp(argv[1], "--help") || !strcmp(argv[1], "-h") || !strcmp(argv[1], "help")) {
        usage(stdout);
        return 0;
    }
    if (!strcmp(argv[1], "--version")) {
        puts("archgram " ARCHGRAM_VERSION);
        return 0;
    }
    ag_threads_install(); /* core's and io's parallel parts (a large OBJ read in halves) */
    for (size_t i = 0; i < NCOMMANDS; i++)
        if (!strcmp(argv[1], commands[i].name))
            return commands[i].run(argc - 1, argv + 1);
    fprintf(stderr, "archgram: unknown command '%s' (see archgram --help)\n", argv[1]);
    return 2;
}
