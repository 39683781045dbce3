#include "kdtree.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define LEAF_SIZE 8

typedef struct {
    double p[3];
    uint32_t id;
} kd_point;

/* A leaf has left == 0 (node 0 is the root, never a child). */
typedef struct {
    double split;
    uint32_t lo, hi; /* point range [lo, hi) */
    uint32_t left, right;
    int dim;
} kd_node;

struct ag_kdtree {
    size_t n;
    kd_point *pts;
    uint32_t *order;
    kd_node *nodes;
    size_t nnodes, cap_nodes;
};

static void swap_pt(kd_point *a, kd_point *b)
{
    kd_point t = *a;
    *a = *b;
    *b = t;
}

/* Rearranges pts[lo, hi) so that pts[k] holds the value of rank k on axis dim, smaller or
 * equal values before it and larger or equal after (Hoare partitioning, median-of-three). */
static void select_kth(kd_point *pts, size_t lo, size_t hi, size_t k, int dim)
{
    while (hi - lo > 1) {
        /* the lower middle as pivot keeps both sides of a Hoare partition non-empty */
        size_t last = hi - 1, mid = lo + (last - lo) / 2;
        if (pts[mid].p[dim] < pts[lo].p[dim])
            swap_pt(&pts[mid], &pts[lo]);
        if (pts[last].p[dim] < pts[lo].p[dim])
            swap_pt(&pts[last], &pts[lo]);
        if (pts[last].p[dim] < pts[mid].p[dim])
            swap_pt(&pts[last], &pts[mid]);
        double pivot = pts[mid].p[dim];
        size_t i = lo, j = last;
        for (;;) {
            while (pts[i].p[dim] < pivot)
                i++;
            while (pts[j].p[dim] > pivot)
                j--;
            if (i >= j)
                break;
            swap_pt(&pts[i], &pts[j]);
            i++;
            j--;
        }
        /* [lo, j] <= pivot <= [j+1, hi) */
        if (k <= j)
            hi = j + 1;
        else
            lo = j + 1;
    }
}

static int add_node(ag_kdtree *t, uint32_t lo, uint32_t hi, uint32_t *index)
{
    if (t->nnodes == t->cap_nodes) {
        size_t cap = t->cap_nodes ? 2 * t->cap_nodes : 64;
        kd_node *nodes = realloc(t->nodes, cap * sizeof *nodes);
        if (!nodes)
            return -1;
        t->nodes = nodes;
        t->cap_nodes = cap;
    }
    kd_node *nd = &t->nodes[t->nnodes];
    memset(nd, 0, sizeof *nd);
    nd->lo = lo;
    nd->hi = hi;
    *index = (uint32_t)t->nnodes++;
    return 0;
}

/* Splits node `index` and its descendants; an explicit stack keeps deep trees safe. */
static int build_nodes(ag_kdtree *t)
{
    uint32_t stack[128];
    size_t top = 0;
    stack[top++] = 0;
    while (top) {
        uint32_t index = stack[--top];
        uint32_t lo = t->nodes[index].lo, hi = t->nodes[index].hi;
        if (hi - lo <= LEAF_SIZE)
            continue;
        double mn[3] = {DBL_MAX, DBL_MAX, DBL_MAX}, mx[3] = {-DBL_MAX, -DBL_MAX, -DBL_MAX};
        for (uint32_t i = lo; i < hi; i++)
            for (int a = 0; a < 3; a++) {
                double v = t->pts[i].p[a];
                if (v < mn[a])
                    mn[a] = v;
                if (v > mx[a])
                    mx[a] = v;
            }
        int dim = 0;
        for (int a = 1; a < 3; a++)
            if (mx[a] - mn[a] > mx[dim] - mn[dim])
                dim = a;
        /* equal points are split by position too: no leaf grows past LEAF_SIZE, so a pile of
         * duplicates cannot make every query scan it */
        uint32_t mid = lo + (hi - lo) / 2;
        select_kth(t->pts, lo, hi, mid, dim);
        uint32_t left, right;
        if (add_node(t, lo, mid, &left) || add_node(t, mid, hi, &right))
            return -1;
        kd_node *nd = &t->nodes[index];
        nd->dim = dim;
        nd->split = t->pts[mid].p[dim];
        nd->left = left;
        nd->right = right;
        if (top + 2 > sizeof stack / sizeof stack[0])
            return -1; /* cannot happen: median splits halve the range */
        stack[top++] = right;
        stack[top++] = left;
    }
    return 0;
}

ag_status ag_kdtree_build(const double *xyz, const uint32_t *subset, size_t n, ag_kdtree **out,
                          ag_error *err)
{
    *out = NULL;
    if (n >= UINT32_MAX)
        return ag_error_set(err, AG_ERR_TOO_LARGE, 0, "%zu points are too many for one index", n);
    ag_kdtree *t = calloc(1, sizeof *t);
    if (!t)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory for the spatial index");
    t->n = n;
    t->pts = malloc((n ? n : 1) * sizeof *t->pts);
    t->order = malloc((n ? n : 1) * sizeof *t->order);
    uint32_t root;
    if (!t->pts || !t->order || add_node(t, 0, (uint32_t)n, &root)) {
        ag_kdtree_free(t);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory for the spatial index");
    }
    for (size_t i = 0; i < n; i++) {
        uint32_t id = subset ? subset[i] : (uint32_t)i;
        memcpy(t->pts[i].p, xyz + 3 * (size_t)id, sizeof t->pts[i].p);
        t->pts[i].id = id;
    }
    if (build_nodes(t)) {
        ag_kdtree_free(t);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory for the spatial index");
    }
    for (size_t i = 0; i < n; i++)
        t->order[i] = t->pts[i].id;
    *out = t;
    return AG_OK;
}

void ag_kdtree_free(ag_kdtree *t)
{
    if (!t)
        return;
    free(t->pts);
    free(t->order);
    free(t->nodes);
    free(t);
}

size_t ag_kdtree_size(const ag_kdtree *t)
{
    return t->n;
}

const uint32_t *ag_kdtree_order(const ag_kdtree *t)
{
    return t->order;
}

typedef struct {
    const ag_kdtree *t;
    double q[3];
    size_t k, count;
    uint32_t *idx;
    double *d2;
    double bound; /* squared distance a point must beat: the k-th so far, or a known cap */
    uint32_t *slot; /* optional: the answers' positions in the tree's point array */
} knn_query;

/* Sorted insertion (k is small), dropping the farthest when full. */
static void knn_offer(knn_query *s, double d2, const kd_point *p)
{
    size_t i = s->count < s->k ? s->count++ : s->k - 1;
    while (i > 0 && s->d2[i - 1] > d2) {
        s->d2[i] = s->d2[i - 1];
        s->idx[i] = s->idx[i - 1];
        if (s->slot)
            s->slot[i] = s->slot[i - 1];
        i--;
    }
    s->d2[i] = d2;
    s->idx[i] = p->id;
    if (s->slot)
        s->slot[i] = (uint32_t)(p - s->t->pts);
    if (s->count == s->k)
        s->bound = s->d2[s->k - 1];
}

/* rd: squared distance from q to the node's cell (incremental, Arya & Mount); off: per-axis
 * offsets that make it up. */
static void knn_search(knn_query *s, uint32_t index, double rd, double off[3])
{
    const kd_node *nd = &s->t->nodes[index];
    if (!nd->left) {
        const kd_point *p = s->t->pts + nd->lo, *end = s->t->pts + nd->hi;
        for (; p < end; p++) {
            double dx = p->p[0] - s->q[0], dy = p->p[1] - s->q[1], dz = p->p[2] - s->q[2];
            double d2 = dx * dx + dy * dy + dz * dz;
            if (d2 < s->bound)
                knn_offer(s, d2, p);
        }
        return;
    }
    double diff = s->q[nd->dim] - nd->split;
    uint32_t near = diff < 0 ? nd->left : nd->right, far = diff < 0 ? nd->right : nd->left;
    knn_search(s, near, rd, off);
    double old = off[nd->dim];
    double far_rd = rd - old * old + diff * diff;
    if (far_rd < s->bound) {
        off[nd->dim] = diff;
        knn_search(s, far, far_rd, off);
        off[nd->dim] = old;
    }
}

static size_t knn_run(const ag_kdtree *t, const double q[3], size_t k, double bound, uint32_t *idx,
                      double *d2)
{
    knn_query s = {t, {q[0], q[1], q[2]}, k, 0, idx, d2, bound, NULL};
    double off[3] = {0, 0, 0};
    knn_search(&s, 0, 0, off);
    return s.count;
}

size_t ag_kdtree_knn(const ag_kdtree *t, const double q[3], size_t k, uint32_t *idx, double *d2)
{
    if (!t->n || !k)
        return 0;
    double local[64], *dist = d2;
    if (!dist)
        dist = k <= 64 ? local : malloc(k * sizeof *dist);
    if (!dist)
        return 0;
    size_t m = knn_run(t, q, k, INFINITY, idx, dist);
    if (dist != d2 && dist != local)
        free(dist);
    return m;
}

size_t ag_kdtree_knn_hint(const ag_kdtree *t, const double q[3], size_t k, const uint32_t *hint,
                          const double *xyz, uint32_t *idx, double *d2)
{
    if (!t->n || !k || k > t->n || !d2)
        return ag_kdtree_knn(t, q, k, idx, d2);
    /* k distinct points at most `cap` away: the k-th nearest is no farther */
    double cap = 0;
    for (size_t j = 0; j < k; j++) {
        const double *p = xyz + 3 * (size_t)hint[j];
        double dx = p[0] - q[0], dy = p[1] - q[1], dz = p[2] - q[2];
        double dd = dx * dx + dy * dy + dz * dz;
        if (dd > cap)
            cap = dd;
    }
    return knn_run(t, q, k, nextafter(cap, INFINITY), idx, d2);
}

typedef struct {
    const ag_kdtree *t;
    double q[3], r2;
    ag_kdtree_visit visit;
    void *user;
} radius_query;

static int radius_search(radius_query *s, uint32_t index, double rd, double off[3])
{
    const kd_node *nd = &s->t->nodes[index];
    if (!nd->left) {
        const kd_point *p = s->t->pts + nd->lo, *end = s->t->pts + nd->hi;
        for (; p < end; p++) {
            double dx = p->p[0] - s->q[0], dy = p->p[1] - s->q[1], dz = p->p[2] - s->q[2];
            double d2 = dx * dx + dy * dy + dz * dz;
            if (d2 <= s->r2) {
                int stop = s->visit(s->user, p->id, d2);
                if (stop)
                    return stop;
            }
        }
        return 0;
    }
    double diff = s->q[nd->dim] - nd->split;
    uint32_t near = diff < 0 ? nd->left : nd->right, far = diff < 0 ? nd->right : nd->left;
    int stop = radius_search(s, near, rd, off);
    if (stop)
        return stop;
    double old = off[nd->dim];
    double far_rd = rd - old * old + diff * diff;
    if (far_rd <= s->r2) {
        off[nd->dim] = diff;
        stop = radius_search(s, far, far_rd, off);
        off[nd->dim] = old;
    }
    return stop;
}

int ag_kdtree_radius(const ag_kdtree *t, const double q[3], double r, ag_kdtree_visit visit,
                     void *user)
{
    if (!t->n || !(r >= 0))
        return 0;
    radius_query s = {t, {q[0], q[1], q[2]}, r * r, visit, user};
    double off[3] = {0, 0, 0};
    return radius_search(&s, 0, 0, off);
}

/* ---- all points' neighbours ------------------------------------------------------------- */

int ag_kdtree_knn_each(const ag_kdtree *t, size_t k, ag_kdtree_knn_fn fn, void *user)
{
    if (!t->n || !k)
        return 0;
    if (k > 64)
        k = 64;
    uint32_t ids[64], slots[64];
    double d2[64];
    size_t m = 0;
    for (size_t i = 0; i < t->n; i++) {
        const kd_point *q = &t->pts[i];
        /* the previous point is close by in tree order: its k neighbours, k distinct points,
         * bound the search from the start */
        double bound = INFINITY;
        if (m == k) {
            double cap = 0;
            for (size_t j = 0; j < k; j++) {
                const double *p = t->pts[slots[j]].p;
                double dx = p[0] - q->p[0], dy = p[1] - q->p[1], dz = p[2] - q->p[2];
                double dd = dx * dx + dy * dy + dz * dz;
                if (dd > cap)
                    cap = dd;
            }
            bound = nextafter(cap, INFINITY);
        }
        knn_query s = {t, {q->p[0], q->p[1], q->p[2]}, k, 0, ids, d2, bound, slots};
        double off[3] = {0, 0, 0};
        knn_search(&s, 0, 0, off);
        m = s.count;
        const double *pos[64];
        for (size_t j = 0; j < m; j++)
            pos[j] = t->pts[slots[j]].p;
        int stop = fn(user, q->id, ids, d2, pos, m);
        if (stop)
            return stop;
    }
    return 0;
}
