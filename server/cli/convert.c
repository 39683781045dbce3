/* archgram convert IN OUT [--up y|z] — OUT's extension picks the format (.obj or .glb). */
#include <stdio.h>
#include <string.h>
#include <strings.h>

#include "../io/glb.h"
#include "../io/obj.h"
#include "commands.h"

static int usage(void)
{
    fputs("usage: archgram convert IN OUT [--up y|z]   (OUT ends in .obj or .glb)\n", stderr);
    return 2;
}

static int ends_with(const char *s, const char *suffix)
{
    size_t n = strlen(s), k = strlen(suffix);
    return n > k && strcasecmp(s + n - k, suffix) == 0;
}

int ag_cli_convert(int argc, char **argv)
{
    const char *in = NULL, *out = NULL;
    ag_up_axis up = AG_UP_DEFAULT;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--up")) {
            if (++i >= argc || ag_cli_parse_up(argv[i], &up)) {
                fputs("archgram: --up takes y or z\n", stderr);
                return 2;
            }
        } else if (!strcmp(argv[i], "--help")) {
            fputs("usage: archgram convert IN OUT [--up y|z]   (OUT ends in .obj or .glb)\n",
                  stdout);
            return 0;
        } else if (argv[i][0] == '-' && argv[i][1]) {
            fprintf(stderr, "archgram: convert: unknown option %s\n", argv[i]);
            return usage();
        } else if (!in) {
            in = argv[i];
        } else if (!out) {
            out = argv[i];
        } else {
            return usage();
        }
    }
    if (!in || !out)
        return usage();
    if (ag_cli_is_cloud_file(in)) /* point clouds: PLY, LAS, XYZ out */
        return ag_cli_cloud_convert(in, out, 0);
    int glb = ends_with(out, ".glb");
    if (!glb && !ends_with(out, ".obj")) {
        fprintf(stderr, "archgram: %s: cannot tell the output format (use .obj or .glb)\n",
                out);
        return 2;
    }
    ag_mesh *m;
    size_t bytes;
    if (ag_cli_load_mesh(in, up, &m, &bytes))
        return 1;
    ag_error err;
    ag_error_clear(&err);
    /* OBJ goes out in the axis it came in with, so a round trip changes nothing. */
    ag_status st = glb ? ag_glb_write_file(m, out, &err) : ag_obj_write_file(m, up, out, &err);
    ag_mesh_free(m);
    if (st != AG_OK) {
        ag_cli_report(out, &err);
        return 1;
    }
    return 0;
}
