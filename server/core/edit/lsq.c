#include "lsq.h"

#include <cholmod.h>
#include <stdlib.h>
#include <string.h>

struct ag_lsq {
    cholmod_common c;
    cholmod_sparse *at;  /* A' (ncols x nrows): CHOLMOD factorizes At * At' = A'A from it */
    cholmod_factor *L;
    cholmod_dense *b, *rhs;
    size_t nrows, ncols;
};

void ag_lsq_free(ag_lsq *s)
{
    if (!s)
        return;
    cholmod_free_sparse(&s->at, &s->c);
    cholmod_free_factor(&s->L, &s->c);
    cholmod_free_dense(&s->b, &s->c);
    cholmod_free_dense(&s->rhs, &s->c);
    cholmod_finish(&s->c);
    free(s);
}

ag_status ag_lsq_create(size_t nrows, size_t ncols, size_t nnz, const uint32_t *rows,
                        const uint32_t *cols, const double *vals, ag_lsq **out, ag_error *err)
{
    *out = NULL;
    if (!ncols || nrows < ncols)
        return ag_error_set(err, AG_ERR_INVALID, 0,
                            "least squares: %zu equations cannot determine %zu unknowns",
                            nrows, ncols);
    if (nrows > INT32_MAX || ncols > INT32_MAX || nnz > INT32_MAX)
        return ag_error_set(err, AG_ERR_TOO_LARGE, 0, "least squares: system too large");
    ag_lsq *s = calloc(1, sizeof *s);
    if (!s)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    cholmod_start(&s->c);
    s->c.print = 0;
    s->c.error_handler = NULL;
    s->nrows = nrows;
    s->ncols = ncols;
    ag_status st = AG_ERR_NOMEM;
    /* A' as triplets: row = unknown, column = equation. */
    cholmod_triplet *T = cholmod_allocate_triplet(ncols, nrows, nnz, 0, CHOLMOD_REAL, &s->c);
    if (!T)
        goto fail;
    int *ti = T->i, *tj = T->j;
    double *tx = T->x;
    for (size_t k = 0; k < nnz; k++) {
        if (rows[k] >= nrows || cols[k] >= ncols) {
            cholmod_free_triplet(&T, &s->c);
            st = ag_error_set(err, AG_ERR_INVALID, (long)k + 1,
                              "least squares: entry %zu out of range", k);
            goto fail_set;
        }
        ti[k] = (int)cols[k];
        tj[k] = (int)rows[k];
        tx[k] = vals[k];
    }
    T->nnz = nnz;
    s->at = cholmod_triplet_to_sparse(T, nnz, &s->c);
    cholmod_free_triplet(&T, &s->c);
    if (!s->at)
        goto fail;
    s->L = cholmod_analyze(s->at, &s->c);
    if (!s->L)
        goto fail;
    if (!cholmod_factorize(s->at, s->L, &s->c) && s->c.status < CHOLMOD_OK)
        goto fail;
    if (s->c.status == CHOLMOD_NOT_POSDEF) {
        st = ag_error_set(err, AG_ERR_INVALID, 0,
                          "least squares: the equations do not determine every unknown");
        goto fail_set;
    }
    s->b = cholmod_allocate_dense(nrows, 1, nrows, CHOLMOD_REAL, &s->c);
    s->rhs = cholmod_allocate_dense(ncols, 1, ncols, CHOLMOD_REAL, &s->c);
    if (!s->b || !s->rhs)
        goto fail;
    *out = s;
    return AG_OK;
fail:
    st = s->c.status == CHOLMOD_OUT_OF_MEMORY || s->c.status == CHOLMOD_OK
             ? ag_error_set(err, AG_ERR_NOMEM, 0, "least squares: out of memory")
             : ag_error_set(err, AG_ERR_INTERNAL, 0, "least squares: CHOLMOD status %d",
                            s->c.status);
fail_set:
    ag_lsq_free(s);
    return st;
}

ag_status ag_lsq_solve(ag_lsq *s, const double *b, double *x, ag_error *err)
{
    memcpy(s->b->x, b, s->nrows * sizeof *b);
    double one[2] = {1, 0}, zero[2] = {0, 0};
    /* rhs = A' b */
    if (!cholmod_sdmult(s->at, 0, one, zero, s->b, s->rhs, &s->c))
        return ag_error_set(err, AG_ERR_INTERNAL, 0, "least squares: product failed");
    cholmod_dense *sol = cholmod_solve(CHOLMOD_A, s->L, s->rhs, &s->c);
    if (!sol)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "least squares: out of memory");
    memcpy(x, sol->x, s->ncols * sizeof *x);
    cholmod_free_dense(&sol, &s->c);
    return AG_OK;
}

size_t ag_lsq_rows(const ag_lsq *s) { return s->nrows; }
size_t ag_lsq_cols(const ag_lsq *s) { return s->ncols; }
