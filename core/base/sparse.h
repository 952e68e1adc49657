/* sparse.h — the sparse symmetric solver interface core/ calls and api/
 * implements (api/solver/sparse_cholmod.c: SuiteSparse CHOLMOD).  core/ stays plain
 * C17: it assembles a triplet matrix and receives the solver as a vtable
 * (data flows api → core). */
#ifndef PK_SPARSE_H
#define PK_SPARSE_H

#include <stddef.h>
#include <stdint.h>

/* Symmetric n×n matrix, upper triangle (row <= col) as triplets;
 * duplicates are summed. */
typedef struct pk_sparse_sym {
    size_t n, nnz, cap;
    int32_t *row, *col;
    double *val;
} pk_sparse_sym;

int pk_sparse_sym_add(pk_sparse_sym *A, int32_t r, int32_t c, double v); /* 0 / -1 */
void pk_sparse_sym_free(pk_sparse_sym *A);
/* y = A x (A symmetric, stored as its upper triangle). */
void pk_sparse_sym_mv(const pk_sparse_sym *A, const double *x, double *y);

typedef enum pk_sparse_status {
    PK_SPARSE_OK = 0,     /* positive definite */
    PK_SPARSE_INDEFINITE, /* negative pivots (inertia reported) */
    PK_SPARSE_SINGULAR,   /* zero pivot(s) */
    PK_SPARSE_FAILED,     /* memory or library error */
    PK_SPARSE_NOT_PD      /* not positive definite, inertia not computed (factor_pd) */
} pk_sparse_status;

const char *pk_sparse_status_name(pk_sparse_status s);

typedef struct pk_sparse_info {
    pk_sparse_status status;
    size_t npos, nneg, nzero; /* inertia of the LDLᵀ pivots */
    double min_abs_pivot, max_abs_pivot;
    int reused_analysis; /* factor_pd_ctx: 1 = the context's analysis was used */
} pk_sparse_info;

typedef struct pk_sparse_factor pk_sparse_factor; /* solver-owned */
/* A solver context kept over a sequence of factorisations (a relaxation, or
 * the steps of a load path):
 * it keeps the last symbolic analysis (fill-reducing ordering, pattern of L)
 * and reuses it when the next matrix has the same pattern — the same
 * ordering gives the same numbers, bit for bit. */
typedef struct pk_sparse_ctx pk_sparse_ctx; /* solver-owned */

typedef struct pk_sparse_solver {
    const char *name;
    /* Factor A; never NULL-crash: on failure returns NULL with info->status
     * = FAILED.  A factor is returned for OK and INDEFINITE. */
    pk_sparse_factor *(*factor)(const pk_sparse_sym *A, pk_sparse_info *info);
    /* Factor A only if it is positive definite (Newton's question): NULL with
     * info->status = NOT_PD otherwise, and no inertia. */
    pk_sparse_factor *(*factor_pd)(const pk_sparse_sym *A, pk_sparse_info *info);
    /* factor_pd with a context (NULL: the same as factor_pd): the analysis
     * of the context is used when A has its pattern, else A is analysed and
     * its analysis replaces the context's.  The factor outlives ctx. */
    pk_sparse_factor *(*factor_pd_ctx)(pk_sparse_ctx *ctx, const pk_sparse_sym *A,
                                       pk_sparse_info *info);
    pk_sparse_ctx *(*ctx_new)(void);      /* NULL on failure (then use factor_pd) */
    void (*ctx_free)(pk_sparse_ctx *ctx); /* NULL-safe */
    /* X = A⁻¹B, B and X column-major n × nrhs.  0 / -1. */
    int (*solve)(pk_sparse_factor *f, size_t nrhs, const double *B, double *X);
    void (*release)(pk_sparse_factor *f);
} pk_sparse_solver;

#endif
