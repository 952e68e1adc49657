/* sparse.c — the symmetric triplet matrix core/ assembles for the sparse
 * solver api/ provides.  Contract: core/base/sparse.h. */
#include "sparse.h"

#include <stdlib.h>
#include <string.h>

int pk_sparse_sym_add(pk_sparse_sym *A, int32_t r, int32_t c, double v)
{
    if (r > c) {
        int32_t t = r;
        r = c;
        c = t;
    }
    if (A->nnz == A->cap) {
        size_t cap = A->cap ? 2 * A->cap : 4096;
        int32_t *nr = realloc(A->row, cap * sizeof *nr);
        if (nr)
            A->row = nr;
        int32_t *nc = realloc(A->col, cap * sizeof *nc);
        if (nc)
            A->col = nc;
        double *nv = realloc(A->val, cap * sizeof *nv);
        if (nv)
            A->val = nv;
        if (!nr || !nc || !nv)
            return -1;
        A->cap = cap;
    }
    A->row[A->nnz] = r;
    A->col[A->nnz] = c;
    A->val[A->nnz] = v;
    A->nnz++;
    return 0;
}

void pk_sparse_sym_free(pk_sparse_sym *A)
{
    free(A->row);
    free(A->col);
    free(A->val);
    memset(A, 0, sizeof *A);
}

void pk_sparse_sym_mv(const pk_sparse_sym *A, const double *x, double *y)
{
    memset(y, 0, A->n * sizeof *y);
    for (size_t k = 0; k < A->nnz; k++) {
        int32_t r = A->row[k], c = A->col[k];
        y[r] += A->val[k] * x[c];
        if (r != c)
            y[c] += A->val[k] * x[r];
    }
}

const char *pk_sparse_status_name(pk_sparse_status s)
{
    switch (s) {
    case PK_SPARSE_OK: return "positive_definite";
    case PK_SPARSE_INDEFINITE: return "indefinite";
    case PK_SPARSE_SINGULAR: return "singular";
    case PK_SPARSE_FAILED: return "failed";
    case PK_SPARSE_NOT_PD: return "not_positive_definite";
    }
    return "unknown";
}
