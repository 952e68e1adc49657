/* The solver context of core/base/sparse.h (api/solver/sparse_cholmod.c): a factor made
 * with the context's reused analysis must be the factor a fresh analysis
 * gives — same ordering, same supernodes, hence the same numbers.  Compared
 * with == (no tolerance): the context may not change the result by a bit. */
#include <stdlib.h>
#include <string.h>

#include "../check.h"
#include "core/base/rng.h"
#include "api/solver/sparse_cholmod.h"

/* A 2D spring network like Newton's blocks: m×m nodes of 2 DOFs on a
 * periodic grid, each node joined to its right, upper and (when `diag`)
 * upper-right neighbour by a spring of random direction and stiffness
 * (Gauss–Newton k n⊗n) plus `shift` on the diagonal (positive definite for
 * shift > 0, indefinite for shift < −(largest spring eigenvalue)).  The
 * pattern depends on m and diag only; the values on the seed. */
static void spring_block(int m, int diag, double shift, uint64_t seed, pk_sparse_sym *A)
{
    pk_rng g;
    pk_rng_seed(&g, seed, 0);
    *A = (pk_sparse_sym){.n = (size_t)(2 * m * m)};
    for (int i = 0; i < m; i++)
        for (int j = 0; j < m; j++) {
            int32_t a = (int32_t)(i * m + j);
            int32_t nb[3] = {(int32_t)(i * m + (j + 1) % m), (int32_t)(((i + 1) % m) * m + j),
                             (int32_t)(((i + 1) % m) * m + (j + 1) % m)};
            pk_sparse_sym_add(A, 2 * a, 2 * a, shift);
            pk_sparse_sym_add(A, 2 * a + 1, 2 * a + 1, shift);
            for (int e = 0; e < 2 + diag; e++) {
                double t = pk_rng_range(&g, 0, 2 * M_PI), k = pk_rng_range(&g, 0.5, 2);
                double n[2] = {cos(t), sin(t)};
                int32_t b = nb[e];
                for (int p = 0; p < 2; p++)
                    for (int q = 0; q < 2; q++) {
                        double v = k * n[p] * n[q];
                        if (p <= q) { /* the diagonal blocks' upper triangles */
                            pk_sparse_sym_add(A, 2 * a + p, 2 * a + q, v);
                            pk_sparse_sym_add(A, 2 * b + p, 2 * b + q, v);
                        }
                        pk_sparse_sym_add(A, 2 * a + p, 2 * b + q, -v); /* coupling a–b */
                    }
            }
        }
}

/* 1 when the solves of f and g for the same right-hand side are equal (==). */
static int same_solution(pk_sparse_factor *f, pk_sparse_factor *g, size_t n)
{
    double *b = malloc(n * sizeof *b), *x = malloc(n * sizeof *x), *y = malloc(n * sizeof *y);
    int same = b && x && y;
    for (size_t k = 0; same && k < n; k++)
        b[k] = cos(0.37 * (double)k) + 0.1;
    same = same && pk_sparse_cholmod.solve(f, 1, b, x) == 0 &&
        pk_sparse_cholmod.solve(g, 1, b, y) == 0 && memcmp(x, y, n * sizeof *x) == 0;
    free(b), free(x), free(y);
    return same;
}

/* Factor A fresh and through ctx; CHECK they are equal and return whether
 * the context's analysis was reused. */
static int factor_both(pk_sparse_ctx *ctx, const pk_sparse_sym *A, pk_sparse_status want)
{
    pk_sparse_info fi, ci;
    pk_sparse_factor *f = pk_sparse_cholmod.factor_pd(A, &fi);
    pk_sparse_factor *g = pk_sparse_cholmod.factor_pd_ctx(ctx, A, &ci);
    CHECK_MSG(fi.status == want && ci.status == want, "status %s / %s, expected %s",
              pk_sparse_status_name(fi.status), pk_sparse_status_name(ci.status),
              pk_sparse_status_name(want));
    if (want == PK_SPARSE_OK) {
        CHECK(f && g);
        CHECK(fi.min_abs_pivot == ci.min_abs_pivot && fi.max_abs_pivot == ci.max_abs_pivot);
        CHECK(f && g && same_solution(f, g, A->n));
    } else {
        CHECK(!f && !g);
    }
    pk_sparse_cholmod.release(f);
    pk_sparse_cholmod.release(g);
    return ci.reused_analysis;
}

/* A sequence like a relaxation's: new pattern (analysed), same pattern with
 * other values (reused, == the fresh factor), a changed pattern (analysed
 * again, ==), back to the first pattern (analysed: the context keeps one),
 * a not positive definite block with that pattern (NOT_PD like
 * factor_pd), then a positive definite one after it (the analysis is kept
 * through the NOT_PD answer). */
static void test_reuse_bit_identical(void)
{
    const int m = 30;
    pk_sparse_ctx *ctx = pk_sparse_cholmod.ctx_new();
    CHECK(ctx != NULL);
    if (!ctx)
        return;
    pk_sparse_sym A1, A2, B, C, D;
    spring_block(m, 1, 1e-3, 1, &A1);
    spring_block(m, 1, 1e-3, 2, &A2);
    spring_block(m, 0, 1e-3, 3, &B);
    spring_block(m, 1, -50, 4, &C);
    spring_block(m, 1, 1e-2, 5, &D);
    CHECK(A1.nnz == A2.nnz && memcmp(A1.row, A2.row, A1.nnz * sizeof *A1.row) == 0 &&
          memcmp(A1.col, A2.col, A1.nnz * sizeof *A1.col) == 0 && A1.val[7] != A2.val[7]);
    CHECK(factor_both(ctx, &A1, PK_SPARSE_OK) == 0);
    CHECK(factor_both(ctx, &A2, PK_SPARSE_OK) == 1);
    CHECK(factor_both(ctx, &B, PK_SPARSE_OK) == 0);
    CHECK(factor_both(ctx, &A1, PK_SPARSE_OK) == 0);
    CHECK(factor_both(ctx, &C, PK_SPARSE_NOT_PD) == 1);
    CHECK(factor_both(ctx, &D, PK_SPARSE_OK) == 1);
    pk_sparse_cholmod.ctx_free(ctx);
    pk_sparse_cholmod.ctx_free(NULL);
    pk_sparse_sym *all[] = {&A1, &A2, &B, &C, &D};
    for (size_t k = 0; k < sizeof all / sizeof *all; k++)
        pk_sparse_sym_free(all[k]);
}

/* A factor outlives the context that made it (Newton releases its last
 * factor after the relaxation's context may be gone). */
static void test_factor_outlives_ctx(void)
{
    pk_sparse_sym A;
    spring_block(12, 1, 1e-2, 7, &A);
    pk_sparse_ctx *ctx = pk_sparse_cholmod.ctx_new();
    pk_sparse_info ci, fi;
    pk_sparse_factor *g = ctx ? pk_sparse_cholmod.factor_pd_ctx(ctx, &A, &ci) : NULL;
    pk_sparse_cholmod.ctx_free(ctx);
    pk_sparse_factor *f = pk_sparse_cholmod.factor_pd(&A, &fi);
    CHECK(g && f && same_solution(f, g, A.n));
    pk_sparse_cholmod.release(f);
    pk_sparse_cholmod.release(g);
    pk_sparse_sym_free(&A);
}

int main(void)
{
    RUN(test_reuse_bit_identical);
    RUN(test_factor_outlives_ctx);
    return check_summary();
}
