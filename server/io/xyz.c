#include "xyz.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define MAX_VALUES 9
#define MAX_TOKEN 64

static int is_sep(uint8_t ch)
{
    return ch == ' ' || ch == '\t' || ch == ',' || ch == ';' || ch == '\r' || ch == '\f' ||
           ch == '\v';
}

/* Values of one line [p, e) into v; returns the count, -1 for a bad token (its text in
 * bad), -2 for more than MAX_VALUES values. */
static int parse_line(const uint8_t *p, const uint8_t *e, double *v, char *bad)
{
    int n = 0;
    char tok[MAX_TOKEN + 1];
    while (p < e) {
        while (p < e && is_sep(*p))
            p++;
        if (p >= e)
            break;
        size_t k = 0;
        while (p < e && !is_sep(*p)) {
            if (k < MAX_TOKEN)
                tok[k] = (char)*p;
            k++;
            p++;
        }
        if (k > MAX_TOKEN) {
            snprintf(bad, MAX_TOKEN + 1, "%.*s", MAX_TOKEN, tok);
            return -1;
        }
        tok[k] = 0;
        if (n == MAX_VALUES)
            return -2;
        char *end;
        errno = 0;
        double d = strtod(tok, &end);
        if (*end || end == tok) {
            snprintf(bad, MAX_TOKEN + 1, "%s", tok);
            return -1;
        }
        v[n++] = d;
    }
    return n;
}

ag_status ag_xyz_read_buffer(const uint8_t *data, size_t len, ag_cloud **out, ag_error *err)
{
    *out = NULL;
    double *vals = NULL;
    size_t nvals = 0, cap = 0, points = 0, line = 0;
    int width = 0;
    const uint8_t *p = data, *end = data + len;
    char bad[MAX_TOKEN + 1];
    while (p < end) {
        const uint8_t *nl = memchr(p, '\n', (size_t)(end - p));
        const uint8_t *e = nl ? nl : end;
        line++;
        const uint8_t *s = p;
        p = nl ? nl + 1 : end;
        while (s < e && is_sep(*s))
            s++;
        if (s == e || *s == '#' || (e - s >= 2 && s[0] == '/' && s[1] == '/'))
            continue;
        double v[MAX_VALUES];
        int n = parse_line(s, e, v, bad);
        if (n == -1) {
            free(vals);
            return ag_error_set(err, AG_ERR_PARSE, (long)line, "line %zu: '%s' is not a number",
                                line, bad);
        }
        if (n == -2 || (n != 3 && n != 6 && n != 9)) {
            free(vals);
            char count[16];
            snprintf(count, sizeof count, n == -2 ? "more than 9" : "%d", n);
            return ag_error_set(err, AG_ERR_PARSE, (long)line,
                                "line %zu: %s values; expected x y z [nx ny nz] [r g b]", line,
                                count);
        }
        if (!width)
            width = n;
        if (n != width) {
            free(vals);
            return ag_error_set(err, AG_ERR_PARSE, (long)line,
                                "line %zu: %d values where the first point line had %d", line, n,
                                width);
        }
        if (!isfinite(v[0]) || !isfinite(v[1]) || !isfinite(v[2])) {
            free(vals);
            return ag_error_set(err, AG_ERR_PARSE, (long)line,
                                "line %zu: a coordinate is not a finite number", line);
        }
        if (nvals + (size_t)n > cap) {
            size_t nc = cap ? 2 * cap : 3 * 4096;
            double *q = nc < SIZE_MAX / sizeof *q ? realloc(vals, nc * sizeof *q) : NULL;
            if (!q) {
                free(vals);
                return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory at line %zu", line);
            }
            vals = q;
            cap = nc;
        }
        memcpy(vals + nvals, v, (size_t)n * sizeof *v);
        nvals += (size_t)n;
        points++;
    }
    if (!points) {
        free(vals);
        return ag_error_set(err, AG_ERR_EMPTY, 0, "no point lines");
    }
    /* what the 4th to 6th values are */
    int normals = 0, colour = width == 9;
    if (width == 6) {
        normals = 1;
        for (size_t i = 0; i < points && normals; i++) {
            const double *q = vals + i * 6 + 3;
            double l = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]);
            normals = fabs(l - 1) <= 0.1;
        }
        colour = !normals;
    }
    if (width == 9)
        normals = 1;
    int col_at = width == 9 ? 6 : 3, bytes = 1;
    if (colour)
        for (size_t i = 0; i < points && bytes; i++)
            for (int a = 0; a < 3; a++) {
                double c = vals[i * (size_t)width + (size_t)col_at + (size_t)a];
                if (!(c >= 0 && c <= 255 && c == floor(c)))
                    bytes = 0;
            }
    ag_cloud *c = ag_cloud_create();
    ag_status st = c ? ag_cloud_resize(c, points, err) : ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    if (st == AG_OK && normals)
        st = ag_cloud_add_normals(c, err);
    size_t rgb[3];
    static const char *const names[3] = {"red", "green", "blue"};
    for (int a = 0; st == AG_OK && colour && a < 3; a++)
        st = ag_cloud_add_property(c, names[a], bytes ? AG_SCALAR_UINT8 : AG_SCALAR_FLOAT32, &rgb[a],
                                   err);
    if (st != AG_OK) {
        free(vals);
        ag_cloud_free(c);
        return st;
    }
    for (size_t i = 0; i < points; i++) {
        const double *q = vals + i * (size_t)width;
        memcpy(c->xyz + 3 * i, q, 3 * sizeof *q);
        if (normals)
            for (int a = 0; a < 3; a++)
                c->normals[3 * i + a] = (float)q[3 + a];
        for (int a = 0; colour && a < 3; a++)
            ag_cloud_set(&c->props[rgb[a]], i, q[col_at + a]);
    }
    free(vals);
    double mn[3], mx[3], origin[3];
    ag_cloud_bounds(c, mn, mx);
    ag_cloud_choose_origin(mn, mx, origin);
    ag_cloud_rebase(c, origin);
    *out = c;
    return AG_OK;
}

/* The decimals that write a coordinate of resolution `scale` (a LAS scale: 0.001 gives 3)
 * exactly, or -1 when there is no such resolution or it needs more than 9 (then %.17g):
 * 84916.949, not the 84916.949000000008 that the local origin's sum prints as. */
static int decimals_of(double scale)
{
    if (!(scale > 0) || !isfinite(scale))
        return -1;
    double t = scale;
    for (int d = 0; d <= 9; d++, t *= 10)
        if (round(t) >= 1 && fabs(t - round(t)) < 1e-9 * t)
            return d;
    return -1;
}

ag_status ag_xyz_write(const ag_cloud *c, FILE *f, ag_error *err)
{
    const ag_cloud_property *rgb[3] = {ag_cloud_find(c, "red"), ag_cloud_find(c, "green"),
                                       ag_cloud_find(c, "blue")};
    int colour = rgb[0] && rgb[1] && rgb[2];
    int dec[3] = {decimals_of(c->scale[0]), decimals_of(c->scale[1]), decimals_of(c->scale[2])};
    for (size_t i = 0; i < c->n; i++) {
        const double *p = c->xyz + 3 * i;
        for (int k = 0; k < 3; k++) {
            double v = p[k] + c->offset[k];
            if (dec[k] >= 0)
                fprintf(f, k ? " %.*f" : "%.*f", dec[k], v);
            else
                fprintf(f, k ? " %.17g" : "%.17g", v);
        }
        if (c->normals)
            fprintf(f, " %.9g %.9g %.9g", c->normals[3 * i], c->normals[3 * i + 1],
                    c->normals[3 * i + 2]);
        if (colour)
            fprintf(f, " %.9g %.9g %.9g", ag_cloud_get(rgb[0], i), ag_cloud_get(rgb[1], i),
                    ag_cloud_get(rgb[2], i));
        fputc('\n', f);
    }
    if (ferror(f))
        return ag_error_set(err, AG_ERR_IO, 0, "write error: %s", strerror(errno));
    return AG_OK;
}
