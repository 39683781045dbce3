#include "raster.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define SS 2 /* samples per pixel along each axis */

typedef struct {
    double r[3], u[3], f[3]; /* image right, image up, view direction */
    double cx, cy, scale;    /* centre of the projected bounds and pixels per metre */
    double w, h;             /* size of the sampled image */
} frame;

static double dot(const double *a, const double *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void cross(const double *a, const double *b, double *o)
{
    o[0] = a[1] * b[2] - a[2] * b[1];
    o[1] = a[2] * b[0] - a[0] * b[2];
    o[2] = a[0] * b[1] - a[1] * b[0];
}

static int normalize(double *v)
{
    double n = sqrt(dot(v, v));
    if (!(n > 1e-300) || !isfinite(n))
        return -1;
    for (int i = 0; i < 3; i++)
        v[i] /= n;
    return 0;
}

/* The view's basis and the fit of the mesh's projected bounds into w x h (sampled) pixels. */
static int make_frame(const ag_mesh *m, const ag_raster_view *v, double w, double h, frame *fr)
{
    memcpy(fr->f, v->dir, sizeof fr->f);
    if (normalize(fr->f))
        return -1;
    cross(fr->f, v->up, fr->r);
    if (normalize(fr->r))
        return -1;
    cross(fr->r, fr->f, fr->u);
    double x0 = DBL_MAX, x1 = -DBL_MAX, y0 = DBL_MAX, y1 = -DBL_MAX;
    for (size_t t = 0; t < 3 * m->ntris; t++) {
        const double *p = m->pos + 3 * (size_t)m->tri[t];
        double x = dot(p, fr->r), y = dot(p, fr->u);
        /* comparisons, not fmin/fmax: those are calls here, for every corner */
        x0 = x < x0 ? x : x0;
        x1 = x > x1 ? x : x1;
        y0 = y < y0 ? y : y0;
        y1 = y > y1 ? y : y1;
    }
    fr->w = w;
    fr->h = h;
    if (x0 > x1) { /* nothing to draw */
        fr->cx = fr->cy = 0;
        fr->scale = 1;
        return 0;
    }
    fr->cx = 0.5 * (x0 + x1);
    fr->cy = 0.5 * (y0 + y1);
    double margin = fmin(fmax(v->margin, 0.0), 0.4);
    double aw = w * (1 - 2 * margin), ah = h * (1 - 2 * margin);
    double ex = x1 - x0, ey = y1 - y0;
    double sx = ex > 0 ? aw / ex : INFINITY, sy = ey > 0 ? ah / ey : INFINITY;
    fr->scale = fmin(sx, sy);
    if (!isfinite(fr->scale))
        fr->scale = 1; /* a single point */
    return 0;
}

static void to_pixel(const frame *fr, const double *p, double *x, double *y, double *z)
{
    *x = 0.5 * fr->w + (dot(p, fr->r) - fr->cx) * fr->scale;
    *y = 0.5 * fr->h - (dot(p, fr->u) - fr->cy) * fr->scale;
    *z = dot(p, fr->f);
}

void ag_raster_image_clear(ag_raster_image *img)
{
    if (!img)
        return;
    free(img->rgba);
    memset(img, 0, sizeof *img);
}

void ag_raster_project(const ag_mesh *m, const ag_raster_view *view, unsigned width,
                       unsigned height, const double p[3], double *x, double *y)
{
    frame fr;
    double z;
    if (make_frame(m, view, (double)width, (double)height, &fr)) {
        *x = *y = NAN;
        return;
    }
    to_pixel(&fr, p, x, y, &z);
}

static double edge(double ax, double ay, double bx, double by, double px, double py)
{
    return (bx - ax) * (py - ay) - (by - ay) * (px - ax);
}

ag_status ag_raster_mesh(const ag_mesh *m, const ag_raster_view *view, unsigned width,
                         unsigned height, ag_raster_image *out, ag_error *err)
{
    memset(out, 0, sizeof *out);
    if (width < 1 || height < 1 || width > AG_RASTER_MAX_SIDE || height > AG_RASTER_MAX_SIDE)
        return ag_error_set(err, AG_ERR_INVALID, 0, "an image is 1 to %d pixels on a side",
                            AG_RASTER_MAX_SIDE);
    size_t sw = (size_t)width * SS, sh = (size_t)height * SS, ns = sw * sh;
    frame fr;
    if (make_frame(m, view, (double)sw, (double)sh, &fr))
        return ag_error_set(err, AG_ERR_INVALID, 0,
                            "the view direction is zero or parallel to its up direction");
    float *depth = malloc(ns * sizeof *depth);
    uint8_t *rgb = malloc(ns * 3);
    uint8_t *hit = calloc(ns, 1);
    out->rgba = malloc((size_t)width * height * 4);
    if (!depth || !rgb || !hit || !out->rgba) {
        free(depth);
        free(rgb);
        free(hit);
        ag_raster_image_clear(out);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory drawing a picture");
    }
    for (size_t i = 0; i < ns; i++)
        depth[i] = FLT_MAX;
    /* light from over the viewer's left shoulder */
    double light[3];
    for (int a = 0; a < 3; a++)
        light[a] = -fr.f[a] + 0.8 * fr.u[a] - 0.5 * fr.r[a];
    normalize(light);
    for (size_t t = 0; t < m->ntris; t++) {
        const double *p[3];
        double x[3], y[3], z[3];
        for (int k = 0; k < 3; k++) {
            p[k] = m->pos + 3 * (size_t)m->tri[3 * t + k];
            to_pixel(&fr, p[k], &x[k], &y[k], &z[k]);
        }
        double area = edge(x[0], y[0], x[1], y[1], x[2], y[2]);
        if (!(fabs(area) > 1e-12))
            continue; /* seen edge-on */
        /* Sample centres (px + 0.5, py + 0.5) inside the bounds only; the edge functions are
         * linear, so they step by a constant along a row, and a sample's depth is needed only
         * when it is inside (on an edge counts as inside). Faces many times the samples: the
         * thumbnail of a facade draws ~80k triangles over 64k samples. */
        double bx0 = fmin(x[0], fmin(x[1], x[2])), bx1 = fmax(x[0], fmax(x[1], x[2]));
        double by0 = fmin(y[0], fmin(y[1], y[2])), by1 = fmax(y[0], fmax(y[1], y[2]));
        long ix0 = (long)fmax(0.0, ceil(bx0 - 0.5));
        long ix1 = (long)fmin((double)sw - 1, floor(bx1 - 0.5));
        long iy0 = (long)fmax(0.0, ceil(by0 - 0.5));
        long iy1 = (long)fmin((double)sh - 1, floor(by1 - 0.5));
        if (ix0 > ix1 || iy0 > iy1)
            continue;
        double e1[3], e2[3], n[3];
        for (int a = 0; a < 3; a++) {
            e1[a] = p[1][a] - p[0][a];
            e2[a] = p[2][a] - p[0][a];
        }
        cross(e1, e2, n);
        double shade = normalize(n) ? 1.0 : 0.3 + 0.7 * fabs(dot(n, light));
        const uint8_t *base = view->colour;
        uint32_t comp = m->tri_component ? m->tri_component[t] : 0;
        if (view->group_rgb && comp < m->ncomponents) {
            int32_t g = m->component_group[comp];
            if (g >= 0 && (size_t)g < view->ngroups)
                base = view->group_rgb[g];
        }
        uint8_t c[3];
        for (int a = 0; a < 3; a++)
            c[a] = (uint8_t)fmin(255.0, base[a] * shade + 0.5);
        /* e_k(cx, cy) = a_k cx + b_k cy + c_k, the sign of the area making inside >= 0 */
        double sgn = area > 0 ? 1 : -1, inv = 1 / area;
        int j1[3] = {1, 2, 0}, j2[3] = {2, 0, 1};
        double ea[3], eb[3], ec[3];
        for (int k = 0; k < 3; k++) {
            double ax = x[j1[k]], ay = y[j1[k]], bx = x[j2[k]], by = y[j2[k]];
            ea[k] = -(by - ay) * sgn;
            eb[k] = (bx - ax) * sgn;
            ec[k] = ((by - ay) * ax - (bx - ax) * ay) * sgn;
        }
        double fx = ix0 + 0.5;
        for (long py = iy0; py <= iy1; py++) {
            double cy = py + 0.5;
            double s0 = ea[0] * fx + eb[0] * cy + ec[0];
            double s1 = ea[1] * fx + eb[1] * cy + ec[1];
            double s2 = ea[2] * fx + eb[2] * cy + ec[2];
            size_t i = (size_t)py * sw + (size_t)ix0;
            for (long px = ix0; px <= ix1; px++, i++, s0 += ea[0], s1 += ea[1], s2 += ea[2]) {
                if (s0 < 0 || s1 < 0 || s2 < 0)
                    continue;
                double w0 = s0 * sgn * inv, w1 = s1 * sgn * inv;
                float d = (float)(w0 * z[0] + w1 * z[1] + (1 - w0 - w1) * z[2]);
                if (d >= depth[i])
                    continue;
                depth[i] = d;
                hit[i] = 1;
                memcpy(rgb + 3 * i, c, 3);
            }
        }
    }
    /* each pixel the mean of its samples, empty samples counting as the background */
    for (unsigned py = 0; py < height; py++)
        for (unsigned px = 0; px < width; px++) {
            double acc[4] = {0, 0, 0, 0};
            for (int sy = 0; sy < SS; sy++)
                for (int sx = 0; sx < SS; sx++) {
                    size_t i = ((size_t)py * SS + sy) * sw + (size_t)px * SS + sx;
                    if (hit[i]) {
                        for (int a = 0; a < 3; a++)
                            acc[a] += rgb[3 * i + a];
                        acc[3] += 255;
                    } else {
                        for (int a = 0; a < 4; a++)
                            acc[a] += view->background[a];
                    }
                }
            uint8_t *o = out->rgba + 4 * ((size_t)py * width + px);
            for (int a = 0; a < 4; a++)
                o[a] = (uint8_t)(acc[a] / (SS * SS) + 0.5);
        }
    free(depth);
    free(rgb);
    free(hit);
    out->width = width;
    out->height = height;
    return AG_OK;
}
