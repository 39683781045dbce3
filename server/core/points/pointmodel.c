#include "pointmodel.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../base/array.h"
#include "../base/clock.h"
#include "../base/kdtree.h"
#include "../base/tolerance.h"
#include "../proc/label.h"
#include "../proc/patterns.h"
#include "../proc/rules.h"
#include "../proc/splittree.h"
#include "resample.h"

/* Derivations stop past this many points unless the caller sets its own limit. */
#define DERIVE_MAX_POINTS 100000000
/* The proxy tetrahedron's triangles; their first use of the vertices is 0, 1, 2, 3. */
static const uint32_t tetra_tris[4][3] = {{0, 1, 2}, {0, 3, 1}, {0, 2, 3}, {1, 3, 2}};
/* A terminal axis at or below this is flat: its tetrahedron leg is 1 (the grammar does not
 * scale such an axis, see gframe.h). */
#define FLAT AG_PROC_TINY

ag_pointmodel *ag_pointmodel_create(void)
{
    return calloc(1, sizeof(ag_pointmodel));
}

void ag_pointmodel_free(ag_pointmodel *pm)
{
    if (!pm)
        return;
    for (size_t t = 0; t < pm->nterminals; t++)
        ag_cloud_free(pm->terminals[t].points);
    free(pm->terminals);
    free(pm->placements);
    ag_edit_model_free(pm->em);
    free(pm);
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Neighbours asked for the spacing: more than a point's copies in a scan that repeats them. */
#define SPACING_K 16

/* Median distance from a point to its nearest point elsewhere (0 for fewer than two places). */
static ag_status median_spacing(const ag_cloud *c, double *out, ag_error *err)
{
    *out = 0;
    if (c->n < 2)
        return AG_OK;
    /* a stride sample is enough for a median */
    size_t step = c->n > 20000 ? c->n / 20000 : 1, m = 0;
    ag_kdtree *t;
    ag_status st = ag_kdtree_build(c->xyz, NULL, c->n, &t, err);
    if (st != AG_OK)
        return st;
    double *d = malloc((c->n / step + 1) * sizeof *d);
    if (!d) {
        ag_kdtree_free(t);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    /* the nearest point at another place: copies of a point (a scan that repeats points)
     * are no spacing */
    for (size_t i = 0; i < c->n; i += step) {
        uint32_t id[SPACING_K];
        double d2[SPACING_K];
        size_t got = ag_kdtree_knn(t, c->xyz + 3 * i, SPACING_K, id, d2);
        for (size_t q = 1; q < got; q++)
            if (d2[q] > 0) {
                d[m++] = sqrt(d2[q]);
                break;
            }
    }
    ag_kdtree_free(t);
    if (m) {
        qsort(d, m, sizeof *d, cmp_double);
        *out = d[m / 2];
    }
    free(d);
    return AG_OK;
}

/* The quarter turns of a map of the form diag(s) R_k. */
static int turn_of(const double A[3][3])
{
    if (fabs(A[0][0]) >= fabs(A[0][1]))
        return A[0][0] >= 0 ? 0 : 2;
    return A[1][0] >= 0 ? 1 : 3;
}

static void place_box(const ag_pointmodel_placement *p, const double size[3], ag_box *box)
{
    *box = ag_box_empty();
    for (int k = 0; k < 8; k++) {
        double q[3] = {k & 1 ? size[0] : 0, k & 2 ? size[1] : 0, k & 4 ? size[2] : 0}, x[3];
        for (int i = 0; i < 3; i++)
            x[i] = p->A[i][0] * q[0] + p->A[i][1] * q[1] + p->A[i][2] * q[2] + p->b[i];
        ag_box_extend_point(box, x);
    }
}

ag_status ag_pointmodel_add_terminal(ag_pointmodel *pm, ag_cloud **points, const ag_box *box,
                                     double min_thickness, double spacing, double origin[3],
                                     size_t *index, ag_error *err)
{
    ag_cloud *c = *points;
    ag_box b = box ? *box : ag_cloud_box(c);
    if (ag_box_is_empty(&b))
        return ag_error_set(err, AG_ERR_INVALID, 0, "a terminal needs points or a box");
    for (int a = 0; a < 3; a++)
        if (ag_box_extent(&b, a) < min_thickness) {
            double mid = ag_box_centre_axis(&b, a);
            b.min[a] = mid - 0.5 * min_thickness;
            b.max[a] = mid + 0.5 * min_thickness;
        }
    if (AG_ARRAY_RESERVE(pm->terminals, pm->cap_terminals, pm->nterminals + 1))
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    /* the model owns these */
    ag_cloud_remove_property(c, "label");
    ag_cloud_remove_property(c, "segment");
    ag_cloud_remove_property(c, "piece");
    for (size_t i = 0; i < c->n; i++)
        for (int a = 0; a < 3; a++)
            c->xyz[3 * i + a] -= b.min[a];
    memset(c->offset, 0, sizeof c->offset);
    ag_pointmodel_terminal *t = &pm->terminals[pm->nterminals];
    memset(t, 0, sizeof *t);
    ag_box_extents(&b, t->size);
    t->spacing = spacing;
    if (!(spacing > 0)) {
        ag_status st = median_spacing(c, &t->spacing, err);
        if (st != AG_OK)
            return st;
        if (!(t->spacing > 0))
            t->spacing = pm->spacing > 0 ? pm->spacing : 0.01;
    }
    t->points = c;
    t->members = 1;
    t->merged = 1;
    t->points_before = c->n;
    t->mean_before = (double)c->n;
    *points = NULL;
    if (origin)
        memcpy(origin, b.min, sizeof b.min);
    if (index)
        *index = pm->nterminals;
    pm->nterminals++;
    return AG_OK;
}

ag_status ag_pointmodel_add_placement(ag_pointmodel *pm, int32_t terminal, const double A[3][3],
                                      const double b[3], ag_error *err)
{
    if (terminal < 0 || (size_t)terminal >= pm->nterminals)
        return ag_error_set(err, AG_ERR_INTERNAL, 0, "placement of terminal %d of %zu",
                            (int)terminal, pm->nterminals);
    for (int i = 0; i < 3; i++)
        if (!isfinite(b[i]) || !isfinite(A[i][0]) || !isfinite(A[i][1]) || !isfinite(A[i][2]))
            return ag_error_set(err, AG_ERR_INVALID, 0, "a placement that is not finite");
    if (AG_ARRAY_RESERVE(pm->placements, pm->cap_placements, pm->nplacements + 1))
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    ag_pointmodel_placement *p = &pm->placements[pm->nplacements++];
    memset(p, 0, sizeof *p);
    p->terminal = terminal;
    memcpy(p->A, A, sizeof p->A);
    memcpy(p->b, b, sizeof p->b);
    p->rot = (uint8_t)turn_of(A);
    place_box(p, pm->terminals[terminal].size, &p->box);
    return AG_OK;
}

/* ---- build ------------------------------------------------------------------------------ */

/* Drops terminals without placements (renumbering the rest). */
static void drop_unused(ag_pointmodel *pm)
{
    int32_t *map = calloc(pm->nterminals + 1, sizeof *map);
    if (!map)
        return; /* nothing dropped: still a valid model */
    for (size_t i = 0; i < pm->nplacements; i++)
        map[pm->placements[i].terminal] = 1;
    size_t k = 0;
    for (size_t t = 0; t < pm->nterminals; t++) {
        if (!map[t]) {
            ag_cloud_free(pm->terminals[t].points);
            map[t] = -1;
            continue;
        }
        pm->terminals[k] = pm->terminals[t];
        map[t] = (int32_t)k++;
    }
    pm->nterminals = k;
    for (size_t i = 0; i < pm->nplacements; i++)
        pm->placements[i].terminal = map[pm->placements[i].terminal];
    free(map);
}

/* Turns terminal t's points by k quarter turns (about z, within its box) and its placements
 * back, so that a placement with turn k becomes unturned. */
static void turn_terminal(ag_pointmodel *pm, int32_t t, int k)
{
    ag_pointmodel_terminal *T = &pm->terminals[t];
    double S[3] = {T->size[0], T->size[1], T->size[2]};
    double S2[3] = {k & 1 ? S[1] : S[0], k & 1 ? S[0] : S[1], S[2]};
    /* p' = R_k (p - S/2) + S'/2; the placements' A' = A R_k^-1, b' = b + A (S/2) - A' (S'/2) */
    for (size_t i = 0; i < T->points->n; i++) {
        double *p = T->points->xyz + 3 * i;
        double x = p[0] - S[0] / 2, y = p[1] - S[1] / 2;
        ag_label_rotate(k, &x, &y);
        p[0] = x + S2[0] / 2;
        p[1] = y + S2[1] / 2;
        if (T->points->normals) {
            float *n = T->points->normals + 3 * i;
            double nx = n[0], ny = n[1];
            ag_label_rotate(k, &nx, &ny);
            n[0] = (float)nx;
            n[1] = (float)ny;
        }
    }
    memcpy(T->size, S2, sizeof S2);
    /* R_k^-1 = R_{-k}: its columns */
    double R[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, Ri[3][3];
    for (int j = 0; j < 3; j++) {
        double x = R[0][j], y = R[1][j];
        ag_label_rotate((4 - k) & 3, &x, &y);
        Ri[0][j] = x;
        Ri[1][j] = y;
        Ri[2][j] = R[2][j];
    }
    for (size_t i = 0; i < pm->nplacements; i++) {
        ag_pointmodel_placement *p = &pm->placements[i];
        if (p->terminal != t)
            continue;
        double A2[3][3];
        for (int r = 0; r < 3; r++)
            for (int c = 0; c < 3; c++)
                A2[r][c] = p->A[r][0] * Ri[0][c] + p->A[r][1] * Ri[1][c] + p->A[r][2] * Ri[2][c];
        for (int r = 0; r < 3; r++)
            p->b[r] += p->A[r][0] * S[0] / 2 + p->A[r][1] * S[1] / 2 + p->A[r][2] * S[2] / 2 -
                       (A2[r][0] * S2[0] / 2 + A2[r][1] * S2[1] / 2 + A2[r][2] * S2[2] / 2);
        memcpy(p->A, A2, sizeof A2);
        p->rot = (uint8_t)turn_of(p->A);
    }
}

/* Legs of a terminal's tetrahedron. */
static void legs_of(const double size[3], double L[3])
{
    for (int a = 0; a < 3; a++)
        L[a] = size[a] > FLAT ? size[a] : 1;
}

ag_status ag_pointmodel_proxy_mesh(const ag_pointmodel *pm, ag_mesh **out, ag_error *err)
{
    ag_mesh *m = ag_mesh_create();
    ag_status st = m ? ag_mesh_reserve(m, 4 * pm->nplacements, 4 * pm->nplacements)
                     : AG_ERR_NOMEM;
    for (size_t t = 0; t < pm->nterminals && !st; t++) {
        char name[32];
        snprintf(name, sizeof name, "L%zu", t + 1);
        st = ag_mesh_add_group(m, name, NULL);
    }
    for (size_t i = 0; i < pm->nplacements && !st; i++) {
        const ag_pointmodel_placement *p = &pm->placements[i];
        double L[3];
        legs_of(pm->terminals[p->terminal].size, L);
        size_t comp, v0 = m->nverts;
        st = ag_mesh_add_component(m, p->terminal, &comp);
        for (int k = 0; k < 4 && !st; k++) {
            double q[3] = {k == 1 ? L[0] : 0, k == 2 ? L[1] : 0, k == 3 ? L[2] : 0}, x[3];
            for (int r = 0; r < 3; r++)
                x[r] = p->A[r][0] * q[0] + p->A[r][1] * q[1] + p->A[r][2] * q[2] + p->b[r];
            st = ag_mesh_add_vertex(m, x[0], x[1], x[2]);
        }
        for (int k = 0; k < 4 && !st; k++)
            st = ag_mesh_add_triangle(m, (uint32_t)(v0 + tetra_tris[k][0]),
                                      (uint32_t)(v0 + tetra_tris[k][1]),
                                      (uint32_t)(v0 + tetra_tris[k][2]), (uint32_t)comp);
    }
    if (st) {
        ag_mesh_free(m);
        return ag_error_set(err, st, 0, "out of memory for the proxy mesh");
    }
    *out = m;
    return AG_OK;
}

static ag_status proxy_labels(const ag_pointmodel *pm, ag_labels **out, ag_error *err)
{
    size_t n = pm->nplacements, nt = pm->nterminals;
    ag_labels *L = calloc(1, sizeof *L);
    if (!L)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    L->ncomponents = n;
    L->box = malloc((n + 1) * sizeof *L->box);
    L->ntris = malloc((n + 1) * sizeof *L->ntris);
    L->label = malloc((n + 1) * sizeof *L->label);
    L->rot = malloc(n + 1);
    L->variant = malloc((n + 1) * sizeof *L->variant);
    L->vrot = malloc(n + 1);
    L->tri_start = malloc((n + 1) * sizeof *L->tri_start);
    L->tris = malloc((4 * n + 1) * sizeof *L->tris);
    L->nlabels = L->nvariants = nt;
    L->exemplar = malloc((nt + 1) * sizeof *L->exemplar);
    L->count = calloc(nt + 1, sizeof *L->count);
    L->variant_exemplar = malloc((nt + 1) * sizeof *L->variant_exemplar);
    L->variant_count = calloc(nt + 1, sizeof *L->variant_count);
    L->variant_label = malloc((nt + 1) * sizeof *L->variant_label);
    if (!L->box || !L->ntris || !L->label || !L->rot || !L->variant || !L->vrot ||
        !L->tri_start || !L->tris || !L->exemplar || !L->count || !L->variant_exemplar ||
        !L->variant_count || !L->variant_label) {
        ag_labels_free(L);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    ag_box all = ag_box_empty();
    for (size_t t = 0; t < nt; t++) {
        L->exemplar[t] = L->variant_exemplar[t] = UINT32_MAX;
        L->variant_label[t] = (int32_t)t;
    }
    for (size_t c = 0; c < n; c++) {
        const ag_pointmodel_placement *p = &pm->placements[c];
        L->box[c] = p->box;
        ag_box_extend_box(&all, &p->box);
        L->ntris[c] = 4;
        L->label[c] = L->variant[c] = p->terminal;
        L->rot[c] = L->vrot[c] = p->rot;
        L->tri_start[c] = (uint32_t)(4 * c);
        for (int k = 0; k < 4; k++)
            L->tris[4 * c + k] = (uint32_t)(4 * c + k);
        L->count[p->terminal]++;
        L->variant_count[p->terminal]++;
        /* the exemplar: the first unturned placement (build turns terminals so one is) */
        if (L->exemplar[p->terminal] == UINT32_MAX && p->rot == 0)
            L->exemplar[p->terminal] = L->variant_exemplar[p->terminal] = (uint32_t)c;
    }
    L->tri_start[n] = (uint32_t)(4 * n);
    for (size_t t = 0; t < nt; t++)
        if (L->exemplar[t] == UINT32_MAX)
            L->exemplar[t] = L->variant_exemplar[t] = 0;
    L->diagonal = ag_box_diagonal(&all);
    L->tol = L->exact = pm->tolerance > 0 ? pm->tolerance : 1e-6 * (L->diagonal + 1);
    *out = L;
    return AG_OK;
}

/* Sets grammar terminal g to the size of model terminal t and a tetrahedron of it. */
static ag_status terminal_proxy(ag_gterminal *gt, const double size[3])
{
    double L[3];
    legs_of(size, L);
    double pos[12] = {0, 0, 0, L[0], 0, 0, 0, L[1], 0, 0, 0, L[2]};
    memcpy(gt->size, size, sizeof gt->size);
    return ag_grammar_set_terminal_geometry(gt, pos, 4, &tetra_tris[0][0], 4);
}

ag_status ag_pointmodel_build(ag_pointmodel *pm, ag_error *err)
{
    ag_edit_model_free(pm->em);
    pm->em = NULL;
    if (!pm->nplacements)
        return ag_error_set(err, AG_ERR_EMPTY, 0, "the model places no terminal");
    drop_unused(pm);
    /* every terminal with an unturned placement: the grammar's terminal frame */
    for (size_t t = 0; t < pm->nterminals; t++) {
        int first = -1, unturned = 0;
        for (size_t i = 0; i < pm->nplacements && !unturned; i++)
            if (pm->placements[i].terminal == (int32_t)t) {
                if (first < 0)
                    first = pm->placements[i].rot;
                unturned |= pm->placements[i].rot == 0;
            }
        if (!unturned && first > 0)
            turn_terminal(pm, (int32_t)t, first);
    }
    ag_proceduralize_result *r = calloc(1, sizeof *r);
    if (!r)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    double t0 = ag_clock_seconds(), c0 = ag_clock_thread_cpu_seconds();
    ag_status st = ag_pointmodel_proxy_mesh(pm, &r->mesh, err);
    if (!st)
        st = proxy_labels(pm, &r->labels, err);
    if (!st)
        st = ag_splittree_build(r->mesh, r->labels, &r->tree, err);
    if (!st)
        st = ag_rules_label(r->tree, err);
    if (!st)
        st = ag_patterns_find(r->tree, NULL, err);
    double t1 = ag_clock_seconds(), c1 = ag_clock_thread_cpu_seconds();
    if (!st)
        st = ag_grammar_export(r->mesh, r->labels, r->tree, &r->grammar, &r->info, err);
    /* the grammar's terminals: the terminals' own sizes (an exemplar may be stretched) */
    for (size_t t = 0; !st && t < pm->nterminals; t++) {
        int32_t g = t < r->info.nvariants ? r->info.terminal_of_variant[t] : -1;
        if (g >= 0 && (st = terminal_proxy(&r->grammar->terminals[g], pm->terminals[t].size)))
            st = ag_error_set(err, st, 0, "out of memory");
    }
    pm->build_seconds[0] = t1 - t0;
    pm->build_cpu_seconds[0] = c1 - c0;
    pm->build_seconds[1] = ag_clock_seconds() - t1;
    pm->build_cpu_seconds[1] = ag_clock_thread_cpu_seconds() - c1;
    r->segment.components = pm->nplacements;
    if (!st)
        st = ag_edit_model_wrap(r, NULL, &pm->em, err);
    if (st)
        ag_proceduralize_result_free(r);
    return st;
}

ag_status ag_pointmodel_grammar_terminals(const ag_pointmodel *pm, int32_t **term,
                                          ag_error *err)
{
    *term = NULL;
    if (!pm->em)
        return ag_error_set(err, AG_ERR_INVALID, 0, "the model is not built");
    const ag_proceduralize_result *r = pm->em->proc;
    int32_t *m = malloc((r->grammar->nterminals + 1) * sizeof *m);
    if (!m)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    for (size_t g = 0; g < r->grammar->nterminals; g++)
        m[g] = -1;
    for (size_t t = 0; t < pm->nterminals && t < r->info.nvariants; t++)
        if (r->info.terminal_of_variant[t] >= 0)
            m[r->info.terminal_of_variant[t]] = (int32_t)t;
    for (size_t g = 0; g < r->grammar->nterminals; g++)
        if (m[g] < 0) {
            free(m);
            return ag_error_set(err, AG_ERR_INTERNAL, 0, "grammar terminal %s is no terminal",
                                r->grammar->terminals[g].name);
        }
    *term = m;
    return AG_OK;
}

/* ---- proxies read back --------------------------------------------------------------------- */

ag_status ag_pointmodel_read_proxy(ag_pointmodel *pm, const ag_mesh *proxy,
                                   ag_pointmodel_lookup lookup, void *user, size_t *joined,
                                   ag_error *err)
{
    if (joined)
        *joined = 0;
    size_t nc = proxy->ncomponents;
    /* the triangles of each component, in order */
    uint32_t *start = calloc(nc + 2, sizeof *start), *tris = malloc((proxy->ntris + 1) * sizeof *tris);
    int32_t *gterm = malloc((proxy->ngroups + 1) * sizeof *gterm);
    if (!start || !tris || !gterm) {
        free(start);
        free(tris);
        free(gterm);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    for (size_t g = 0; g < proxy->ngroups; g++)
        gterm[g] = -1;
    for (size_t t = 0; t < proxy->ntris; t++)
        start[proxy->tri_component[t] + 1]++;
    for (size_t c = 0; c < nc; c++)
        start[c + 1] += start[c];
    {
        uint32_t *fill = malloc((nc + 1) * sizeof *fill);
        if (!fill) {
            free(start);
            free(tris);
            free(gterm);
            return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        }
        memcpy(fill, start, (nc + 1) * sizeof *fill);
        for (size_t t = 0; t < proxy->ntris; t++)
            tris[fill[proxy->tri_component[t]]++] = (uint32_t)t;
        free(fill);
    }
    ag_status st = AG_OK;
    for (size_t c = 0; c < nc && !st; c++) {
        size_t n = start[c + 1] - start[c];
        if (!n)
            continue;
        int32_t gi = proxy->component_group[c];
        if (n % 4) {
            st = ag_error_set(err, AG_ERR_INTERNAL, 0, "component %zu is no set of tetrahedra", c + 1);
            break;
        }
        if (joined && n > 4)
            *joined += n / 4 - 1;
        /* every tetrahedron: its vertices in first-use order */
        for (size_t q = 0; q < n / 4 && !st; q++) {
            uint32_t v[4];
            int nv = 0;
            for (size_t k = 0; k < 4; k++) {
                const uint32_t *tr = proxy->tri + 3 * (size_t)tris[start[c] + 4 * q + k];
                for (int j = 0; j < 3; j++) {
                    int seen = 0;
                    for (int u = 0; u < nv; u++)
                        seen |= v[u] == tr[j];
                    if (!seen && nv < 4)
                        v[nv++] = tr[j];
                }
            }
            if (nv != 4) {
                st = ag_error_set(err, AG_ERR_INTERNAL, 0, "component %zu: a tetrahedron without four corners", c + 1);
                break;
            }
            const double *p0 = proxy->pos + 3 * (size_t)v[0];
            double raw[3];
            for (int k = 0; k < 3; k++) {
                const double *pk = proxy->pos + 3 * (size_t)v[k + 1];
                raw[k] = sqrt((pk[0] - p0[0]) * (pk[0] - p0[0]) + (pk[1] - p0[1]) * (pk[1] - p0[1]) +
                              (pk[2] - p0[2]) * (pk[2] - p0[2]));
            }
            if (err)
                err->code = AG_OK;
            /* a group names one terminal, but a join's ("L3+L5") tells them by their legs */
            int32_t t = -1;
            if (gi >= 0 && gterm[gi] >= 0)
                t = gterm[gi];
            else if (gi >= 0) {
                t = lookup(user, proxy->group_names[gi], raw, err);
                if (!strchr(proxy->group_names[gi], '+'))
                    gterm[gi] = t;
            }
            if (t < 0) {
                st = err && err->code != AG_OK
                         ? err->code
                         : ag_error_set(err, AG_ERR_INTERNAL, 0,
                                        "component %zu (group %s) places no terminal", c + 1,
                                        gi >= 0 ? proxy->group_names[gi] : "none");
                break;
            }
            double L[3], A[3][3], b[3];
            legs_of(pm->terminals[t].size, L);
            for (int r = 0; r < 3; r++) {
                b[r] = p0[r];
                for (int k = 0; k < 3; k++)
                    A[r][k] = (proxy->pos[3 * (size_t)v[k + 1] + r] - p0[r]) / L[k];
            }
            st = ag_pointmodel_add_placement(pm, t, A, b, err);
        }
    }
    free(start);
    free(tris);
    free(gterm);
    return st;
}

/* ---- from a grammar ----------------------------------------------------------------------- */

typedef struct {
    const ag_grammar *g;
    const int32_t *model_of; /* per grammar terminal */
} grammar_lookup;

static int32_t lookup_grammar(void *user, const char *group, const double legs[3],
                              ag_error *err)
{
    const grammar_lookup *gl = user;
    (void)err;
    (void)legs;
    for (size_t k = 0; k < gl->g->nterminals; k++)
        if (!strcmp(gl->g->terminals[k].name, group))
            return gl->model_of[k];
    return -1;
}

/* The model terminal of each grammar terminal: label order when the labels are L1 .. Lk (the
 * names this model gives), else grammar order. */
static void terminal_order(const ag_grammar *g, int32_t *model_of)
{
    size_t k = g->nterminals;
    uint8_t *seen = calloc(k + 1, 1);
    int ok = seen != NULL;
    for (size_t i = 0; i < k && ok; i++) {
        const char *l = g->terminals[i].label_name;
        char *end;
        long v = l && l[0] == 'L' ? strtol(l + 1, &end, 10) : 0;
        ok = l && l[0] == 'L' && *end == 0 && v >= 1 && (size_t)v <= k && !seen[v - 1];
        if (ok) {
            seen[v - 1] = 1;
            model_of[i] = (int32_t)(v - 1);
        }
    }
    if (!ok)
        for (size_t i = 0; i < k; i++)
            model_of[i] = (int32_t)i;
    free(seen);
}

ag_status ag_pointmodel_from_grammar(const ag_grammar *g, ag_cloud **points,
                                     const double offset[3], ag_pointmodel **out,
                                     ag_error *err)
{
    *out = NULL;
    size_t k = g->nterminals;
    ag_pointmodel *pm = ag_pointmodel_create();
    int32_t *model_of = malloc((k + 1) * sizeof *model_of);
    ag_gterminal *view_terms = calloc(k + 1, sizeof *view_terms);
    ag_mesh *proxy = NULL;
    ag_status st = AG_OK;
    if (!pm || !model_of || !view_terms) {
        st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        goto done;
    }
    if (offset)
        memcpy(pm->offset, offset, sizeof pm->offset);
    terminal_order(g, model_of);
    if (k && (st = AG_ARRAY_RESERVE_EXACT(pm->terminals, pm->cap_terminals, k))) {
        st = ag_error_set(err, st, 0, "out of memory");
        goto done;
    }
    memset(pm->terminals, 0, k * sizeof *pm->terminals);
    pm->nterminals = k;
    double spacing_sum = 0;
    for (size_t i = 0; i < k; i++) {
        if (!points[i]) {
            st = ag_error_set(err, AG_ERR_INVALID, 0, "terminal '%s' has no points",
                              g->terminals[i].name);
            goto done;
        }
        ag_pointmodel_terminal *t = &pm->terminals[model_of[i]];
        t->points = points[i];
        points[i] = NULL;
        memcpy(t->size, g->terminals[i].size, sizeof t->size);
        if ((st = median_spacing(t->points, &t->spacing, err)) != AG_OK)
            goto done;
        t->members = t->merged = 1;
        t->points_before = t->points->n;
        t->mean_before = (double)t->points->n;
        spacing_sum += t->spacing;
    }
    pm->spacing = k ? spacing_sum / (double)k : 0;
    for (size_t i = 0; i < k && !st; i++) {
        if (!(pm->terminals[i].spacing > 0))
            pm->terminals[i].spacing = pm->spacing > 0 ? pm->spacing : 0.01;
    }
    /* a view of g whose terminals are tetrahedra grouped by their own names */
    ag_grammar view = *g;
    view.terminals = view_terms;
    for (size_t i = 0; i < k && !st; i++) {
        view_terms[i].name = g->terminals[i].name;
        view_terms[i].label = -1;
        if ((st = terminal_proxy(&view_terms[i], g->terminals[i].size)))
            st = ag_error_set(err, st, 0, "out of memory");
    }
    if (st)
        goto done;
    ag_grammar_derive_options dopt = {.max_triangles = 4 * (size_t)DERIVE_MAX_POINTS / 100};
    if ((st = ag_grammar_derive(&view, &dopt, &proxy, err)) != AG_OK)
        goto done;
    grammar_lookup gl = {g, model_of};
    if ((st = ag_pointmodel_read_proxy(pm, proxy, lookup_grammar, &gl, NULL, err)) != AG_OK)
        goto done;
    pm->tolerance = pm->spacing;
    if ((st = ag_pointmodel_build(pm, err)) != AG_OK)
        goto done;
    *out = pm;
    pm = NULL;
done:
    for (size_t i = 0; view_terms && i < k; i++) {
        free(view_terms[i].pos);
        free(view_terms[i].tri);
    }
    free(view_terms);
    free(model_of);
    ag_mesh_free(proxy);
    ag_pointmodel_free(pm);
    return st;
}

/* ---- derivation ----------------------------------------------------------------------------- */

/* The union of the terminals' properties, in first-seen order. */
static ag_status output_properties(const ag_pointmodel *pm, ag_cloud *out, ag_error *err)
{
    ag_status st = AG_OK;
    for (size_t t = 0; t < pm->nterminals && !st; t++) {
        const ag_cloud *c = pm->terminals[t].points;
        for (size_t p = 0; p < c->nprops && !st; p++)
            if (!ag_cloud_find(out, c->props[p].name) && strcmp(c->props[p].name, "label") &&
                strcmp(c->props[p].name, "segment"))
                st = ag_cloud_add_property(out, c->props[p].name, c->props[p].type, NULL, err);
    }
    if (!st)
        st = ag_cloud_add_property(out, "label", AG_SCALAR_INT32, NULL, err);
    if (!st)
        st = ag_cloud_add_property(out, "segment", AG_SCALAR_INT32, NULL, err);
    return st;
}

static int is_rigid(const double A[3][3])
{
    /* columns of unit length (a quarter turn has no scale) */
    for (int k = 0; k < 3; k++) {
        double l = A[0][k] * A[0][k] + A[1][k] * A[1][k] + A[2][k] * A[2][k];
        if (fabs(l - 1) > 1e-9)
            return 0;
    }
    return 1;
}

ag_status ag_pointmodel_derive(const ag_pointmodel *pm, size_t max_points, ag_cloud **out,
                               ag_pointmodel_derive_info *info, ag_error *err)
{
    *out = NULL;
    ag_pointmodel_derive_info local = {0};
    if (!info)
        info = &local;
    memset(info, 0, sizeof *info);
    if (!max_points)
        max_points = DERIVE_MAX_POINTS;
    ag_cloud *c = ag_cloud_create();
    size_t *first = malloc((pm->nplacements + 1) * sizeof *first);
    uint8_t *drop = NULL;
    uint32_t *ia = NULL, *ib = NULL;
    ag_status st = c && first ? AG_OK : AG_ERR_NOMEM;
    if (st) {
        st = ag_error_set(err, st, 0, "out of memory");
        goto done;
    }
    memcpy(c->offset, pm->offset, sizeof c->offset);
    memcpy(c->scale, pm->scale, sizeof c->scale);
    if ((st = output_properties(pm, c, err)) || (st = ag_cloud_add_normals(c, err)))
        goto done;
    ag_cloud_property *plabel = ag_cloud_find(c, "label"), *pseg = ag_cloud_find(c, "segment");
    size_t ilabel = (size_t)(plabel - c->props), iseg = (size_t)(pseg - c->props);
    /* per terminal property: the output property it goes to */
    for (size_t i = 0; i < pm->nplacements && !st; i++) {
        const ag_pointmodel_placement *p = &pm->placements[i];
        const ag_pointmodel_terminal *T = &pm->terminals[p->terminal];
        const ag_cloud *tc = T->points;
        first[i] = c->n;
        int rigid = is_rigid(p->A);
        const double (*A)[3] = p->A;
        const double C[3][3] = {
            {A[1][1] * A[2][2] - A[1][2] * A[2][1], A[1][2] * A[2][0] - A[1][0] * A[2][2],
             A[1][0] * A[2][1] - A[1][1] * A[2][0]},
            {A[0][2] * A[2][1] - A[0][1] * A[2][2], A[0][0] * A[2][2] - A[0][2] * A[2][0],
             A[0][1] * A[2][0] - A[0][0] * A[2][1]},
            {A[0][1] * A[1][2] - A[0][2] * A[1][1], A[0][2] * A[1][0] - A[0][0] * A[1][2],
             A[0][0] * A[1][1] - A[0][1] * A[1][0]}};
        double sign = A[0][0] * C[0][0] + A[0][1] * C[0][1] + A[0][2] * C[0][2] < 0 ? -1 : 1;
        if (!rigid)
            info->stretched++;
        uint64_t seed = 0x70686f746f6e73ull ^ ((uint64_t)i * 0x9E3779B97F4A7C15ull);
        size_t need = c->n + tc->n;
        if (!rigid) {
            /* the copies first, to size the output */
            need = c->n;
            for (size_t j = 0; j < tc->n; j++) {
                float zn[3] = {0, 0, 1};
                const float *n = tc->normals ? tc->normals + 3 * j : zn;
                need += ag_resample_copies(ag_resample_area_factor(p->A, n), seed, j);
            }
        }
        if (need > max_points) {
            st = ag_error_set(err, AG_ERR_TOO_LARGE, 0, "the derivation exceeds %zu points",
                              max_points);
            break;
        }
        size_t at = c->n;
        if ((st = ag_cloud_resize(c, need, err)))
            break;
        /* output index of each terminal property (by name), looked up once per placement */
        size_t pmap[AG_CLOUD_MAX_PROPERTIES];
        for (size_t q = 0; q < tc->nprops; q++) {
            const ag_cloud_property *op = ag_cloud_find(c, tc->props[q].name);
            pmap[q] = op && op != plabel && op != pseg ? (size_t)(op - c->props) : SIZE_MAX;
        }
        for (size_t j = 0; j < tc->n; j++) {
            float zn[3] = {0, 0, 1};
            const float *n = tc->normals ? tc->normals + 3 * j : zn;
            unsigned copies = rigid ? 1 : ag_resample_copies(ag_resample_area_factor(p->A, n), seed, j);
            for (unsigned k = 0; k < copies; k++) {
                double q[3];
                memcpy(q, tc->xyz + 3 * j, sizeof q);
                if (k > 0) {
                    double d[3];
                    ag_resample_jitter(n, 0.5 * T->spacing, seed, j, k, d);
                    for (int a = 0; a < 3; a++)
                        q[a] += d[a];
                }
                double *x = c->xyz + 3 * at;
                for (int r = 0; r < 3; r++)
                    x[r] = p->A[r][0] * q[0] + p->A[r][1] * q[1] + p->A[r][2] * q[2] + p->b[r];
                /* normals: the inverse transpose (the cofactors over the determinant) */
                double nn[3];
                for (int r = 0; r < 3; r++)
                    nn[r] = (C[r][0] * n[0] + C[r][1] * n[1] + C[r][2] * n[2]) * sign;
                double l = sqrt(nn[0] * nn[0] + nn[1] * nn[1] + nn[2] * nn[2]);
                for (int r = 0; r < 3; r++)
                    c->normals[3 * at + r] = (float)(l > 0 ? nn[r] / l : 0);
                for (size_t q2 = 0; q2 < tc->nprops; q2++)
                    if (pmap[q2] != SIZE_MAX)
                        ag_cloud_set(&c->props[pmap[q2]], at, ag_cloud_get(&tc->props[q2], j));
                ag_cloud_set(&c->props[ilabel], at, p->terminal);
                ag_cloud_set(&c->props[iseg], at, (double)i);
                at++;
            }
        }
        if (at != need) {
            st = ag_error_set(err, AG_ERR_INTERNAL, 0, "placement %zu emitted %zu of %zu points",
                              i, at - first[i], need - first[i]);
            break;
        }
    }
    if (st)
        goto done;
    first[pm->nplacements] = c->n;
    /* seams: adjacent placements that overlap, the later one's duplicates dropped */
    if (pm->em && c->n) {
        const ag_splittree *t = pm->em->proc->tree;
        drop = calloc(c->n, 1);
        uint8_t *d2 = NULL;
        size_t cap_a = 0, cap_b = 0, cap_d = 0;
        if (!drop) {
            st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
            goto done;
        }
        for (size_t e = 0; e < t->nadj && !st; e++) {
            int32_t na = t->nodes[t->adj[2 * e]].component, nb = t->nodes[t->adj[2 * e + 1]].component;
            if (na < 0 || nb < 0 || na == nb)
                continue;
            int32_t pa = na < nb ? na : nb, pb = na < nb ? nb : na;
            const ag_pointmodel_placement *A = &pm->placements[pa], *B = &pm->placements[pb];
            double sp = fmin(pm->terminals[A->terminal].spacing, pm->terminals[B->terminal].spacing);
            ag_box reg = ag_box_intersect(&A->box, &B->box);
            if (ag_box_is_empty(&reg))
                continue;
            for (int a = 0; a < 3; a++) {
                reg.min[a] -= 2 * sp;
                reg.max[a] += 2 * sp;
            }
            size_t n_a = 0, n_b = 0;
            for (size_t j = first[pa]; j < first[pa + 1]; j++)
                if (!drop[j] && ag_box_contains_point(&reg, c->xyz + 3 * j, 0)) {
                    if (AG_ARRAY_RESERVE(ia, cap_a, n_a + 1)) {
                        st = AG_ERR_NOMEM;
                        break;
                    }
                    ia[n_a++] = (uint32_t)j;
                }
            for (size_t j = first[pb]; j < first[pb + 1] && !st; j++)
                if (!drop[j] && ag_box_contains_point(&reg, c->xyz + 3 * j, 0)) {
                    if (AG_ARRAY_RESERVE(ib, cap_b, n_b + 1)) {
                        st = AG_ERR_NOMEM;
                        break;
                    }
                    ib[n_b++] = (uint32_t)j;
                }
            if (st) {
                st = ag_error_set(err, st, 0, "out of memory");
                break;
            }
            if (!n_a || !n_b)
                continue;
            if (AG_ARRAY_RESERVE(d2, cap_d, n_b)) {
                st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
                break;
            }
            if ((st = ag_resample_dedupe(c->xyz, ia, n_a, ib, n_b, sp / 3, d2, err)))
                break;
            for (size_t j = 0; j < n_b; j++)
                drop[ib[j]] |= d2[j];
        }
        free(d2);
        if (st)
            goto done;
        size_t w = 0;
        for (size_t j = 0; j < c->n; j++) {
            if (drop[j]) {
                info->seam_dropped++;
                continue;
            }
            if (w != j) {
                memcpy(c->xyz + 3 * w, c->xyz + 3 * j, 3 * sizeof *c->xyz);
                memcpy(c->normals + 3 * w, c->normals + 3 * j, 3 * sizeof *c->normals);
                for (size_t q = 0; q < c->nprops; q++) {
                    size_t s = ag_scalar_size(c->props[q].type);
                    memcpy((char *)c->props[q].values + w * s, (char *)c->props[q].values + j * s, s);
                }
            }
            w++;
        }
        if ((st = ag_cloud_resize(c, w, err)))
            goto done;
    }
    info->points = c->n;
    *out = c;
    c = NULL;
done:
    ag_cloud_free(c);
    free(first);
    free(drop);
    free(ia);
    free(ib);
    return st;
}

ag_status ag_pointmodel_compare(const ag_cloud *input, const ag_cloud *derived, double tol,
                                 ag_pointmodel_fidelity *f, ag_error *err)
{
    memset(f, 0, sizeof *f);
    f->input = input->n;
    f->derived = derived->n;
    f->tolerance = tol;
    if (!input->n || !derived->n)
        return AG_OK;
    /* both in the input's frame */
    double d[3];
    for (int a = 0; a < 3; a++)
        d[a] = derived->offset[a] - input->offset[a];
    double *dx = malloc(3 * derived->n * sizeof *dx);
    if (!dx)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    for (size_t i = 0; i < derived->n; i++)
        for (int a = 0; a < 3; a++)
            dx[3 * i + a] = derived->xyz[3 * i + a] + d[a];
    ag_kdtree *td = NULL, *ti = NULL;
    ag_status st = ag_kdtree_build(dx, NULL, derived->n, &td, err);
    if (!st)
        st = ag_kdtree_build(input->xyz, NULL, input->n, &ti, err);
    if (!st) {
        size_t hit = 0;
        for (size_t i = 0; i < input->n; i++) {
            uint32_t k;
            double d2;
            hit += ag_kdtree_knn(td, input->xyz + 3 * i, 1, &k, &d2) && d2 <= tol * tol;
        }
        f->coverage = (double)hit / (double)input->n;
        hit = 0;
        for (size_t i = 0; i < derived->n; i++) {
            uint32_t k;
            double d2;
            hit += ag_kdtree_knn(ti, dx + 3 * i, 1, &k, &d2) && d2 <= tol * tol;
        }
        f->precision = (double)hit / (double)derived->n;
    }
    ag_kdtree_free(td);
    ag_kdtree_free(ti);
    free(dx);
    return st;
}
