/* Point clouds in the CLI: loading and writing by extension, and the cloud branches of
 * `archgram info` and `archgram convert`. */
#include <errno.h>
#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <strings.h>

#include "../io/cloud_import.h"
#include "../io/filemap.h"
#include "../io/las.h"
#include "../io/ply.h"
#include "../io/xyz.h"
#include "commands.h"

static int ends_with(const char *s, const char *suffix)
{
    size_t n = strlen(s), k = strlen(suffix);
    return n > k && strcasecmp(s + n - k, suffix) == 0;
}

int ag_cli_is_cloud_file(const char *path)
{
    ag_filemap fm;
    if (ag_filemap_open(path, &fm, NULL) != AG_OK)
        return 0; /* the mesh path reports the problem */
    int cloud = ag_cloud_import_is_cloud(fm.data, fm.len, path);
    ag_filemap_close(&fm);
    return cloud;
}

int ag_cli_is_cloud_output(const char *path)
{
    return ends_with(path, ".las") || ends_with(path, ".laz") || ends_with(path, ".xyz") ||
           ends_with(path, ".txt") || ends_with(path, ".ply");
}

int ag_cli_load_cloud(const char *path, ag_cloud **out)
{
    ag_error err;
    ag_error_clear(&err);
    if (ag_cloud_import_file(path, out, &err) != AG_OK) {
        ag_cli_report(path, &err);
        return 1;
    }
    return 0;
}

int ag_cli_write_cloud(const ag_cloud *c, const char *path, int double_xyz)
{
    ag_error err;
    ag_error_clear(&err);
    ag_status st;
    if (ends_with(path, ".las")) {
        ag_las_write_options lo = {.point_format = -1};
        st = ag_las_write_file(c, &lo, path, &err);
    } else if (ends_with(path, ".laz")) {
        fprintf(stderr, "archgram: %s: writing LAZ is not supported; write .las (and compress "
                        "it with laszip if you need LAZ)\n",
                path);
        return 2;
    } else if (ends_with(path, ".xyz") || ends_with(path, ".txt")) {
        FILE *f = fopen(path, "w");
        if (!f) {
            fprintf(stderr, "archgram: %s: %s\n", path, strerror(errno));
            return 1;
        }
        st = ag_xyz_write(c, f, &err);
        if (fclose(f) && st == AG_OK)
            st = ag_error_set(&err, AG_ERR_IO, 0, "cannot write: %s", strerror(errno));
    } else if (ends_with(path, ".ply")) {
        ag_ply_write_options po = {.double_xyz = double_xyz};
        st = ag_ply_write_file(c, &po, path, &err);
    } else {
        fprintf(stderr, "archgram: %s: cannot tell the output format (use .ply, .las or .xyz)\n",
                path);
        return 2;
    }
    if (st != AG_OK) {
        ag_cli_report(path, &err);
        return 1;
    }
    return 0;
}

/* The format name and size of a file. */
static const char *format_of(const char *path, size_t *bytes)
{
    ag_filemap fm;
    *bytes = 0;
    if (ag_filemap_open(path, &fm, NULL) != AG_OK)
        return "unknown";
    const char *name = ag_cloud_format_name(ag_cloud_format_sniff(fm.data, fm.len, path));
    *bytes = fm.len;
    ag_filemap_close(&fm);
    return name;
}

static void prop_range(const ag_cloud *c, const ag_cloud_property *p, double *lo, double *hi)
{
    *lo = INFINITY;
    *hi = -INFINITY;
    for (size_t i = 0; i < c->n; i++) {
        double v = ag_cloud_get(p, i);
        if (v < *lo)
            *lo = v;
        if (v > *hi)
            *hi = v;
    }
}

int ag_cli_cloud_info(const char *file, int as_json)
{
    ag_cloud *c;
    if (ag_cli_load_cloud(file, &c))
        return 1;
    double mn[3], mx[3];
    ag_cloud_bounds(c, mn, mx);
    for (int a = 0; a < 3 && c->n; a++) {
        mn[a] += c->offset[a];
        mx[a] += c->offset[a];
    }
    double diag = ag_cloud_diagonal(c);
    size_t bytes;
    const char *fmt = format_of(file, &bytes);
    if (as_json) {
        json_t *j = json_object();
        json_object_set_new(j, "file", json_string(file));
        json_object_set_new(j, "bytes", json_integer((json_int_t)bytes));
        json_object_set_new(j, "kind", json_string("pointcloud"));
        json_object_set_new(j, "format", json_string(fmt));
        json_object_set_new(j, "points", json_integer((json_int_t)c->n));
        json_object_set_new(j, "normals", json_boolean(c->normals != NULL));
        json_t *off = json_array(), *bmin = json_array(), *bmax = json_array(), *sc = json_array();
        for (int a = 0; a < 3; a++) {
            json_array_append_new(off, json_real(c->offset[a]));
            json_array_append_new(sc, json_real(c->scale[a]));
            json_array_append_new(bmin, c->n ? json_real(mn[a]) : json_null());
            json_array_append_new(bmax, c->n ? json_real(mx[a]) : json_null());
        }
        json_object_set_new(j, "offset", off);
        json_object_set_new(j, "scale", sc);
        json_object_set_new(j, "min", bmin);
        json_object_set_new(j, "max", bmax);
        json_object_set_new(j, "diagonal", json_real(diag));
        json_t *props = json_array();
        for (size_t p = 0; p < c->nprops; p++) {
            const ag_cloud_property *pr = &c->props[p];
            double lo, hi;
            prop_range(c, pr, &lo, &hi);
            json_t *o = json_object();
            json_object_set_new(o, "name", json_string(pr->name));
            json_object_set_new(o, "type", json_string(ag_scalar_name(pr->type)));
            json_object_set_new(o, "min", c->n ? json_real(lo) : json_null());
            json_object_set_new(o, "max", c->n ? json_real(hi) : json_null());
            json_array_append_new(props, o);
        }
        json_object_set_new(j, "properties", props);
        json_dumpf(j, stdout, JSON_INDENT(2) | JSON_PRESERVE_ORDER | JSON_REAL_PRECISION(15));
        putchar('\n');
        json_decref(j);
    } else {
        printf("file        %s\n", file);
        printf("bytes       %zu\n", bytes);
        printf("format      %s point cloud\n", fmt);
        printf("points      %zu\n", c->n);
        printf("normals     %s\n", c->normals ? "yes" : "no");
        if (c->offset[0] || c->offset[1] || c->offset[2])
            printf("offset      %.3f %.3f %.3f (local origin)\n", c->offset[0], c->offset[1],
                   c->offset[2]);
        if (c->scale[0] > 0)
            printf("scale       %g %g %g\n", c->scale[0], c->scale[1], c->scale[2]);
        if (c->n) {
            printf("bounds      min %.6f %.6f %.6f  max %.6f %.6f %.6f\n", mn[0], mn[1], mn[2],
                   mx[0], mx[1], mx[2]);
            printf("size        %.6g x %.6g x %.6g, diagonal %.6g\n", mx[0] - mn[0],
                   mx[1] - mn[1], mx[2] - mn[2], diag);
        }
        for (size_t p = 0; p < c->nprops; p++) {
            const ag_cloud_property *pr = &c->props[p];
            double lo, hi;
            prop_range(c, pr, &lo, &hi);
            printf("property    %-22s %-8s", pr->name, ag_scalar_name(pr->type));
            if (c->n)
                printf(" %.10g .. %.10g", lo, hi);
            putchar('\n');
        }
    }
    ag_cloud_free(c);
    return ferror(stdout) ? 1 : 0;
}

int ag_cli_cloud_convert(const char *in, const char *out, int double_xyz)
{
    ag_cloud *c;
    if (ag_cli_load_cloud(in, &c))
        return 1;
    int rc = ag_cli_write_cloud(c, out, double_xyz);
    ag_cloud_free(c);
    return rc;
}
