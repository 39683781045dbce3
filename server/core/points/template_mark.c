#include "template_mark.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define STEP_SHARE 0.1       /* the slide step: a tenth of the template on each axis */
#define COUNT_SHARE 0.1      /* the label rule: point counts within 10 % */
#define EXTENT_SHARE 0.05    /* and extents within 5 % */
#define OVERLAP_SHARE 0.1    /* copies may overlap by a tenth of the template per axis */
#define MAX_POSITIONS 400000 /* the budget of window positions: coarser steps beyond it */
#define PLACE_WEIGHT 4.0     /* how much the points' centre counts in placing a copy */
#define REFINE 2             /* a copy is placed to a quarter step: 2 sub-steps either side */

void ag_template_mark_report_clear(ag_template_mark_report *rep)
{
    if (rep) {
        free(rep->copy);
        memset(rep, 0, sizeof *rep);
    }
}

typedef struct {
    double off[3];
    size_t count;
    double score;  /* how close it is in everything: copies are taken best first */
    double place;  /* how close its points' centre and spread are: copies are placed by it */
    size_t order;  /* position index: ties are broken by it */
} candidate;

static int by_score(const void *a, const void *b)
{
    const candidate *x = a, *y = b;
    if (x->score != y->score)
        return x->score < y->score ? -1 : 1;
    return (x->order > y->order) - (x->order < y->order);
}

static int cmp_desc(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x < y) - (x > y);
}

/* The points of the segment (their frame coordinates u) on a grid over the first two axes. */
typedef struct {
    const double *u;
    size_t m;
    double lo[2], cell[2];
    size_t dim[2];
    uint32_t *start, *items; /* CSR: points of each cell */
} grid;

static ag_status grid_build(grid *g, const double *u, size_t m, const double lo[3],
                            const double hi[3], const double want[2], ag_error *err)
{
    memset(g, 0, sizeof *g);
    g->u = u;
    g->m = m;
    for (int k = 0; k < 2; k++) {
        g->lo[k] = lo[k];
        g->cell[k] = want[k] > 0 ? want[k] : 1;
        double cells = floor((hi[k] - lo[k]) / g->cell[k]) + 1;
        if (cells > 1000) { /* each axis at most 1000 cells: MAX_CELLS in all */
            g->cell[k] = (hi[k] - lo[k]) / 999.0;
            cells = 1000;
        }
        g->dim[k] = (size_t)cells;
    }
    size_t cells = g->dim[0] * g->dim[1];
    g->start = calloc(cells + 1, sizeof *g->start);
    g->items = malloc((m ? m : 1) * sizeof *g->items);
    uint32_t *fill = malloc((cells + 1) * sizeof *fill);
    if (!g->start || !g->items || !fill) {
        free(fill);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    size_t *at = malloc((m ? m : 1) * sizeof *at);
    if (!at) {
        free(fill);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    for (size_t j = 0; j < m; j++) {
        size_t c[2];
        for (int k = 0; k < 2; k++) {
            double q = floor((u[3 * j + k] - g->lo[k]) / g->cell[k]);
            c[k] = q < 0 ? 0 : q >= (double)g->dim[k] ? g->dim[k] - 1 : (size_t)q;
        }
        at[j] = c[1] * g->dim[0] + c[0];
        g->start[at[j] + 1]++;
    }
    for (size_t c = 0; c < cells; c++)
        g->start[c + 1] += g->start[c];
    memcpy(fill, g->start, (cells + 1) * sizeof *fill);
    for (size_t j = 0; j < m; j++)
        g->items[fill[at[j]]++] = (uint32_t)j;
    free(at);
    free(fill);
    return AG_OK;
}

static void grid_free(grid *g)
{
    free(g->start);
    free(g->items);
}

static size_t cell_of(const grid *g, int k, double v)
{
    double q = floor((v - g->lo[k]) / g->cell[k]);
    return q < 0 ? 0 : q >= (double)g->dim[k] ? g->dim[k] - 1 : (size_t)q;
}

static int inside(const double *p, const double lo[3], const double hi[3])
{
    return p[0] >= lo[0] && p[0] <= hi[0] && p[1] >= lo[1] && p[1] <= hi[1] && p[2] >= lo[2] &&
           p[2] <= hi[2];
}

/* Runs body for every point j of the segment in the frame window [lo, hi]. */
#define EACH_IN_WINDOW(g, lo, hi, j, body)                                                      \
    do {                                                                                       \
        size_t c0a = cell_of(g, 0, (lo)[0]), c0b = cell_of(g, 0, (hi)[0]);                     \
        size_t c1a = cell_of(g, 1, (lo)[1]), c1b = cell_of(g, 1, (hi)[1]);                     \
        for (size_t c1 = c1a; c1 <= c1b; c1++)                                                 \
            for (size_t c0 = c0a; c0 <= c0b; c0++) {                                           \
                size_t cc = c1 * (g)->dim[0] + c0;                                             \
                for (uint32_t q = (g)->start[cc]; q < (g)->start[cc + 1]; q++) {               \
                    size_t j = (g)->items[q];                                                  \
                    if (inside((g)->u + 3 * j, lo, hi)) {                                      \
                        body;                                                                  \
                    }                                                                          \
                }                                                                              \
            }                                                                                  \
    } while (0)

/* Whether two windows of the template's size overlap by more than OVERLAP_SHARE of it on
 * every axis (an axis where the template is thinner than the slack always overlaps). */
static int overlaps(const double a[3], const double b[3], const double size[3], double slack)
{
    for (int k = 0; k < 3; k++) {
        if (size[k] <= slack)
            continue;
        double o = size[k] - fabs(a[k] - b[k]);
        if (o <= OVERLAP_SHARE * size[k])
            return 0;
    }
    return 1;
}

/* The template as the windows are compared with it. */
typedef struct {
    const grid *g;
    const double *u;
    const double *tlo, *thi, *tsize, *tdims, *tmid, *tspread;
    size_t tc;
    double slack;
} tmpl;

/* Whether the window at offset off is a copy of the template: c->count, c->score and
 * c->place (lower is closer) filled. */
static int evaluate(const tmpl *T, const double off[3], candidate *c)
{
    const double *u = T->u, slack = T->slack;
    double lo[3], hi[3], elo[3], ehi[3];
    for (int k = 0; k < 3; k++) {
        lo[k] = T->tlo[k] + off[k];
        hi[k] = T->thi[k] + off[k];
        elo[k] = INFINITY;
        ehi[k] = -INFINITY;
    }
    size_t count = 0;
    EACH_IN_WINDOW(T->g, lo, hi, j, {
        count++;
        for (int k = 0; k < 3; k++) {
            elo[k] = fmin(elo[k], u[3 * j + k]);
            ehi[k] = fmax(ehi[k], u[3 * j + k]);
        }
    });
    size_t tc = T->tc;
    double big = (double)(count > tc ? count : tc);
    if (!count || fabs((double)count - (double)tc) > COUNT_SHARE * big)
        return 0;
    double dims[3] = {ehi[0] - elo[0], ehi[1] - elo[1], ehi[2] - elo[2]};
    qsort(dims, 3, sizeof dims[0], cmp_desc);
    double score = fabs((double)count - (double)tc) / big;
    for (int k = 0; k < 3; k++) {
        double e = fmax(dims[k], T->tdims[k]);
        if (fabs(dims[k] - T->tdims[k]) > EXTENT_SHARE * e + slack)
            return 0;
        score += fabs(dims[k] - T->tdims[k]) / fmax(e, slack > 0 ? slack : 1e-9);
    }
    double mid[3] = {0, 0, 0}, spread[3] = {0, 0, 0};
    EACH_IN_WINDOW(T->g, lo, hi, j, {
        for (int k = 0; k < 3; k++) {
            double d = u[3 * j + k] - lo[k];
            mid[k] += d / (double)count;
            spread[k] += d * d / (double)count;
        }
    });
    /* and its points placed in it as the template's are in its own: their centre and their
     * spread about it */
    double place = 0;
    for (int k = 0; k < 3; k++) {
        if (T->tsize[k] <= slack)
            continue;
        spread[k] = sqrt(fmax(0, spread[k] - mid[k] * mid[k]));
        double dm = fabs(mid[k] - T->tmid[k]), ds = fabs(spread[k] - T->tspread[k]);
        double tol = EXTENT_SHARE * T->tsize[k] + slack;
        if (dm > tol || ds > tol)
            return 0;
        place += (dm + ds) / T->tsize[k];
    }
    memcpy(c->off, off, sizeof c->off);
    c->count = count;
    c->score = score + PLACE_WEIGHT * place;
    c->place = place;
    return 1;
}

/* The best place for a copy found at c->off, within half a step of it on each axis: where
 * its points lie most as the template's do (the count, noisy by its square root, would pull
 * the place about). */
static void refine_place(const tmpl *T, const double step[3], const size_t steps[3],
                         candidate *c)
{
    candidate best = *c;
    for (int i = -REFINE; i <= REFINE; i++)
        for (int j = -REFINE; j <= REFINE; j++) {
            double off[3] = {c->off[0], c->off[1], c->off[2]};
            if (steps[0] > 1)
                off[0] += step[0] * i / (2.0 * REFINE);
            if (steps[1] > 1)
                off[1] += step[1] * j / (2.0 * REFINE);
            candidate t = *c;
            if ((i || j) && evaluate(T, off, &t) && t.place < best.place)
                best = t;
        }
    *c = best;
}

ag_status ag_template_mark(const ag_cloud *c, ag_segment_cloud_result **rp, int32_t segment,
                           const double min[3], const double max[3],
                           ag_template_mark_report *rep, ag_error *err)
{
    memset(rep, 0, sizeof *rep);
    ag_segment_cloud_result *r = *rp;
    if (segment < 0 || (size_t)segment >= r->nsegments)
    {
        if (!r->nsegments)
            return ag_error_set(err, AG_ERR_INVALID, 0, "segment %d: the cloud has no segments",
                                segment);
        return ag_error_set(err, AG_ERR_INVALID, 0,
                            "segment %d: the segmentation has segments 0 to %zu", segment,
                            r->nsegments - 1);
    }
    const ag_segment_cloud_item *it = &r->segments[segment];
    const uint32_t *mem = r->members + r->member_start[segment];
    size_t m = r->member_start[segment + 1] - r->member_start[segment];
    double slack = 2 * r->spacing;
    double *u = malloc((m ? m : 1) * 3 * sizeof *u);
    int32_t *group = malloc((m ? m : 1) * sizeof *group);
    candidate *cand = NULL;
    double (*taken)[3] = NULL;
    grid g = {0};
    ag_status st = u && group ? AG_OK : ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    double tlo[3] = {INFINITY, INFINITY, INFINITY}, thi[3] = {-INFINITY, -INFINITY, -INFINITY};
    double slo[3] = {INFINITY, INFINITY, INFINITY}, shi[3] = {-INFINITY, -INFINITY, -INFINITY};
    size_t tc = 0;
    for (size_t j = 0; st == AG_OK && j < m; j++) {
        const double *p = c->xyz + 3 * (size_t)mem[j];
        double d[3] = {p[0] - it->centroid[0], p[1] - it->centroid[1], p[2] - it->centroid[2]};
        int in = inside(p, min, max);
        tc += in;
        group[j] = in ? 0 : -1;
        for (int k = 0; k < 3; k++) {
            double v = d[0] * it->axes[k][0] + d[1] * it->axes[k][1] + d[2] * it->axes[k][2];
            u[3 * j + k] = v;
            slo[k] = fmin(slo[k], v);
            shi[k] = fmax(shi[k], v);
            if (in) {
                tlo[k] = fmin(tlo[k], v);
                thi[k] = fmax(thi[k], v);
            }
        }
    }
    if (st == AG_OK && tc < AG_TEMPLATE_MIN_POINTS)
        st = ag_error_set(err, AG_ERR_INVALID, (long)tc,
                          "the box holds %zu points of segment %d; a template needs at least %d",
                          tc, segment, AG_TEMPLATE_MIN_POINTS);
    double tsize[3], step[3], tdims[3];
    size_t steps[3] = {1, 1, 1};
    double first[3];
    for (int k = 0; st == AG_OK && k < 3; k++) {
        tsize[k] = thi[k] - tlo[k];
        tdims[k] = tsize[k];
        step[k] = fmax(STEP_SHARE * tsize[k], r->spacing > 0 ? r->spacing : 1e-6);
        double room = (shi[k] - thi[k]) - (slo[k] - tlo[k]); /* the offsets' range */
        first[k] = slo[k] - tlo[k];
        if (tsize[k] > slack && room >= step[k])
            steps[k] = (size_t)floor(room / step[k]) + 1;
        else
            first[k] = 0; /* no room on this axis: the template's own place */
    }
    /* the budget of positions: coarser steps when a small template slides on a big segment */
    while (st == AG_OK && (double)steps[0] * steps[1] * steps[2] > MAX_POSITIONS) {
        for (int k = 0; k < 3; k++)
            if (steps[k] > 1) {
                step[k] *= 2;
                steps[k] = (steps[k] + 1) / 2;
            }
    }
    qsort(tdims, 3, sizeof tdims[0], cmp_desc);
    size_t npos = st == AG_OK ? steps[0] * steps[1] * steps[2] : 0, ncand = 0;
    if (st == AG_OK) {
        double want[2] = {fmax(tsize[0] / 2, r->spacing), fmax(tsize[1] / 2, r->spacing)};
        st = grid_build(&g, u, m, slo, shi, want, err);
    }
    if (st == AG_OK && !(cand = malloc((npos ? npos : 1) * sizeof *cand)))
        st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    /* Copies are accepted by the label rule alone, but placed by where their points lie: a
     * window shifted while the template's features stay inside it holds as many points, and
     * the centre of its points relative to the window tells the shift */
    double tmid[3] = {0, 0, 0}, tspread[3] = {0, 0, 0};
    for (size_t j = 0; st == AG_OK && j < m; j++)
        if (group[j] == 0)
            for (int k = 0; k < 3; k++) {
                double d = u[3 * j + k] - tlo[k];
                tmid[k] += d / (double)tc;
                tspread[k] += d * d / (double)tc;
            }
    for (int k = 0; k < 3; k++)
        tspread[k] = sqrt(fmax(0, tspread[k] - tmid[k] * tmid[k]));
    tmpl T = {&g, u, tlo, thi, tsize, tdims, tmid, tspread, tc, slack};
    for (size_t pos = 0; st == AG_OK && pos < npos; pos++) {
        size_t ix[3] = {pos % steps[0], (pos / steps[0]) % steps[1], pos / (steps[0] * steps[1])};
        double off[3];
        for (int k = 0; k < 3; k++)
            off[k] = steps[k] > 1 ? first[k] + (double)ix[k] * step[k] : 0;
        cand[ncand].order = pos;
        if (evaluate(&T, off, &cand[ncand]))
            ncand++;
    }
    rep->positions = npos;
    rep->template_points = tc;
    if (st == AG_OK) {
        qsort(cand, ncand, sizeof *cand, by_score);
        taken = malloc((ncand + 1) * sizeof *taken);
        if (!taken)
            st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    size_t ntaken = 0;
    if (st == AG_OK) {
        taken[ntaken][0] = taken[ntaken][1] = taken[ntaken][2] = 0; /* the template itself */
        ntaken++;
    }
    for (size_t i = 0; st == AG_OK && i < ncand; i++) {
        int free_place = 1;
        for (size_t t = 0; t < ntaken && free_place; t++)
            free_place = !overlaps(cand[i].off, taken[t], tsize, slack);
        if (!free_place)
            continue;
        refine_place(&T, step, steps, &cand[i]);
        for (size_t t = 0; t < ntaken && free_place; t++)
            free_place = !overlaps(cand[i].off, taken[t], tsize, slack);
        if (!free_place)
            continue;
        memcpy(taken[ntaken], cand[i].off, sizeof taken[ntaken]);
        double lo[3], hi[3];
        for (int k = 0; k < 3; k++) {
            lo[k] = tlo[k] + cand[i].off[k];
            hi[k] = thi[k] + cand[i].off[k];
        }
        int32_t gid = (int32_t)ntaken;
        EACH_IN_WINDOW(&g, lo, hi, j, {
            if (group[j] < 0)
                group[j] = gid;
        });
        ntaken++;
    }
    /* the new segmentation: the template and its copies become segments of the segment's
     * kind (planes keep the first ids), empty segments are dropped */
    ag_segment_cloud_result *out = NULL;
    int32_t *seg = NULL, *piece = NULL, *map = NULL, *pmap = NULL;
    size_t *count = NULL;
    size_t k = ntaken, old = r->nsegments, total = old + k, n = c->n;
    int plane = (size_t)segment < r->nplanes;
    size_t base = plane ? r->nplanes : old; /* where the new ids go */
    if (st == AG_OK) {
        seg = malloc((n ? n : 1) * sizeof *seg);
        piece = malloc((n ? n : 1) * sizeof *piece);
        map = malloc((total + 1) * sizeof *map);
        count = calloc(total + 1, sizeof *count);
        pmap = malloc((r->npieces + k + 1) * sizeof *pmap);
        if (!seg || !piece || !map || !count || !pmap)
            st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    if (st == AG_OK) {
        for (size_t i = 0; i < n; i++) {
            int32_t s = r->segment[i];
            seg[i] = s < 0 ? -1 : (size_t)s >= base ? s + (int32_t)k : s;
            piece[i] = r->piece[i];
        }
        for (size_t j = 0; j < m; j++)
            if (group[j] >= 0) {
                seg[mem[j]] = (int32_t)(base + (size_t)group[j]);
                piece[mem[j]] = (int32_t)(r->npieces + (size_t)group[j]);
            }
        for (size_t i = 0; i < n; i++)
            if (seg[i] >= 0)
                count[seg[i]]++;
        int32_t next = 0;
        size_t nplanes = 0, planes_end = r->nplanes + (plane ? k : 0);
        for (size_t s = 0; s < total; s++) {
            map[s] = count[s] ? next++ : -1;
            if (s < planes_end && count[s])
                nplanes++;
        }
        int32_t pn = 0;
        for (size_t p = 0; p < r->npieces + k; p++)
            pmap[p] = -1;
        for (size_t i = 0; i < n; i++) {
            if (seg[i] < 0)
                continue;
            seg[i] = map[seg[i]];
            if (pmap[piece[i]] < 0)
                pmap[piece[i]] = pn++;
            piece[i] = pmap[piece[i]];
        }
        ag_segment_cloud_ids ids = {.segment = seg,
                                    .piece = piece,
                                    .nsegments = (size_t)next,
                                    .nplanes = nplanes,
                                    .npieces = (size_t)pn,
                                    .spacing = r->spacing};
        st = ag_segment_cloud_restore(c, &ids, &out, err);
    }
    if (st == AG_OK) {
        /* one new label for the template and its copies, then labels renumbered densely */
        int32_t fresh = (int32_t)out->nlabels;
        for (size_t t = 0; t < k; t++) {
            int32_t s = map[base + t];
            if (s >= 0)
                out->segments[s].label = fresh;
        }
        int32_t *dense = malloc((out->nlabels + 2) * sizeof *dense);
        if (!dense) {
            st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        } else {
            for (size_t l = 0; l <= out->nlabels; l++)
                dense[l] = -1;
            int32_t nl = 0;
            for (size_t s = 0; s < out->nsegments; s++) {
                int32_t l = out->segments[s].label;
                if (dense[l] < 0)
                    dense[l] = nl++;
                out->segments[s].label = dense[l];
            }
            out->nlabels = (size_t)nl;
            for (size_t i = 0; i < n; i++)
                out->label[i] = out->segment[i] >= 0 ? out->segments[out->segment[i]].label : -1;
            rep->label = dense[fresh];
            rep->template_segment = map[base];
            free(dense);
        }
    }
    if (st == AG_OK && k > 1 && !(rep->copy = calloc(k - 1, sizeof *rep->copy)))
        st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    size_t copies = 0;
    for (size_t t = 1; st == AG_OK && t < k; t++) {
        int32_t s = map[base + t];
        if (s < 0) /* every point of it went to a copy before */
            continue;
        ag_template_copy *cp = &rep->copy[copies++];
        for (int a = 0; a < 3; a++) {
            cp->min[a] = INFINITY;
            cp->max[a] = -INFINITY;
        }
        for (uint32_t q = out->member_start[s]; q < out->member_start[s + 1]; q++) {
            const double *p = c->xyz + 3 * (size_t)out->members[q];
            for (int a = 0; a < 3; a++) {
                cp->min[a] = fmin(cp->min[a], p[a]);
                cp->max[a] = fmax(cp->max[a], p[a]);
            }
        }
        cp->count = out->member_start[s + 1] - out->member_start[s];
    }
    if (st == AG_OK) {
        rep->copies = copies;
        ag_segment_cloud_free(r);
        *rp = out;
        out = NULL;
    } else {
        ag_template_mark_report_clear(rep);
    }
    ag_segment_cloud_free(out);
    grid_free(&g);
    free(u);
    free(group);
    free(cand);
    free(taken);
    free(seg);
    free(piece);
    free(map);
    free(count);
    free(pmap);
    return st;
}
