/* archgram cut TILE --footprints F.geojson --out DIR [--buffer M] [--ground auto|class|plane|none]
 *              [--id-property NAME] [--double]
 * One cloud per building footprint: DIR/<footprint id>.ply with every input property and
 * coordinates in the tile's coordinate system (float relative to a `comment offset` header
 * line, or --double absolute), plus DIR/report.json. */
#include <errno.h>
#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../core/points/cut.h"
#include "../io/footprints.h"
#include "../io/ply.h"
#include "../app/folder_ws.h"
#include "commands.h"

static int usage(FILE *f)
{
    fputs("usage: archgram cut TILE --footprints F.geojson --out DIR [--buffer METRES]\n"
          "                    [--ground auto|class|plane|none] [--id-property NAME] [--double]\n"
          "                    [--metres]\n"
          "  --buffer M          points this close to a footprint belong to it (0.5)\n"
          "  --ground G          auto: classification 2 when the tile has it, else a plane;\n"
          "                      class: refused when no point has classification 2\n"
          "  --id-property NAME  name the files by this feature property (default: the feature\n"
          "                      id, properties.id, else the feature's index)\n"
          "  --double            absolute double coordinates instead of float + offset\n"
          "  --metres            the tile is in metres even where its coordinates could be\n"
          "                      degrees (a local site frame near 0, 0)\n",
          f);
    return f == stdout ? 0 : 2;
}

static char *id_text(json_t *v)
{
    char buf[64];
    if (json_is_string(v))
        return strdup(json_string_value(v));
    if (json_is_integer(v)) {
        snprintf(buf, sizeof buf, "%lld", (long long)json_integer_value(v));
        return strdup(buf);
    }
    if (json_is_real(v)) {
        snprintf(buf, sizeof buf, "%.17g", json_real_value(v));
        return strdup(buf);
    }
    return NULL;
}

/* Names from --id-property: features are matched to footprints in order by the id the
 * footprint reader gives them (feature id, properties.id, else the feature's index). */
static int property_names(const char *path, const char *prop, const ag_footprints *fp, char **names)
{
    json_error_t je;
    json_t *root = json_load_file(path, 0, &je);
    json_t *features = root ? json_object_get(root, "features") : NULL;
    if (!json_is_array(features)) {
        json_decref(root);
        return -1;
    }
    size_t fi = 0, nf = json_array_size(features);
    for (size_t k = 0; k < fp->n; k++) {
        for (; fi < nf; fi++) {
            json_t *feat = json_array_get(features, fi);
            char *id = id_text(json_object_get(feat, "id"));
            if (!id)
                id = id_text(json_object_get(json_object_get(feat, "properties"), "id"));
            if (!id) {
                char buf[32];
                snprintf(buf, sizeof buf, "%zu", fi);
                id = strdup(buf);
            }
            int match = id && !strcmp(id, fp->items[k].id);
            free(id);
            if (match)
                break;
        }
        if (fi == nf)
            break;
        json_t *v = json_object_get(json_object_get(json_array_get(features, fi), "properties"), prop);
        names[k] = id_text(v);
        fi++;
    }
    json_decref(root);
    return 0;
}

/* A file name from an id: letters, digits, '.', '-' and '_' kept, the rest '_'. */
static void file_name(const char *id, char *out, size_t cap)
{
    size_t n = 0;
    for (const char *p = id; *p && n + 1 < cap; p++) {
        char ch = *p;
        int ok = (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') || (ch >= '0' && ch <= '9') ||
                 ch == '-' || ch == '_' || (ch == '.' && n > 0);
        out[n++] = ok ? ch : '_';
    }
    if (!n)
        out[n++] = '_';
    out[n] = 0;
}

int ag_cli_cut(int argc, char **argv)
{
    const char *in = NULL, *fp_path = NULL, *dir = NULL, *id_prop = NULL;
    ag_cut_options o = {0};
    int dbl = 0, metres = 0;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        int more = i + 1 < argc;
        if (!strcmp(a, "--help"))
            return usage(stdout);
        if (!strcmp(a, "--footprints") && more) {
            fp_path = argv[++i];
        } else if (!strcmp(a, "--out") && more) {
            dir = argv[++i];
        } else if (!strcmp(a, "--buffer") && more) {
            char *end;
            o.buffer = strtod(argv[++i], &end);
            if (*end || !(o.buffer >= 0 && o.buffer <= 100)) {
                fprintf(stderr, "archgram cut: --buffer takes metres between 0 and 100\n");
                return 2;
            }
            if (o.buffer == 0)
                o.buffer = -1; /* no buffer (0 would mean the default) */
        } else if (!strcmp(a, "--ground") && more) {
            const char *g = argv[++i];
            if (!strcmp(g, "auto"))
                o.ground = AG_CUT_GROUND_AUTO;
            else if (!strcmp(g, "class"))
                o.ground = AG_CUT_GROUND_CLASS;
            else if (!strcmp(g, "plane"))
                o.ground = AG_CUT_GROUND_PLANE;
            else if (!strcmp(g, "none"))
                o.ground = AG_CUT_GROUND_NONE;
            else {
                fprintf(stderr, "archgram cut: --ground takes auto, class, plane or none\n");
                return 2;
            }
        } else if (!strcmp(a, "--id-property") && more) {
            id_prop = argv[++i];
        } else if (!strcmp(a, "--double")) {
            dbl = 1;
        } else if (!strcmp(a, "--metres")) {
            metres = 1;
        } else if (a[0] == '-' && a[1]) {
            fprintf(stderr, "archgram cut: unknown or incomplete option %s\n", a);
            return usage(stderr);
        } else if (!in) {
            in = a;
        } else {
            return usage(stderr);
        }
    }
    if (!in || !fp_path || !dir)
        return usage(stderr);
    ag_cloud *c;
    if (ag_cli_load_cloud(in, &c))
        return 1;
    ag_error err;
    ag_error_clear(&err);
    /* the tile is in projected metres when its coordinates cannot be degrees */
    double mn[3], mx[3];
    ag_cloud_bounds(c, mn, mx);
    int degrees = !metres && c->n && fabs(mn[0] + c->offset[0]) <= 180 && fabs(mx[0] + c->offset[0]) <= 180 &&
                  fabs(mn[1] + c->offset[1]) <= 90 && fabs(mx[1] + c->offset[1]) <= 90;
    if (degrees) {
        fprintf(stderr, "archgram cut: %s: the tile looks like longitude/latitude; cut needs "
                        "projected metres (e.g. UTM or RD New), or --metres for a local frame\n",
                in);
        ag_cloud_free(c);
        return 1;
    }
    if (o.ground == AG_CUT_GROUND_CLASS &&
        ag_cut_ground_method(c, AG_CUT_GROUND_AUTO) != AG_CUT_GROUND_CLASS) {
        /* asked for, but nothing to remove: say so rather than keep the ground silently */
        fprintf(stderr, "archgram cut: %s: --ground class, but no point has classification 2 "
                        "(ground); --ground plane fits one\n",
                in);
        ag_cloud_free(c);
        return 1;
    }
    ag_footprints_options fo = {.lonlat = -1};
    ag_footprints *fp = NULL;
    if (ag_footprints_read_file(fp_path, &fo, &fp, &err) != AG_OK) {
        ag_cli_report(fp_path, &err);
        ag_cloud_free(c);
        return 1;
    }
    int rc = 0;
    ag_cut_footprint *cf = calloc(fp->n + 1, sizeof *cf);
    double **loops = NULL;
    size_t nloops_total = 0;
    for (size_t k = 0; k < fp->n; k++)
        nloops_total += fp->items[k].nloops;
    loops = calloc(nloops_total + 1, sizeof *loops);
    int32_t *owner = malloc((c->n ? c->n : 1) * sizeof *owner);
    ag_cut_stats *stats = calloc(fp->n + 1, sizeof *stats);
    char **names = calloc(fp->n + 1, sizeof *names);
    if (!cf || !loops || !owner || !stats || !names) {
        fputs("archgram cut: out of memory\n", stderr);
        rc = 1;
        goto out;
    }
    /* footprint coordinates (file origin removed) into the tile's local frame */
    double shift[2] = {fp->origin[0] - c->offset[0], fp->origin[1] - c->offset[1]};
    size_t li = 0;
    for (size_t k = 0; k < fp->n && !rc; k++) {
        const ag_footprint *f = &fp->items[k];
        cf[k].nloops = f->nloops;
        cf[k].sizes = f->sizes;
        cf[k].loops = (const double *const *)(loops + li);
        for (size_t l = 0; l < f->nloops; l++, li++) {
            loops[li] = malloc(2 * f->sizes[l] * sizeof **loops);
            if (!loops[li]) {
                fputs("archgram cut: out of memory\n", stderr);
                rc = 1;
                break;
            }
            for (size_t v = 0; v < f->sizes[l]; v++) {
                loops[li][2 * v] = f->loops[l][2 * v] + shift[0];
                loops[li][2 * v + 1] = f->loops[l][2 * v + 1] + shift[1];
            }
        }
    }
    if (rc)
        goto out;
    if (id_prop && property_names(fp_path, id_prop, fp, names)) {
        fprintf(stderr, "archgram cut: %s: cannot read the features for --id-property\n", fp_path);
        rc = 1;
        goto out;
    }
    double t0 = ag_cli_seconds();
    if (ag_cut_assign(c, cf, fp->n, &o, owner, stats, &err) != AG_OK) {
        ag_cli_report(in, &err);
        rc = 1;
        goto out;
    }
    double t_cut = ag_cli_seconds() - t0;
    if (ag_folder_ws_make_dirs(dir)) {
        fprintf(stderr, "archgram cut: %s: %s\n", dir, strerror(errno));
        rc = 1;
        goto out;
    }
    /* per-building point lists (CSR by owner) */
    size_t *start = calloc(fp->n + 2, sizeof *start);
    uint32_t *members = malloc((c->n ? c->n : 1) * sizeof *members);
    if (!start || !members) {
        free(start);
        free(members);
        fputs("archgram cut: out of memory\n", stderr);
        rc = 1;
        goto out;
    }
    for (size_t i = 0; i < c->n; i++)
        if (owner[i] >= 0)
            start[owner[i] + 1]++;
    for (size_t k = 0; k < fp->n; k++)
        start[k + 1] += start[k];
    {
        size_t *fill = malloc((fp->n + 1) * sizeof *fill);
        if (!fill) {
            free(start);
            free(members);
            rc = 1;
            goto out;
        }
        memcpy(fill, start, (fp->n + 1) * sizeof *fill);
        for (size_t i = 0; i < c->n; i++)
            if (owner[i] >= 0)
                members[fill[owner[i]]++] = (uint32_t)i;
        free(fill);
    }
    json_t *report = json_object(), *buildings = json_array(), *empty = json_array();
    static const char *const methods[] = {"auto", "class", "plane", "none"};
    json_object_set_new(report, "tile", json_string(in));
    json_object_set_new(report, "footprints_file", json_string(fp_path));
    json_object_set_new(report, "points", json_integer((json_int_t)c->n));
    json_object_set_new(report, "footprints", json_integer((json_int_t)fp->n));
    json_object_set_new(report, "skipped_features", json_integer((json_int_t)fp->skipped));
    json_object_set_new(report, "buffer", json_real(o.buffer > 0 ? o.buffer : o.buffer < 0 ? 0 : 0.5));
    json_object_set_new(report, "ground", json_string(methods[ag_cut_ground_method(c, o.ground)]));
    size_t written = 0, kept_total = 0;
    for (size_t k = 0; k < fp->n && !rc; k++) {
        const char *id = names[k] ? names[k] : fp->items[k].id;
        size_t m = start[k + 1] - start[k];
        if (!m) {
            json_array_append_new(empty, json_string(id));
            continue;
        }
        ag_cloud *b = NULL;
        if (ag_cloud_subset(c, members + start[k], m, &b, &err) != AG_OK) {
            ag_cli_report(in, &err);
            rc = 1;
            break;
        }
        /* a building-sized local origin keeps float coordinates precise */
        double bmn[3], bmx[3], origin[3];
        ag_cloud_bounds(b, bmn, bmx);
        for (int a = 0; a < 3; a++)
            origin[a] = floor(bmn[a] + b->offset[a]);
        ag_cloud_rebase(b, origin);
        char name[200], path[4096];
        file_name(id, name, sizeof name);
        snprintf(path, sizeof path, "%s/%s.ply", dir, name);
        /* ids that clean up to the same name get a number */
        for (int dup = 2; dup < 10000; dup++) {
            int taken = 0;
            for (size_t q = 0; q < json_array_size(buildings) && !taken; q++) {
                const char *f = json_string_value(json_object_get(json_array_get(buildings, q), "file"));
                taken = f && !strcmp(f, strrchr(path, '/') + 1);
            }
            if (!taken)
                break;
            snprintf(path, sizeof path, "%s/%s-%d.ply", dir, name, dup);
        }
        ag_ply_write_options po = {.double_xyz = dbl};
        if (ag_ply_write_file(b, &po, path, &err) != AG_OK) {
            ag_cli_report(path, &err);
            ag_cloud_free(b);
            rc = 1;
            break;
        }
        json_t *e = json_object();
        json_object_set_new(e, "id", json_string(id));
        if (names[k])
            json_object_set_new(e, "feature_id", json_string(fp->items[k].id));
        json_object_set_new(e, "file", json_string(strrchr(path, '/') + 1));
        json_object_set_new(e, "points", json_integer((json_int_t)m));
        json_object_set_new(e, "inside", json_integer((json_int_t)stats[k].inside));
        json_object_set_new(e, "buffered", json_integer((json_int_t)stats[k].buffered));
        json_object_set_new(e, "ground_removed", json_integer((json_int_t)stats[k].ground));
        json_t *off = json_array();
        for (int a = 0; a < 3; a++)
            json_array_append_new(off, json_real(origin[a]));
        json_object_set_new(e, "offset", off);
        json_array_append_new(buildings, e);
        ag_cloud_free(b);
        written++;
        kept_total += m;
    }
    free(start);
    free(members);
    json_object_set_new(report, "with_points", json_integer((json_int_t)written));
    json_object_set_new(report, "points_kept", json_integer((json_int_t)kept_total));
    json_object_set_new(report, "seconds", json_real(t_cut));
    json_object_set_new(report, "buildings", buildings);
    json_object_set_new(report, "empty", empty);
    if (!rc) {
        char path[4096];
        snprintf(path, sizeof path, "%s/report.json", dir);
        if (json_dump_file(report, path, JSON_INDENT(2) | JSON_PRESERVE_ORDER | JSON_REAL_PRECISION(12))) {
            fprintf(stderr, "archgram cut: cannot write %s\n", path);
            rc = 1;
        } else {
            printf("%zu footprints, %zu with points written to %s (%zu points kept of %zu)\n", fp->n,
                   written, dir, kept_total, c->n);
        }
    }
    json_decref(report);
out:
    for (size_t k = 0; names && k < fp->n; k++)
        free(names[k]);
    free(names);
    for (size_t l = 0; loops && l < nloops_total; l++)
        free(loops[l]);
    free(loops);
    free(cf);
    free(owner);
    free(stats);
    ag_footprints_free(fp);
    ag_cloud_free(c);
    return rc;
}
