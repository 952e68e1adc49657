/* sparse_cholmod.c — core/base/sparse.h's solver with SuiteSparse CHOLMOD:
 * simplicial LDLᵀ (no BLAS: the same bits on every CPU), the inertia from D.
 * Contract: sparse_cholmod.h. */
#include "sparse_cholmod.h"

#include <cholmod.h>
#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

/* Debian's CHOLMOD is built with OpenMP: some of its loops open a team of
 * up to 4 threads (num_threads clauses) — small ones on packd's blocks, so a
 * team costs more to start, and its threads more in spinning (libgomp spins
 * before it sleeps, on the cores the relaxation and the speculative attempts
 * use), than it gives (near-jamming 10⁴ bench/homog step: −25..−30 % time
 * with a team of one; docs/perf/sparse.md).  So every entry point makes the
 * calling thread's parallel regions inactive (max-active-levels 0: a team
 * of one; the ICV is per thread, so each thread that calls in sets its own
 * — a few ns).  The numbers do not change (the same operations, in one
 * thread). */
static void serial_regions(void) { omp_set_max_active_levels(0); }

struct pk_sparse_factor {
    cholmod_common c;
    cholmod_factor *L;
    size_t n;
};

/* The last analysis (symbolic factor, pattern only) and the
 * column pattern of the matrix it was made for. */
struct pk_sparse_ctx {
    cholmod_common c;
    cholmod_factor *L; /* NULL: none yet */
    size_t n, nnz;
    int *p, *i; /* n + 1 column pointers, nnz row indices (packed, sorted) */
};

/* |d| below this share of the largest pivot counts as zero (singular). */
#define ZERO_PIVOT_SHARE 1e-12

/* Classify pivots d_j (LDLᵀ's D, or L_jj² of an LLᵀ factor) into the inertia
 * of info; |d| ≤ ZERO_PIVOT_SHARE·max|d| counts as zero. */
static void classify_pivots(const double *d, size_t ncol, size_t n, pk_sparse_info *info)
{
    double dmax = 0, dmin = INFINITY;
    for (size_t j = 0; j < ncol; j++)
        dmax = fmax(dmax, fabs(d[j]));
    for (size_t j = 0; j < ncol; j++) {
        dmin = fmin(dmin, fabs(d[j]));
        if (fabs(d[j]) <= ZERO_PIVOT_SHARE * dmax)
            info->nzero++;
        else if (d[j] < 0)
            info->nneg++;
        else
            info->npos++;
    }
    info->nzero += n - ncol; /* factorization stopped at a zero pivot */
    info->min_abs_pivot = ncol ? dmin : 0;
    info->max_abs_pivot = dmax;
    info->status = info->nzero ? PK_SPARSE_SINGULAR
        : info->nneg           ? PK_SPARSE_INDEFINITE
                               : PK_SPARSE_OK;
}

/* Analyse S afresh (AMD) into f->L and factorise it as simplicial LDLᵀ;
 * 0 when CHOLMOD ran (the factor may still stop early: L->minor < n). */
static int factorize_fresh(pk_sparse_factor *f, cholmod_sparse *S)
{
    f->L = cholmod_analyze(S, &f->c);
    if (!f->L)
        return -1;
    cholmod_factorize(S, f->L, &f->c);
    return f->c.status < 0 ? -1 : 0;
}

/* S has the pattern ctx's analysis was made for. */
static int same_pattern(const pk_sparse_ctx *ctx, const cholmod_sparse *S)
{
    const int *p = S->p;
    size_t n = S->ncol, nnz = (size_t)p[n];
    return ctx->L && n == ctx->n && nnz == ctx->nnz &&
        memcmp(p, ctx->p, (n + 1) * sizeof *p) == 0 &&
        memcmp(S->i, ctx->i, nnz * sizeof *ctx->i) == 0;
}

/* ctx's analysis := S's (0), or none (-1). */
static int analyse_into(pk_sparse_ctx *ctx, cholmod_sparse *S)
{
    cholmod_free_factor(&ctx->L, &ctx->c);
    const int *p = S->p;
    size_t n = S->ncol, nnz = (size_t)p[n];
    int *np_ = realloc(ctx->p, (n + 1) * sizeof *np_);
    if (np_)
        ctx->p = np_;
    int *ni = realloc(ctx->i, (nnz ? nnz : 1) * sizeof *ni);
    if (ni)
        ctx->i = ni;
    if (!np_ || !ni)
        return -1;
    ctx->L = cholmod_analyze(S, &ctx->c);
    if (!ctx->L)
        return -1;
    memcpy(ctx->p, p, (n + 1) * sizeof *p);
    memcpy(ctx->i, S->i, nnz * sizeof *ctx->i);
    ctx->n = n;
    ctx->nnz = nnz;
    return 0;
}

/* The LDLᵀ of S, analysed afresh (ctx NULL) or with ctx's analysis — the
 * same AMD ordering as a fresh analysis of the same pattern (cholmod_analyze
 * reads the pattern only), hence the same numbers. */
static int factorize(pk_sparse_ctx *ctx, pk_sparse_factor *f, cholmod_sparse *S,
                     pk_sparse_info *info)
{
    if (!ctx)
        return factorize_fresh(f, S);
    info->reused_analysis = same_pattern(ctx, S);
    if (!info->reused_analysis && analyse_into(ctx, S) != 0)
        return -1;
    f->L = cholmod_copy_factor(ctx->L, &f->c);
    if (!f->L)
        return -1;
    cholmod_factorize(S, f->L, &f->c);
    return f->c.status < 0 ? -1 : 0;
}

/* CHOLMOD's settings for every factor and analysis: simplicial LDLᵀ.  Its
 * arithmetic is CHOLMOD's own loops, in an order fixed by the ordering —
 * no BLAS call, so the numbers do not depend on which BLAS is installed or
 * which kernel OpenBLAS picks for the CPU (the supernodal LLᵀ's dense blocks
 * went through dgemm/dtrsm, whose rounding changes with the kernel: a
 * homogenization's tangent differed between CPUs).  The price and the
 * figures: docs/perf/sparse.md.  D carries the full inertia in one pass. */
static void simplicial_ldlt(cholmod_common *c)
{
    c->print = 0;
    c->error_handler = NULL;
    c->supernodal = CHOLMOD_SIMPLICIAL;
    c->final_ll = 0;
}

/* Factorise A as LDLᵀ; the inertia from D.  `pd_only` (factor_pd): a block
 * that is not positive definite gives NULL with NOT_PD and no inertia. */
static pk_sparse_factor *factor_any(pk_sparse_ctx *ctx, const pk_sparse_sym *A, int pd_only,
                                    pk_sparse_info *info)
{
    info->status = PK_SPARSE_FAILED;
    info->npos = info->nneg = info->nzero = 0;
    info->min_abs_pivot = info->max_abs_pivot = 0;
    info->reused_analysis = 0;
    serial_regions();
    pk_sparse_factor *f = calloc(1, sizeof *f);
    double *d = NULL;
    if (!f)
        return NULL;
    cholmod_start(&f->c);
    simplicial_ldlt(&f->c);
    f->n = A->n;
    cholmod_triplet *T =
        cholmod_allocate_triplet(A->n, A->n, A->nnz ? A->nnz : 1, 1, CHOLMOD_REAL, &f->c);
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
    d = malloc((A->n ? A->n : 1) * sizeof *d);
    if (!S || !d)
        goto fail;
    if (factorize(ctx, f, S, info) != 0)
        goto fail;
    const int *Lp = f->L->p;
    const double *Lx = f->L->x;
    size_t ncol = f->L->minor < A->n ? f->L->minor : A->n;
    for (size_t j = 0; j < ncol; j++)
        d[j] = Lx[Lp[j]]; /* D_jj: the first entry of column j */
    classify_pivots(d, ncol, A->n, info);
    if (info->status != PK_SPARSE_OK && pd_only) {
        info->status = PK_SPARSE_NOT_PD;
        info->npos = info->nneg = info->nzero = 0;
        goto fail_keep_status;
    }
    cholmod_free_sparse(&S, &f->c); /* sets S = NULL */
    free(d);
    d = NULL;
    if (info->status == PK_SPARSE_SINGULAR)
        goto fail_keep_status;
    return f;
fail:
    info->status = PK_SPARSE_FAILED;
fail_keep_status:
    if (S)
        cholmod_free_sparse(&S, &f->c);
    free(d);
    if (f->L)
        cholmod_free_factor(&f->L, &f->c);
    cholmod_finish(&f->c);
    free(f);
    return NULL;
}

static pk_sparse_factor *chol_factor(const pk_sparse_sym *A, pk_sparse_info *info)
{
    return factor_any(NULL, A, 0, info);
}

static pk_sparse_factor *chol_factor_pd(const pk_sparse_sym *A, pk_sparse_info *info)
{
    return factor_any(NULL, A, 1, info);
}

static pk_sparse_factor *chol_factor_pd_ctx(pk_sparse_ctx *ctx, const pk_sparse_sym *A,
                                            pk_sparse_info *info)
{
    return factor_any(ctx, A, 1, info);
}

static pk_sparse_ctx *chol_ctx_new(void)
{
    pk_sparse_ctx *ctx = calloc(1, sizeof *ctx);
    if (!ctx)
        return NULL;
    cholmod_start(&ctx->c);
    simplicial_ldlt(&ctx->c);
    return ctx;
}

static void chol_ctx_free(pk_sparse_ctx *ctx)
{
    if (!ctx)
        return;
    cholmod_free_factor(&ctx->L, &ctx->c);
    cholmod_finish(&ctx->c);
    free(ctx->p);
    free(ctx->i);
    free(ctx);
}

static int chol_solve(pk_sparse_factor *f, size_t nrhs, const double *B, double *X)
{
    serial_regions();
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
    .name = "cholmod",
    .factor = chol_factor,
    .factor_pd = chol_factor_pd,
    .factor_pd_ctx = chol_factor_pd_ctx,
    .ctx_new = chol_ctx_new,
    .ctx_free = chol_ctx_free,
    .solve = chol_solve,
    .release = chol_release,
};
