/* The part's components grafted into the target model's tree (graft.h). */
#include "graft.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../base/clock.h"
#include "../base/tolerance.h"
#include "../edit/rebuild.h"

static ag_status nomem(ag_error *err)
{
    return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory while grafting the part");
}

/* ---- a small chained hash of boxes by a grid cell ------------------------------------------ */

typedef struct {
    size_t cap;      /* a power of two */
    int32_t *head;   /* per bucket */
    int32_t *next;   /* per entry */
} cellhash;

static uint64_t cell_key(int64_t x, int64_t y, int64_t z)
{
    uint64_t h = (uint64_t)x * 0x9E3779B97F4A7C15ULL;
    h ^= (uint64_t)y * 0xBF58476D1CE4E5B9ULL + (h >> 29);
    h ^= (uint64_t)z * 0x94D049BB133111EBULL + (h >> 31);
    return h ^ (h >> 32);
}

static int cellhash_init(cellhash *h, size_t entries)
{
    h->cap = 64;
    while (h->cap < 2 * entries)
        h->cap *= 2;
    h->head = malloc(h->cap * sizeof *h->head);
    h->next = malloc((entries + 1) * sizeof *h->next);
    if (!h->head || !h->next)
        return -1;
    for (size_t i = 0; i < h->cap; i++)
        h->head[i] = -1;
    return 0;
}

static void cellhash_add(cellhash *h, uint64_t key, int32_t entry)
{
    size_t b = key & (h->cap - 1);
    h->next[entry] = h->head[b];
    h->head[b] = entry;
}

static void cellhash_free(cellhash *h)
{
    free(h->head);
    free(h->next);
}

static int64_t cell_of(double v, double h)
{
    return (int64_t)floor(v / h);
}

static int same_box(const ag_box *a, const ag_box *b, double q)
{
    for (int k = 0; k < 3; k++)
        if (fabs(a->min[k] - b->min[k]) > q || fabs(a->max[k] - b->max[k]) > q)
            return 0;
    return 1;
}

/* ---- the derivation's components ----------------------------------------------------------- */

typedef struct {
    size_t nc;
    uint32_t *tri_start, *tris; /* triangles per component */
    ag_box *box;
    double *sig; /* per component: its surface area and its area centroid (4 values) */
} dcomps;

static void dcomps_free(dcomps *d)
{
    free(d->tri_start);
    free(d->tris);
    free(d->box);
    free(d->sig);
}

/* Area and area centroid of the triangles tris[0..n) of m: what a component covers, whatever
 * its triangulation (sig: 4 values). */
static void signature(const ag_mesh *m, const uint32_t *tris, size_t n, double sig[4])
{
    double a = 0, c[3] = {0, 0, 0};
    for (size_t k = 0; k < n; k++) {
        const double *p = &m->pos[3 * m->tri[3 * tris[k]]], *q = &m->pos[3 * m->tri[3 * tris[k] + 1]],
                     *r = &m->pos[3 * m->tri[3 * tris[k] + 2]];
        double u[3] = {q[0] - p[0], q[1] - p[1], q[2] - p[2]}, v[3] = {r[0] - p[0], r[1] - p[1], r[2] - p[2]};
        double x = u[1] * v[2] - u[2] * v[1], y = u[2] * v[0] - u[0] * v[2], z = u[0] * v[1] - u[1] * v[0];
        double w = 0.5 * sqrt(x * x + y * y + z * z);
        a += w;
        /* about the first corner: the centroid stays exact at UTM-sized coordinates */
        for (int j = 0; j < 3; j++)
            c[j] += w * (u[j] + v[j]) / 3;
    }
    const double *o = n ? &m->pos[3 * m->tri[3 * tris[0]]] : c;
    sig[0] = a;
    for (int j = 0; j < 3; j++)
        sig[1 + j] = n ? o[j] + (a > 0 ? c[j] / a : 0) : 0;
}

static int dcomps_make(const ag_mesh *m, dcomps *d)
{
    size_t nc = m->ncomponents;
    d->nc = nc;
    d->tri_start = calloc(nc + 2, sizeof *d->tri_start);
    d->tris = malloc((m->ntris + 1) * sizeof *d->tris);
    d->box = malloc((nc + 1) * sizeof *d->box);
    d->sig = malloc((4 * nc + 1) * sizeof *d->sig);
    uint32_t *fill = malloc((nc + 1) * sizeof *fill);
    if (!d->tri_start || !d->tris || !d->box || !d->sig || !fill) {
        free(fill);
        return -1;
    }
    for (size_t i = 0; i < m->ntris; i++)
        d->tri_start[m->tri_component[i] + 1]++;
    for (size_t c = 0; c < nc; c++)
        d->tri_start[c + 1] += d->tri_start[c];
    memcpy(fill, d->tri_start, nc * sizeof *fill);
    for (size_t i = 0; i < m->ntris; i++)
        d->tris[fill[m->tri_component[i]]++] = (uint32_t)i;
    free(fill);
    for (size_t c = 0; c < nc; c++) {
        d->box[c] = ag_box_empty();
        for (uint32_t k = d->tri_start[c]; k < d->tri_start[c + 1]; k++)
            for (int j = 0; j < 3; j++)
                ag_box_extend_point(&d->box[c], &m->pos[3 * m->tri[3 * d->tris[k] + j]]);
        signature(m, d->tris + d->tri_start[c], d->tri_start[c + 1] - d->tri_start[c],
                  d->sig + 4 * c);
    }
    return 0;
}

static uint32_t dcomp_ntris(const dcomps *d, size_t c)
{
    return d->tri_start[c + 1] - d->tri_start[c];
}

/* ---- exact shapes of the new components ---------------------------------------------------- */

/* A component's geometry relative to its box: vertices in first use, triangles on them. */
typedef struct {
    size_t nv, nt;
    double ext[3]; /* the box's extents */
    double *pos;   /* 3 * nv, in [0, 1] per axis (0 on flat axes) */
    uint32_t *tri; /* 3 * nt local indices */
} shape;

static void shape_free(shape *s)
{
    free(s->pos);
    free(s->tri);
    memset(s, 0, sizeof *s);
}

/* The shape of triangles tris[0..nt) of m relative to box b. stamp/local: per mesh vertex
 * scratch (stamp of the last shape that met it). */
static int shape_of_tris(const ag_mesh *m, const uint32_t *tris, uint32_t nt, const ag_box *b,
                         uint32_t *stamp, uint32_t *local, uint32_t mark, shape *s)
{
    s->nt = nt;
    s->nv = 0;
    s->pos = malloc((3 * (size_t)nt + 1) * 3 * sizeof *s->pos);
    s->tri = malloc((3 * (size_t)nt + 1) * sizeof *s->tri);
    if (!s->pos || !s->tri)
        return -1;
    double *ext = s->ext;
    ag_box_extents(b, ext);
    for (uint32_t k = 0; k < nt; k++) {
        uint32_t tr = tris[k];
        for (int j = 0; j < 3; j++) {
            uint32_t v = m->tri[3 * tr + j];
            if (stamp[v] != mark) {
                stamp[v] = mark;
                local[v] = (uint32_t)s->nv;
                for (int a = 0; a < 3; a++)
                    s->pos[3 * s->nv + a] =
                        ext[a] > 0 ? (m->pos[3 * v + a] - b->min[a]) / ext[a] : 0;
                s->nv++;
            }
            s->tri[3 * k + j] = local[v];
        }
    }
    return 0;
}

static int shape_of(const ag_mesh *m, const dcomps *d, size_t c, uint32_t *stamp, uint32_t *local,
                    uint32_t mark, shape *s)
{
    return shape_of_tris(m, d->tris + d->tri_start[c], dcomp_ntris(d, c), &d->box[c], stamp,
                         local, mark, s);
}

/* Is b the shape a turned by r quarter turns counter-clockwise about z (within its box:
 * (x, y) -> (1 - y, x) per turn)? */
static int same_shape(const shape *a, const shape *b, int r)
{
    if (a->nv != b->nv || a->nt != b->nt ||
        memcmp(a->tri, b->tri, 3 * a->nt * sizeof *a->tri) != 0)
        return 0;
    for (size_t i = 0; i < a->nv; i++) {
        double x = a->pos[3 * i], y = a->pos[3 * i + 1];
        for (int k = 0; k < r; k++) {
            double t = x;
            x = 1 - y;
            y = t;
        }
        if (fabs(x - b->pos[3 * i]) > 1e-9 || fabs(y - b->pos[3 * i + 1]) > 1e-9 ||
            fabs(a->pos[3 * i + 2] - b->pos[3 * i + 2]) > 1e-9)
            return 0;
    }
    return 1;
}

/* ---- the tree ------------------------------------------------------------------------------ */

/* Marks the subtree of n (with the split chain above it, when n ends one) dead, its links
 * left for unlink_dead; counts the visible nodes removed. stack: room for every node. */
static void remove_subtree(ag_splittree *t, int32_t n, int32_t *stack, size_t *visible)
{
    int32_t top = n;
    while (t->nodes[top].parent >= 0 && t->nodes[t->nodes[top].parent].kind == AG_NODE_SPLIT &&
           t->nodes[t->nodes[top].parent].first_child == top &&
           t->nodes[t->nodes[top].parent].last_child == top)
        top = t->nodes[top].parent;
    size_t ns = 0;
    stack[ns++] = top;
    while (ns) {
        int32_t x = stack[--ns];
        if (t->nodes[x].kind == AG_NODE_DEAD)
            continue;
        for (int32_t c = t->nodes[x].first_child; c >= 0; c = t->nodes[c].next_sibling)
            stack[ns++] = c;
        *visible += t->nodes[x].kind == AG_NODE_COMPONENT;
        t->nodes[x].kind = AG_NODE_DEAD;
    }
}

/* Takes the dead nodes out of their parents' lists (one pass: a detach per node would walk
 * long sibling lists once per site) and unlinks them. */
static void unlink_dead(ag_splittree *t)
{
    for (size_t p = 0; p < t->nnodes; p++) {
        ag_tnode *x = &t->nodes[p];
        if (x->kind == AG_NODE_DEAD)
            continue;
        int32_t last = -1;
        for (int32_t c = x->first_child; c >= 0;) {
            int32_t next = t->nodes[c].next_sibling;
            if (t->nodes[c].kind != AG_NODE_DEAD) {
                if (last < 0)
                    x->first_child = c;
                else
                    t->nodes[last].next_sibling = c;
                last = c;
            }
            c = next;
        }
        if (last < 0)
            x->first_child = -1;
        else
            t->nodes[last].next_sibling = -1;
        x->last_child = last;
    }
    for (size_t p = 0; p < t->nnodes; p++) {
        ag_tnode *x = &t->nodes[p];
        if (x->kind == AG_NODE_DEAD) {
            /* a dead node names nothing: the kept tree checks every index it holds */
            x->parent = x->first_child = x->last_child = x->next_sibling = -1;
            x->component = x->label = x->variant = x->rule = x->pattern = -1;
        }
    }
}

/* The nearest visible ancestor of n (or the root) whose box holds b. */
static int32_t holder(const ag_splittree *t, int32_t n, const ag_box *b, double tol)
{
    for (int32_t p = n; p >= 0; p = t->nodes[p].parent) {
        const ag_tnode *x = &t->nodes[p];
        if ((x->kind == AG_NODE_COMPONENT || x->kind == AG_NODE_ROOT) &&
            (x->parent < 0 || ag_box_contains(&x->box, b, tol)))
            return p;
    }
    return 0;
}

/* ---- the graft ----------------------------------------------------------------------------- */

typedef struct {
    /* inputs */
    const ag_proceduralize_result *in;
    const ag_mesh *D;
    dcomps d;
    double q; /* box pairing tolerance */
    /* sites */
    int32_t *sites;
    size_t nsites;
    int32_t *hang;     /* per site: where its new components hang */
    int32_t *cell;     /* per site: the pattern node it was a cell of (replace), else -1 */
    /* new components: the derivation's index, their site, label, variant */
    size_t nnew;
    uint32_t *nd;
    int32_t *nsite, *nlabel, *nvariant;
    uint8_t *nrot; /* quarter turns from the variant's exemplar */
    size_t new_labels, new_variants;
    int32_t *variant_exemplar; /* per new variant: index into nd */
} graft;

static void graft_free(graft *g)
{
    dcomps_free(&g->d);
    free(g->sites);
    free(g->hang);
    free(g->cell);
    free(g->nd);
    free(g->nsite);
    free(g->nlabel);
    free(g->nvariant);
    free(g->nrot);
    free(g->variant_exemplar);
}

/* Pairs the derivation's components with the kept ones by box; the others are new. */
static ag_status pair_components(graft *g, const ag_splittree *X, const uint8_t *gone,
                                 ag_graft_report *rep, ag_error *err)
{
    const ag_splittree *T = g->in->tree;
    const ag_labels *L = g->in->labels;
    size_t nk = 0;
    int32_t *kept = malloc((T->ncomponents + 1) * sizeof *kept);
    /* the kept boxes side by side: the search reads them, not the tree's scattered nodes */
    ag_box *kbox = malloc((T->ncomponents + 1) * sizeof *kbox);
    uint8_t *used = calloc(T->ncomponents + 1, 1);
    uint8_t *paired = calloc(g->d.nc + 1, 1);
    cellhash h = {0};
    ag_status st = AG_OK;
    /* cells four tolerances wide: a box's min +- q meets at most two per axis (one mostly),
     * not three */
    double cs = 4 * g->q;
    if (!kept || !kbox || !used || !paired || cellhash_init(&h, T->ncomponents)) {
        st = nomem(err);
        goto done;
    }
    for (size_t c = 0; c < T->ncomponents; c++) {
        int32_t n = T->comp_node[c];
        if (n < 0 || gone[n] || X->nodes[n].kind != AG_NODE_COMPONENT ||
            L->tri_start[c + 1] == L->tri_start[c])
            continue;
        const ag_box *b = &T->nodes[n].box;
        kept[nk] = (int32_t)c;
        kbox[nk] = *b;
        cellhash_add(&h, cell_key(cell_of(b->min[0], cs), cell_of(b->min[1], cs),
                                  cell_of(b->min[2], cs)),
                     (int32_t)nk);
        nk++;
    }
    rep->kept = nk;
    const ag_mesh *D = g->D;
    size_t matched = 0;
    /* per group of the derivation: the label "L<k>" names (k - 1), else -1 */
    int32_t *group_label = malloc((D->ngroups + 1) * sizeof *group_label);
    if (!group_label) {
        st = nomem(err);
        goto done;
    }
    for (size_t k = 0; k < D->ngroups; k++)
        group_label[k] = (int32_t)ag__rebuild_label_number(D->group_names[k]) - 1;
    for (size_t c = 0; c < g->d.nc; c++) {
        if (!dcomp_ntris(&g->d, c))
            continue;
        const ag_box *b = &g->d.box[c];
        int64_t lo[3], hi[3];
        for (int a = 0; a < 3; a++) {
            lo[a] = cell_of(b->min[a] - g->q, cs);
            hi[a] = cell_of(b->min[a] + g->q, cs);
        }
        /* the best candidate: the same triangle count, then the same label group, then the
         * first component (coincident copies pair in their order, however the cells fall) */
        int32_t best = -1, best_score = -1;
        int32_t grp = D->component_group ? D->component_group[c] : -1;
        int32_t glab = grp >= 0 && (size_t)grp < D->ngroups ? group_label[grp] : -1;
        for (int64_t x = lo[0]; x <= hi[0]; x++)
            for (int64_t y = lo[1]; y <= hi[1]; y++)
                for (int64_t z = lo[2]; z <= hi[2]; z++)
                    for (int32_t e = h.head[cell_key(x, y, z) & (h.cap - 1)]; e >= 0;
                         e = h.next[e]) {
                        int32_t kc = kept[e];
                        if (used[kc] || !same_box(&kbox[e], b, g->q))
                            continue;
                        int score = (L->tri_start[kc + 1] - L->tri_start[kc]) ==
                                    dcomp_ntris(&g->d, c);
                        score += glab >= 0 && glab == L->label[kc] ? 2 : 0;
                        if (score > best_score || (score == best_score && kc < best)) {
                            best_score = score;
                            best = kc;
                        }
                    }
        if (best >= 0) {
            /* the same surface as the kept component: a composition that put other geometry
             * into the same box would otherwise keep the old one */
            double ks[4], *ds = g->d.sig + 4 * c, dg = ag_box_diagonal(b);
            signature(g->in->mesh, L->tris + L->tri_start[best],
                      L->tri_start[best + 1] - L->tri_start[best], ks);
            /* the derivation places a shared terminal, which differs from the member by up
             * to what labeling certified (its variant's deviation) */
            int32_t kv = L->variant[best];
            double dev = kv >= 0 && (size_t)kv < L->nvariants && L->variant_deviation
                             ? L->variant_deviation[kv]
                             : 0;
            double tol = fmax(g->q, fmax(fmax(L->tol, L->share), dev));
            int same = fabs(ks[0] - ds[0]) <= 1e-2 * fmax(ks[0], ds[0]) + 4 * tol * dg;
            for (int a = 1; a < 4 && same; a++)
                same = fabs(ks[a] - ds[a]) <= 2 * tol + 1e-3 * dg;
            if (!same) {
                free(group_label);
                st = ag_error_set(err, AG_ERR_NOT_AVAILABLE, T->comp_node[best],
                                  "the composed grammar places other geometry on the box of "
                                  "node %d, which stays",
                                  (int)T->comp_node[best]);
                goto done;
            }
            used[best] = 1;
            paired[c] = 1;
            matched++;
        }
    }
    free(group_label);
    if (matched != nk) {
        for (size_t i = 0; i < nk; i++)
            if (!used[kept[i]]) {
                st = ag_error_set(err, AG_ERR_NOT_AVAILABLE, T->comp_node[kept[i]],
                                  "node %d stays but the composed grammar does not place it "
                                  "on its box",
                                  (int)T->comp_node[kept[i]]);
                goto done;
            }
    }
    g->nnew = 0;
    for (size_t c = 0; c < g->d.nc; c++)
        g->nnew += dcomp_ntris(&g->d, c) && !paired[c];
    g->nd = malloc((g->nnew + 1) * sizeof *g->nd);
    if (!g->nd) {
        st = nomem(err);
        goto done;
    }
    size_t k = 0;
    for (size_t c = 0; c < g->d.nc; c++)
        if (dcomp_ntris(&g->d, c) && !paired[c])
            g->nd[k++] = (uint32_t)c;
done:
    free(kept);
    free(kbox);
    free(used);
    free(paired);
    cellhash_free(&h);
    return st;
}

/* Distance from point p to box b (0 inside). */
static double point_box_distance(const ag_box *b, const double p[3])
{
    double s = 0;
    for (int a = 0; a < 3; a++) {
        double e = p[a] < b->min[a] ? b->min[a] - p[a] : p[a] > b->max[a] ? p[a] - b->max[a] : 0;
        s += e * e;
    }
    return sqrt(s);
}

/* The site of every new component: the one nearest its centre (scope rule), within half the
 * site's size. */
static ag_status assign_sites(graft *g, const ag_splittree *T, ag_error *err)
{
    g->nsite = malloc((g->nnew + 1) * sizeof *g->nsite);
    if (!g->nsite)
        return nomem(err);
    if (g->nsites == 1) {
        for (size_t i = 0; i < g->nnew; i++)
            g->nsite[i] = 0;
        return AG_OK;
    }
    /* a grid of cells as large as the largest site: a site covers at most 2 per axis */
    double cs = 0;
    for (size_t s = 0; s < g->nsites; s++)
        for (int a = 0; a < 3; a++)
            cs = fmax(cs, ag_box_extent(&T->nodes[g->sites[s]].box, a));
    cs = fmax(cs, g->q * 16);
    cellhash h = {0};
    size_t nent = 0, cap = 8 * g->nsites + 8;
    int32_t *ent_site = malloc(cap * sizeof *ent_site);
    if (!ent_site || cellhash_init(&h, cap)) {
        free(ent_site);
        cellhash_free(&h);
        return nomem(err);
    }
    for (size_t s = 0; s < g->nsites; s++) {
        const ag_box *b = &T->nodes[g->sites[s]].box;
        for (int64_t x = cell_of(b->min[0], cs); x <= cell_of(b->max[0], cs); x++)
            for (int64_t y = cell_of(b->min[1], cs); y <= cell_of(b->max[1], cs); y++)
                for (int64_t z = cell_of(b->min[2], cs); z <= cell_of(b->max[2], cs); z++) {
                    ent_site[nent] = (int32_t)s;
                    cellhash_add(&h, cell_key(x, y, z), (int32_t)nent);
                    nent++;
                }
    }
    ag_status st = AG_OK;
    for (size_t i = 0; i < g->nnew && !st; i++) {
        double c[3];
        ag_box_centre(&g->d.box[g->nd[i]], c);
        int32_t best = -1;
        double bd = INFINITY;
        int64_t cx = cell_of(c[0], cs), cy = cell_of(c[1], cs), cz = cell_of(c[2], cs);
        for (int64_t x = cx - 1; x <= cx + 1; x++)
            for (int64_t y = cy - 1; y <= cy + 1; y++)
                for (int64_t z = cz - 1; z <= cz + 1; z++)
                    for (int32_t e = h.head[cell_key(x, y, z) & (h.cap - 1)]; e >= 0;
                         e = h.next[e]) {
                        int32_t s = ent_site[e];
                        double dd = point_box_distance(&T->nodes[g->sites[s]].box, c);
                        if (dd < bd || (dd == bd && s < best)) {
                            bd = dd;
                            best = s;
                        }
                    }
        double ext[3] = {0, 0, 0};
        if (best >= 0)
            ag_box_extents(&T->nodes[g->sites[best]].box, ext);
        if (best < 0 || bd > g->q + 0.5 * fmax(ext[0], fmax(ext[1], ext[2])))
            st = ag_error_set(err, AG_ERR_NOT_AVAILABLE, 0,
                              "a component the part brings lies outside every instance of "
                              "the target");
        else
            g->nsite[i] = best;
    }
    free(ent_site);
    cellhash_free(&h);
    return st;
}

/* A new variant that is one of the model's variants of its label (the exemplar's shape and
 * size, turned or not: a terminal the part shares with the target) becomes that variant, as
 * labeling the derivation would find it; the other new variants are numbered after
 * the model's. g->nvariant then holds final variant numbers. */
static ag_status reuse_variants(graft *g, shape *vshape, ag_error *err)
{
    const ag_labels *L = g->in->labels;
    const ag_mesh *M = g->in->mesh;
    int32_t *final = malloc((g->new_variants + 1) * sizeof *final);
    uint8_t *turn = calloc(g->new_variants + 1, 1);
    uint32_t *stamp = calloc(M->nverts + 1, sizeof *stamp);
    uint32_t *local = malloc((M->nverts + 1) * sizeof *local);
    shape *old = calloc(L->nvariants + 1, sizeof *old);
    uint8_t *made = calloc(L->nvariants + 1, 1);
    ag_status st = AG_OK;
    if (!final || !turn || !stamp || !local || !old || !made) {
        st = nomem(err);
        goto done;
    }
    size_t next = L->nvariants;
    uint32_t mark = 0;
    double tol = fmax(g->q, L->exact);
    for (size_t k = 0; k < g->new_variants && !st; k++) {
        final[k] = -1;
        for (size_t v = 0; v < L->nvariants && final[k] < 0; v++) {
            uint32_t e = L->variant_exemplar ? L->variant_exemplar[v] : UINT32_MAX;
            if (e >= L->ncomponents || L->variant[e] != (int32_t)v)
                continue;
            uint32_t nt = L->tri_start[e + 1] - L->tri_start[e];
            /* within its label: the derivation's groups keep labels apart */
            if (nt != vshape[k].nt || L->variant_label[v] != g->nlabel[g->variant_exemplar[k]])
                continue;
            if (!made[v]) {
                ag_box b = ag_box_empty();
                for (uint32_t t = L->tri_start[e]; t < L->tri_start[e + 1]; t++)
                    for (int j = 0; j < 3; j++)
                        ag_box_extend_point(&b, &M->pos[3 * M->tri[3 * L->tris[t] + j]]);
                if (shape_of_tris(M, L->tris + L->tri_start[e], nt, &b, stamp, local, ++mark,
                                  &old[v])) {
                    st = nomem(err);
                    break;
                }
                made[v] = 1;
            }
            /* the same size too (turned): labels tell boxes of other proportions apart */
            for (int r = 0; r < 4 && final[k] < 0; r++)
                if (fabs(old[v].ext[r & 1] - vshape[k].ext[0]) <= tol &&
                    fabs(old[v].ext[1 - (r & 1)] - vshape[k].ext[1]) <= tol &&
                    fabs(old[v].ext[2] - vshape[k].ext[2]) <= tol &&
                    same_shape(&old[v], &vshape[k], r)) {
                    final[k] = (int32_t)v;
                    turn[k] = (uint8_t)r;
                }
        }
        if (final[k] < 0)
            final[k] = (int32_t)next++;
    }
    if (st)
        goto done;
    /* the model's variants taken keep their labels; the rest are the new ones, renumbered */
    size_t nv = 0;
    for (size_t k = 0; k < g->new_variants; k++)
        if ((size_t)final[k] >= L->nvariants)
            g->variant_exemplar[nv++] = g->variant_exemplar[k];
    for (size_t i = 0; i < g->nnew; i++) {
        int32_t k = g->nvariant[i];
        g->nvariant[i] = final[k];
        if ((size_t)final[k] < L->nvariants)
            g->nrot[i] = (uint8_t)((g->nrot[i] + turn[k]) & 3);
    }
    g->new_variants = nv;
done:
    for (size_t v = 0; old && v < L->nvariants; v++)
        shape_free(&old[v]);
    free(old);
    free(made);
    free(final);
    free(turn);
    free(stamp);
    free(local);
    return st;
}

/* Labels (by group) and variants (by exact shape) of the new components. */
static ag_status classify(graft *g, ag_error *err)
{
    const ag_mesh *D = g->D;
    const ag_labels *L = g->in->labels;
    size_t nl0 = L->nlabels;
    g->nlabel = malloc((g->nnew + 1) * sizeof *g->nlabel);
    g->nvariant = malloc((g->nnew + 1) * sizeof *g->nvariant);
    g->nrot = calloc(g->nnew + 1, 1);
    g->variant_exemplar = malloc((g->nnew + 1) * sizeof *g->variant_exemplar);
    int32_t *group_label = malloc((D->ngroups + 1) * sizeof *group_label);
    uint32_t *stamp = calloc(D->nverts + 1, sizeof *stamp);
    uint32_t *local = malloc((D->nverts + 1) * sizeof *local);
    shape *vshape = calloc(g->nnew + 1, sizeof *vshape);
    int32_t *vlabel = malloc((g->nnew + 1) * sizeof *vlabel);
    ag_status st = AG_OK;
    size_t made = 0; /* shapes made into vshape */
    if (!g->nlabel || !g->nvariant || !g->nrot || !g->variant_exemplar || !group_label || !stamp || !local ||
        !vshape || !vlabel) {
        st = nomem(err);
        goto done;
    }
    for (size_t k = 0; k < D->ngroups; k++) {
        size_t n = ag__rebuild_label_number(D->group_names[k]);
        group_label[k] = n >= 1 && n <= nl0 ? (int32_t)(n - 1) : -1;
    }
    uint32_t mark = 0;
    for (size_t i = 0; i < g->nnew && !st; i++) {
        uint32_t c = g->nd[i];
        int32_t grp = D->component_group ? D->component_group[c] : -1;
        int32_t lab;
        if (grp >= 0 && (size_t)grp < D->ngroups) {
            if (group_label[grp] < 0)
                group_label[grp] = (int32_t)(nl0 + g->new_labels++);
            lab = group_label[grp];
        } else {
            lab = (int32_t)(nl0 + g->new_labels++);
        }
        g->nlabel[i] = lab;
        shape s = {0};
        if (shape_of(D, &g->d, c, stamp, local, ++mark, &s)) {
            shape_free(&s);
            st = nomem(err);
            break;
        }
        /* a copy, or a copy turned by quarter turns (as labeling finds them: a part placed
         * on facades facing other ways keeps one terminal) */
        int32_t v = -1;
        for (size_t k = 0; k < g->new_variants && v < 0; k++)
            for (int r = 0; r < 4 && v < 0; r++)
                if (vlabel[k] == lab && same_shape(&vshape[k], &s, r)) {
                    v = (int32_t)k;
                    g->nrot[i] = (uint8_t)r;
                }
        if (v < 0) {
            v = (int32_t)g->new_variants++;
            vshape[v] = s;
            vlabel[v] = lab;
            g->variant_exemplar[v] = (int32_t)i;
        } else {
            shape_free(&s);
        }
        g->nvariant[i] = v;
    }
    /* the reuse renumbers the variants and lowers their count: every shape made is freed */
    made = g->new_variants;
    if (!st)
        st = reuse_variants(g, vshape, err);
done:
    for (size_t k = 0; vshape && k < made; k++)
        shape_free(&vshape[k]);
    free(vshape);
    free(vlabel);
    free(group_label);
    free(stamp);
    free(local);
    return st;
}

/* The input the rebuild reads: in's mesh, labels and tree with the new components appended
 * (the tree X already edited). */
static ag_status combined_input(const graft *g, ag_splittree *X, ag_proceduralize_result *c,
                                ag_error *err)
{
    const ag_proceduralize_result *in = g->in;
    const ag_labels *L0 = in->labels;
    const ag_mesh *D = g->D;
    size_t n0 = L0->ncomponents, nc = n0 + g->nnew;
    const ag_mesh *M = in->mesh;
    ag_mesh *m = ag_mesh_create();
    ag_labels *L = calloc(1, sizeof *L);
    uint32_t *stamp = calloc(D->nverts + 1, sizeof *stamp), *local = malloc((D->nverts + 1) * sizeof *local);
    if (!m || !L || !stamp || !local)
        goto nomem_;
    size_t ntris = M->ntris, nv = M->nverts;
    for (size_t i = 0; i < g->nnew; i++) {
        ntris += dcomp_ntris(&g->d, g->nd[i]);
        nv += 3 * dcomp_ntris(&g->d, g->nd[i]);
    }
    /* the model's mesh copied once into room for the new components (the rebuild reads the
     * geometry and the components; groups are its own) */
    if (ag_mesh_reserve(m, nv, ntris))
        goto nomem_;
    memcpy(m->pos, M->pos, 3 * M->nverts * sizeof *m->pos);
    memcpy(m->tri, M->tri, 3 * M->ntris * sizeof *m->tri);
    memcpy(m->tri_component, M->tri_component, M->ntris * sizeof *m->tri_component);
    m->nverts = M->nverts;
    m->ntris = M->ntris;
    for (size_t c = 0; c < M->ncomponents; c++) {
        size_t comp;
        if (ag_mesh_add_component(m, -1, &comp))
            goto nomem_;
    }
    L->ncomponents = nc;
    L->nlabels = L0->nlabels + g->new_labels;
    L->nvariants = L0->nvariants + g->new_variants;
    L->label = malloc((nc + 1) * sizeof *L->label);
    L->rot = calloc(nc + 1, 1);
    L->mirror = calloc(nc + 1, 1);
    L->turn = calloc(nc + 1, sizeof *L->turn);
    L->variant = malloc((nc + 1) * sizeof *L->variant);
    L->vrot = calloc(nc + 1, 1);
    L->tri_start = calloc(nc + 2, sizeof *L->tri_start);
    L->tris = malloc((ntris + 1) * sizeof *L->tris);
    L->variant_label = malloc((L->nvariants + 1) * sizeof *L->variant_label);
    L->variant_deviation = calloc(L->nvariants + 1, sizeof *L->variant_deviation);
    if (!L->label || !L->rot || !L->mirror || !L->turn || !L->variant || !L->vrot ||
        !L->tri_start || !L->tris || !L->variant_label || !L->variant_deviation)
        goto nomem_;
    memcpy(L->label, L0->label, n0 * sizeof *L->label);
    memcpy(L->rot, L0->rot, n0);
    if (L0->mirror)
        memcpy(L->mirror, L0->mirror, n0);
    if (L0->turn)
        memcpy(L->turn, L0->turn, n0 * sizeof *L->turn);
    memcpy(L->variant, L0->variant, n0 * sizeof *L->variant);
    memcpy(L->vrot, L0->vrot, n0);
    memcpy(L->tri_start, L0->tri_start, (n0 + 1) * sizeof *L->tri_start);
    memcpy(L->tris, L0->tris, L0->tri_start[n0] * sizeof *L->tris);
    memcpy(L->variant_label, L0->variant_label, L0->nvariants * sizeof *L->variant_label);
    if (L0->variant_deviation)
        memcpy(L->variant_deviation, L0->variant_deviation,
               L0->nvariants * sizeof *L->variant_deviation);
    for (size_t v = 0; v < g->new_variants; v++)
        L->variant_label[L0->nvariants + v] = g->nlabel[g->variant_exemplar[v]];
    L->diagonal = L0->diagonal;
    L->tol = L0->tol;
    L->exact = L0->exact;
    L->share = L0->share;
    L->exact_copies = L0->exact_copies;
    /* the new components' geometry from the derivation */
    uint32_t at = L0->tri_start[n0];
    for (size_t i = 0; i < g->nnew; i++) {
        uint32_t dc = g->nd[i];
        size_t comp;
        if (ag_mesh_add_component(m, -1, &comp))
            goto nomem_;
        size_t ci = n0 + i;
        L->label[ci] = g->nlabel[i];
        L->variant[ci] = g->nvariant[i];
        L->rot[ci] = L->vrot[ci] = g->nrot[i];
        L->turn[ci] = g->nrot[i] * 1.5707963267948966;
        uint32_t mark = (uint32_t)i + 1;
        for (uint32_t k = g->d.tri_start[dc]; k < g->d.tri_start[dc + 1]; k++) {
            uint32_t tr = g->d.tris[k], v[3];
            for (int j = 0; j < 3; j++) {
                uint32_t sv = D->tri[3 * tr + j];
                if (stamp[sv] != mark) {
                    stamp[sv] = mark;
                    local[sv] = (uint32_t)m->nverts;
                    const double *p = &D->pos[3 * sv];
                    if (ag_mesh_add_vertex(m, p[0], p[1], p[2]))
                        goto nomem_;
                }
                v[j] = local[sv];
            }
            L->tris[at++] = (uint32_t)m->ntris;
            if (ag_mesh_add_triangle(m, v[0], v[1], v[2], (uint32_t)comp))
                goto nomem_;
        }
        L->tri_start[ci + 1] = at;
    }
    free(stamp);
    free(local);
    c->mesh = m;
    c->labels = L;
    c->tree = X;
    return AG_OK;
nomem_:
    free(stamp);
    free(local);
    ag_mesh_free(m);
    ag_labels_free(L);
    return nomem(err);
}

/* The nearest component above node n of t, else -1. */
static int32_t component_above(const ag_splittree *t, int32_t n)
{
    int32_t p = t->nodes[n].parent;
    while (p >= 0 && t->nodes[p].kind != AG_NODE_COMPONENT)
        p = t->nodes[p].parent;
    return p;
}

/* The number of cells of pattern node p. */
static uint32_t cells_of(const ag_splittree *t, int32_t p)
{
    uint32_t n = 0;
    for (int32_t c = t->nodes[p].first_child; c >= 0; c = t->nodes[c].next_sibling)
        n++;
    return n;
}

/* Per site, the new component that takes the place of the pattern cell the site was (its
 * box the cell's, the only one of the site's that no other new component holds), else -1.
 * Only a pattern every one of whose replaced cells is so taken keeps its cells in place: it
 * then holds as before, and is not dissolved and found again. mt: the new components' own
 * nesting. */
static int32_t *cell_takers(const graft *g, const ag_splittree *X, const ag_splittree *mt)
{
    const ag_splittree *T = g->in->tree;
    int32_t *take = malloc((g->nsites + 1) * sizeof *take);
    uint32_t *tops = calloc(g->nsites + 1, sizeof *tops);
    uint8_t *broken = calloc(X->nnodes + 1, 1);
    uint32_t *replaced = calloc(X->nnodes + 1, sizeof *replaced);
    uint8_t *partial = calloc(X->nnodes + 1, 1); /* per pattern: 1 all cells replaced, 2 not */
    if (!take || !tops || !broken || !replaced || !partial) {
        free(take);
        free(tops);
        free(broken);
        free(replaced);
        free(partial);
        return NULL;
    }
    for (size_t s = 0; s < g->nsites; s++)
        take[s] = -1;
    /* within what the rebuild's pattern check allows, so that the pattern still holds */
    double tol = fmin(g->q, X->tol > 0 ? X->tol : X->eps);
    for (size_t k = 0; k < mt->nnodes; k++) {
        const ag_tnode *x = &mt->nodes[k];
        if (x->kind != AG_NODE_COMPONENT)
            continue;
        int32_t vp = component_above(mt, (int32_t)k);
        size_t i = (size_t)x->component;
        int32_t s = g->nsite[i];
        if (vp >= 0 || g->cell[s] < 0)
            continue;
        tops[s]++;
        if (same_box(&g->d.box[g->nd[i]], &T->nodes[g->sites[s]].box, tol))
            take[s] = (int32_t)i;
    }
    /* replaced cells per pattern: a pattern only partly replaced holds again only when its
     * new cells repeat its rule, so those must at least be its cells' variant (else it is
     * dissolved, and its cells are best hung as before) */
    for (size_t s = 0; s < g->nsites; s++)
        if (g->cell[s] >= 0)
            replaced[g->cell[s]]++;
    for (size_t s = 0; s < g->nsites; s++) {
        int32_t p = g->cell[s];
        if (p < 0)
            continue;
        if (tops[s] != 1 || take[s] < 0 || X->nodes[p].kind != AG_NODE_PATTERN)
            broken[p] = 1;
        else if (partial[p] != 1 &&
                 (g->nvariant[take[s]] != T->nodes[g->sites[s]].variant ||
                  g->nrot[take[s]] != T->nodes[g->sites[s]].rot)) {
            if (!partial[p]) /* counted once per pattern */
                partial[p] = replaced[p] == cells_of(T, p) ? 1 : 2;
            if (partial[p] == 2)
                broken[p] = 1;
        }
    }
    for (size_t s = 0; s < g->nsites; s++)
        if (g->cell[s] < 0 || broken[g->cell[s]])
            take[s] = -1;
    free(tops);
    free(broken);
    free(replaced);
    free(partial);
    return take;
}

/* The cells of pattern node p in X in the order they had in in's tree, each replaced cell's
 * place taken by its new node (placed: per site; site_of: per node of in's tree), so the
 * lattice order of the pattern is kept; its box spans them again. */
static void cells_reorder(const graft *g, ag_splittree *X, int32_t p, const int32_t *placed,
                          const int32_t *site_of)
{
    const ag_splittree *T = g->in->tree;
    ag_tnode *P = &X->nodes[p];
    int32_t last = -1;
    P->first_child = P->last_child = -1;
    for (int32_t c = T->nodes[p].first_child; c >= 0; c = T->nodes[c].next_sibling) {
        int32_t v = -1;
        if (X->nodes[c].kind != AG_NODE_DEAD && X->nodes[c].parent == p)
            v = c;
        else if (site_of[c] >= 0 && placed[site_of[c]] >= 0)
            v = placed[site_of[c]];
        if (v < 0)
            continue;
        X->nodes[v].parent = p;
        X->nodes[v].next_sibling = -1;
        if (last >= 0)
            X->nodes[last].next_sibling = v;
        else
            P->first_child = v;
        last = v;
    }
    P->last_child = last;
    if (last < 0)
        return;
    ag_box b = X->nodes[P->first_child].box;
    for (int32_t c = X->nodes[P->first_child].next_sibling; c >= 0; c = X->nodes[c].next_sibling)
        ag_box_extend_box(&b, &X->nodes[c].box);
    P->box = b;
}

/* The new components nested among themselves (the split tree's rule) and inserted into X
 * under their sites' hang nodes. */
static ag_status insert_new(graft *g, ag_splittree *X, ag_error *err)
{
    const ag_labels *L0 = g->in->labels;
    size_t n0 = L0->ncomponents, nn = g->nnew;
    int32_t *comp_node = realloc(X->comp_node, (n0 + nn + 1) * sizeof *comp_node);
    if (!comp_node)
        return nomem(err);
    X->comp_node = comp_node;
    for (size_t i = 0; i < nn; i++)
        X->comp_node[n0 + i] = -1;
    X->ncomponents = n0 + nn;
    if (!nn)
        return AG_OK;
    /* the nesting of the new components alone */
    ag_labels ml = {0};
    ml.ncomponents = nn;
    ml.box = malloc(nn * sizeof *ml.box);
    ml.ntris = malloc(nn * sizeof *ml.ntris);
    ml.label = malloc(nn * sizeof *ml.label);
    ml.variant = malloc(nn * sizeof *ml.variant);
    ml.vrot = malloc(nn);
    ml.diagonal = L0->diagonal;
    ml.exact = L0->exact;
    ag_splittree *mt = NULL;
    int32_t *map = NULL, *take = NULL, *placed = NULL, *site_of = NULL;
    uint8_t *done_p = NULL;
    ag_status st = AG_OK;
    if (!ml.box || !ml.ntris || !ml.label || !ml.variant || !ml.vrot) {
        st = nomem(err);
        goto done;
    }
    for (size_t i = 0; i < nn; i++) {
        ml.box[i] = g->d.box[g->nd[i]];
        ml.ntris[i] = dcomp_ntris(&g->d, g->nd[i]);
        ml.label[i] = g->nlabel[i];
        ml.variant[i] = g->nvariant[i];
        ml.vrot[i] = g->nrot[i];
    }
    if ((st = ag_splittree_build(g->D, &ml, &mt, err)))
        goto done;
    if (!(map = malloc((mt->nnodes + 1) * sizeof *map)) || !(take = cell_takers(g, X, mt)) ||
        !(placed = malloc((g->nsites + 1) * sizeof *placed))) {
        st = nomem(err);
        goto done;
    }
    for (size_t s = 0; s < g->nsites; s++)
        placed[s] = -1;
    double nest = fmax(X->eps, X->tol);
    for (size_t k = 0; k < mt->nnodes && !st; k++) {
        map[k] = -1;
        const ag_tnode *x = &mt->nodes[k];
        if (x->kind != AG_NODE_COMPONENT)
            continue;
        int32_t vp = component_above(mt, (int32_t)k);
        size_t i = (size_t)x->component;
        ag_box b = g->d.box[g->nd[i]];
        int32_t s = g->nsite[i], n;
        ag_box_extend_box(&X->nodes[0].box, &b);
        if (vp < 0 && take[s] == (int32_t)i) {
            /* the cell's place in its pattern: no split chain (the pattern places its cells) */
            n = ag_splittree_add_node(X, AG_NODE_COMPONENT);
            placed[s] = n;
        } else {
            int32_t parent = vp >= 0 && map[vp] >= 0 ? map[vp] : g->hang[s];
            parent = holder(X, parent, &b, nest);
            n = ag_splittree_insert(X, parent, &b, AG_NODE_COMPONENT);
        }
        if (n < 0) {
            st = nomem(err);
            break;
        }
        ag_tnode *y = &X->nodes[n];
        y->box = b;
        y->component = (int32_t)(n0 + i);
        y->label = g->nlabel[i];
        y->variant = g->nvariant[i];
        y->rot = g->nrot[i];
        X->comp_node[n0 + i] = n;
        map[k] = n;
    }
    /* the replaced cells' new nodes into their patterns, in the cells' places */
    size_t ntaken = 0;
    for (size_t s = 0; !st && s < g->nsites; s++)
        ntaken += placed[s] >= 0;
    if (!st && ntaken) {
        const ag_splittree *T = g->in->tree;
        if (!(site_of = malloc((T->nnodes + 1) * sizeof *site_of)) ||
            !(done_p = calloc(X->nnodes + 1, 1))) {
            st = nomem(err);
            goto done;
        }
        for (size_t v = 0; v < T->nnodes; v++)
            site_of[v] = -1;
        for (size_t s = 0; s < g->nsites; s++)
            if (placed[s] >= 0)
                site_of[g->sites[s]] = (int32_t)s;
        for (size_t s = 0; s < g->nsites; s++)
            if (placed[s] >= 0 && !done_p[g->cell[s]]) {
                done_p[g->cell[s]] = 1;
                cells_reorder(g, X, g->cell[s], placed, site_of);
            }
    }
done:
    free(take);
    free(placed);
    free(site_of);
    free(done_p);
    free(ml.box);
    free(ml.ntris);
    free(ml.label);
    free(ml.variant);
    free(ml.vrot);
    free(map);
    ag_splittree_free(mt);
    return st;
}

ag_status ag_graft_compose(const ag_proceduralize_result *in, const ag_compose_op *op,
                           const ag_mesh *derived, const ag_patterns_options *popt,
                           ag_proceduralize_result **out, ag_graft_report *rep,
                           ag_error *err)
{
    *out = NULL;
    ag_graft_report local = {0};
    if (!rep)
        rep = &local;
    memset(rep, 0, sizeof *rep);
    const ag_splittree *T = in->tree;
    if (op->target < 0 || (size_t)op->target >= T->nnodes ||
        T->nodes[op->target].kind == AG_NODE_DEAD)
        return ag_error_set(err, AG_ERR_INVALID, op->target, "target: node %d is not in the tree",
                            (int)op->target);
    if (in->labels->ncomponents != T->ncomponents ||
        in->mesh->ncomponents != T->ncomponents)
        return ag_error_set(err, AG_ERR_NOT_AVAILABLE, 0,
                            "the model's mesh, labels and tree name different components");
    graft g = {.in = in, .D = derived};
    ag_splittree *X = NULL;
    uint8_t *gone = NULL;
    int32_t *stack = NULL;
    ag_proceduralize_result comb = {0};
    ag_status st = AG_OK;
    double t0 = ag_clock_ms(), t1;
    if (dcomps_make(derived, &g.d)) {
        st = nomem(err);
        goto done;
    }
    double diag = ag_box_diagonal(&T->nodes[0].box);
    g.q = fmax(fmax(T->eps, T->tol), 1e-9 * (diag > 0 ? diag : 1));
    /* the sites */
    if (!(g.sites = malloc((T->nnodes + 1) * sizeof *g.sites))) {
        st = nomem(err);
        goto done;
    }
    const ag_tnode *tn = &T->nodes[op->target];
    if (op->scope == AG_COMPOSE_RULE) {
        if (tn->kind != AG_NODE_COMPONENT || tn->rule < 0) {
            st = ag_error_set(err, AG_ERR_NOT_AVAILABLE, op->target,
                              "node %d has no rule class in the tree", (int)op->target);
            goto done;
        }
        for (size_t n = 0; n < T->nnodes; n++)
            if (T->nodes[n].kind == AG_NODE_COMPONENT && T->nodes[n].rule == tn->rule)
                g.sites[g.nsites++] = (int32_t)n;
    } else {
        g.sites[g.nsites++] = op->target;
    }
    rep->sites = g.nsites;
    t1 = ag_clock_ms();
    rep->components_ms = t1 - t0;
    /* removals */
    if (!(X = ag_splittree_copy(T)) || !(gone = calloc(T->nnodes + 1, 1)) ||
        !(g.hang = malloc((g.nsites + 1) * sizeof *g.hang)) ||
        !(g.cell = malloc((g.nsites + 1) * sizeof *g.cell)) ||
        !(stack = malloc((T->nnodes + 1) * sizeof *stack))) {
        st = nomem(err);
        goto done;
    }
    for (size_t s = 0; s < g.nsites; s++) {
        int32_t n = g.sites[s];
        g.cell[s] = -1;
        if (X->nodes[n].kind == AG_NODE_DEAD) { /* inside a site removed before */
            g.hang[s] = 0;
            continue;
        }
        int whole = op->mode == AG_COMPOSE_REPLACE && n != 0;
        if (whole) {
            int32_t p = X->nodes[n].parent;
            if (X->nodes[n].kind == AG_NODE_COMPONENT && p >= 0 &&
                X->nodes[p].kind == AG_NODE_PATTERN)
                g.cell[s] = p;
            while (p > 0 && X->nodes[p].kind != AG_NODE_COMPONENT)
                p = X->nodes[p].parent;
            g.hang[s] = p < 0 ? 0 : p;
            remove_subtree(X, n, stack, &rep->removed);
        } else {
            g.hang[s] = n;
            if (op->mode != AG_COMPOSE_INSERT)
                for (int32_t c = X->nodes[n].first_child; c >= 0; c = X->nodes[c].next_sibling)
                    remove_subtree(X, c, stack, &rep->removed);
        }
    }
    unlink_dead(X);
    for (size_t n = 0; n < T->nnodes; n++)
        gone[n] = X->nodes[n].kind == AG_NODE_DEAD;
    t0 = ag_clock_ms();
    rep->removal_ms = t0 - t1;
    if ((st = pair_components(&g, X, gone, rep, err)))
        goto done;
    t1 = ag_clock_ms();
    rep->pair_ms = t1 - t0;
    if ((st = assign_sites(&g, T, err)) ||
        (st = classify(&g, err)))
        goto done;
    t0 = ag_clock_ms();
    rep->classify_ms = t0 - t1;
    if ((st = insert_new(&g, X, err)))
        goto done;
    rep->added = g.nnew;
    t1 = ag_clock_ms();
    rep->insert_ms = t1 - t0;
    if ((st = combined_input(&g, X, &comb, err)))
        goto done;
    X = NULL; /* comb.tree */
    /* every node is its own source, so the rebuild edits the combined tree itself rather
     * than a copy of it: it reads a node's source before it changes that node (rebuild.h) */
    ag_splittree *t = comb.tree;
    int32_t *source = malloc((t->nnodes + 1) * sizeof *source);
    if (!source) {
        st = nomem(err);
        goto done;
    }
    for (size_t v = 0; v < t->nnodes; v++)
        source[v] = (int32_t)v;
    t0 = ag_clock_ms();
    rep->input_ms = t0 - t1;
    st = ag_rebuild(&comb, t, source, popt, out, err);
    comb.tree = NULL; /* the rebuild's (its result's, or freed) */
    rep->rebuild_ms = ag_clock_ms() - t0;
done:
    ag_mesh_free(comb.mesh);
    ag_labels_free(comb.labels);
    ag_splittree_free(comb.tree);
    ag_splittree_free(X);
    free(gone);
    free(stack);
    graft_free(&g);
    return st;
}
