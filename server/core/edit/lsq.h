/* Sparse linear least squares min |A x - b|^2 by CHOLMOD on the normal equations.
 *
 * The factorization of A'A is kept, so solving again for a new right-hand side (a drag that
 * only moves targets) costs two triangular solves and one sparse product. A must have full
 * column rank (every unknown appears in some equation with independent coefficients);
 * otherwise creation fails with AG_ERR_INVALID. */
#ifndef AG_LSQ_H
#define AG_LSQ_H

#include <stddef.h>
#include <stdint.h>

#include "../status.h"

typedef struct ag_lsq ag_lsq;

/* A is nrows x ncols given as nnz triplets (duplicates add up); weights are folded in by
 * the caller. Analyses and factorizes A'A. */
ag_status ag_lsq_create(size_t nrows, size_t ncols, size_t nnz, const uint32_t *rows,
                        const uint32_t *cols, const double *vals, ag_lsq **out, ag_error *err);
void ag_lsq_free(ag_lsq *s);

/* x (ncols) = argmin |A x - b|, b has nrows entries. */
ag_status ag_lsq_solve(ag_lsq *s, const double *b, double *x, ag_error *err);

size_t ag_lsq_rows(const ag_lsq *s);
size_t ag_lsq_cols(const ag_lsq *s);

#endif
