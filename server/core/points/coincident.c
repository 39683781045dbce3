#include "coincident.h"

#include <stdlib.h>

#include "../base/uf.h"

typedef struct {
    ag_uf *uf;
    uint32_t self;
    unsigned visited;
} visit_ctx;

static int join(void *user, uint32_t id, double d2)
{
    (void)d2;
    visit_ctx *v = user;
    if (id != v->self)
        ag_uf_union(v->uf, v->self, id);
    return ++v->visited >= AG_COINCIDENT_MAX_VISIT;
}

ag_status ag_coincident_points(const ag_kdtree *tree, const double *xyz, size_t n, double tol,
                               uint32_t *rep, size_t *ndistinct, ag_error *err)
{
    ag_uf uf;
    ag_status st = ag_uf_init(&uf, n, 0);
    uint32_t *smallest = st == AG_OK ? malloc((n ? n : 1) * sizeof *smallest) : NULL;
    if (!smallest) {
        if (st == AG_OK)
            ag_uf_free(&uf);
        return ag_error_set(err, st == AG_OK ? AG_ERR_NOMEM : st, 0,
                            "%zu points are too many to compare", n);
    }
    const uint32_t *order = ag_kdtree_order(tree);
    for (size_t k = 0; k < n; k++) {
        visit_ctx v = {&uf, order[k], 0};
        ag_kdtree_radius(tree, xyz + 3 * (size_t)order[k], tol, join, &v);
    }
    /* the smallest point of each set stands for it: the first copy in the file */
    for (size_t i = 0; i < n; i++)
        smallest[i] = UINT32_MAX;
    size_t distinct = 0;
    for (size_t i = 0; i < n; i++) {
        uint32_t r = ag_uf_find(&uf, (uint32_t)i);
        if (smallest[r] == UINT32_MAX) {
            smallest[r] = (uint32_t)i; /* i ascends: the first member met is the smallest */
            distinct++;
        }
        rep[i] = smallest[r];
    }
    free(smallest);
    ag_uf_free(&uf);
    if (ndistinct)
        *ndistinct = distinct;
    return AG_OK;
}
