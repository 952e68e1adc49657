#include "sparse_cholmod.h"

#include <cholmod.h>
#include <math.h>
#include <stdlib.h>

struct pk_sparse_factor {
    cholmod_common c;
    cholmod_factor *L;
    size_t n;
};

/* |d| below this share of the largest pivot counts as zero (singular). */
#define ZERO_PIVOT_SHARE 1e-12

static pk_sparse_factor *chol_factor(const pk_sparse_sym *A, pk_sparse_info *info)
{
    info->status = PK_SPARSE_FAILED;
    info->npos = info->nneg = info->nzero = 0;
    info->min_abs_pivot = info->max_abs_pivot = 0;
    pk_sparse_factor *f = calloc(1, sizeof *f);
    if (!f)
        return NULL;
    cholmod_start(&f->c);
    f->c.print = 0;
    f->c.error_handler = NULL;
    f->c.supernodal = CHOLMOD_SIMPLICIAL;
    f->c.final_ll = 0; /* keep LDLᵀ: D carries the inertia */
    f->n = A->n;
    cholmod_triplet *T = cholmod_allocate_triplet(A->n, A->n, A->nnz ? A->nnz : 1, 1, CHOLMOD_REAL, &f->c);
    cholmod_sparse *S = NULL;
    if (!T)
        goto fail;
    int *ti = T->i, *tj = T->j;
    double *tx = T->x;
    for (size_t k = 0; k < A->nnz; k++) {
        ti[k] = A->row[k];
        tj[k] = A->col[k];
        tx[k] = A->val[k];
    }
    T->nnz = A->nnz;
    S = cholmod_triplet_to_sparse(T, A->nnz, &f->c);
    cholmod_free_triplet(&T, &f->c);
    if (!S)
        goto fail;
    f->L = cholmod_analyze(S, &f->c);
    if (!f->L)
        goto fail;
    cholmod_factorize(S, f->L, &f->c);
    cholmod_free_sparse(&S, &f->c);
    if (f->c.status < 0)
        goto fail;
    const int *Lp = f->L->p;
    const double *Lx = f->L->x;
    double dmax = 0, dmin = INFINITY;
    size_t ncol = f->L->minor < A->n ? f->L->minor : A->n;
    for (size_t j = 0; j < ncol; j++)
        dmax = fmax(dmax, fabs(Lx[Lp[j]]));
    for (size_t j = 0; j < ncol; j++) {
        double d = Lx[Lp[j]];
        dmin = fmin(dmin, fabs(d));
        if (fabs(d) <= ZERO_PIVOT_SHARE * dmax)
            info->nzero++;
        else if (d < 0)
            info->nneg++;
        else
            info->npos++;
    }
    info->nzero += A->n - ncol; /* factorization stopped at a zero pivot */
    info->min_abs_pivot = ncol ? dmin : 0;
    info->max_abs_pivot = dmax;
    info->status = info->nzero ? PK_SPARSE_SINGULAR
                               : info->nneg ? PK_SPARSE_INDEFINITE : PK_SPARSE_OK;
    if (info->status == PK_SPARSE_SINGULAR)
        goto fail_keep_status;
    return f;
fail:
    info->status = PK_SPARSE_FAILED;
fail_keep_status:
    if (S)
        cholmod_free_sparse(&S, &f->c);
    if (f->L)
        cholmod_free_factor(&f->L, &f->c);
    cholmod_finish(&f->c);
    free(f);
    return NULL;
}

static int chol_solve(pk_sparse_factor *f, size_t nrhs, const double *B, double *X)
{
    cholmod_dense *b = cholmod_allocate_dense(f->n, nrhs, f->n, CHOLMOD_REAL, &f->c);
    if (!b)
        return -1;
    double *bx = b->x;
    for (size_t k = 0; k < f->n * nrhs; k++)
        bx[k] = B[k];
    cholmod_dense *x = cholmod_solve(CHOLMOD_A, f->L, b, &f->c);
    cholmod_free_dense(&b, &f->c);
    if (!x)
        return -1;
    const double *xx = x->x;
    for (size_t k = 0; k < f->n * nrhs; k++)
        X[k] = xx[k];
    cholmod_free_dense(&x, &f->c);
    return 0;
}

static void chol_release(pk_sparse_factor *f)
{
    if (!f)
        return;
    cholmod_free_factor(&f->L, &f->c);
    cholmod_finish(&f->c);
    free(f);
}

const pk_sparse_solver pk_sparse_cholmod = {
    .name = "cholmod-ldlt",
    .factor = chol_factor,
    .solve = chol_solve,
    .release = chol_release,
};
