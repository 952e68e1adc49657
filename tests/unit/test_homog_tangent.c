/* test_homog_tangent.c — Ā = dP̄/dF̄ by static condensation (Meier 2009 ch. 6), with the CHOLMOD solver injected from api/. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "homog_fixture.h"
#include "homog_fd.h"

/* The solver reports inertia: SPD solves, singular and indefinite flagged. */
static void test_sparse_solver_status(void)
{
    pk_sparse_sym A = {.n = 3};
    pk_sparse_sym_add(&A, 0, 0, 4), pk_sparse_sym_add(&A, 0, 1, 1), pk_sparse_sym_add(&A, 1, 1, 3);
    pk_sparse_sym_add(&A, 1, 2, 1), pk_sparse_sym_add(&A, 2, 2, 2),
        pk_sparse_sym_add(&A, 2, 2, 0.5);
    pk_sparse_info info;
    pk_sparse_factor *f = pk_sparse_cholmod.factor(&A, &info);
    CHECK(f && info.status == PK_SPARSE_OK && info.npos == 3);
    double b[3] = {1, 2, 3}, x[3];
    CHECK(f && pk_sparse_cholmod.solve(f, 1, b, x) == 0);
    /* residual of A x = b with A = [[4,1,0],[1,3,1],[0,1,2.5]] */
    CHECK_NEAR(4 * x[0] + x[1], 1, 1e-14);
    CHECK_NEAR(x[0] + 3 * x[1] + x[2], 2, 1e-14);
    CHECK_NEAR(x[1] + 2.5 * x[2], 3, 1e-14);
    pk_sparse_cholmod.release(f);
    pk_sparse_sym_free(&A);

    pk_sparse_sym S = {.n = 2}; /* [[1,1],[1,1]]: singular */
    pk_sparse_sym_add(&S, 0, 0, 1), pk_sparse_sym_add(&S, 0, 1, 1), pk_sparse_sym_add(&S, 1, 1, 1);
    f = pk_sparse_cholmod.factor(&S, &info);
    CHECK(!f && info.status == PK_SPARSE_SINGULAR);
    pk_sparse_sym_free(&S);

    pk_sparse_sym D = {.n = 2}; /* diag(1, −2): indefinite, inertia (1, 1, 0) */
    pk_sparse_sym_add(&D, 0, 0, 1), pk_sparse_sym_add(&D, 1, 1, -2);
    f = pk_sparse_cholmod.factor(&D, &info);
    CHECK(info.status == PK_SPARSE_INDEFINITE && info.nneg == 1 && info.npos == 1);
    pk_sparse_cholmod.release(f);
    pk_sparse_sym_free(&D);
}

/* 5-point Laplacian of an m×m periodic grid plus shift·1: big enough for
 * CHOLMOD to form real supernodes (the factor path of 10⁴-grain RVEs). */
static void grid_laplacian(int m, double shift, pk_sparse_sym *A)
{
    *A = (pk_sparse_sym){.n = (size_t)(m * m)};
    for (int i = 0; i < m; i++)
        for (int j = 0; j < m; j++) {
            int32_t k = (int32_t)(i * m + j);
            int32_t e = (int32_t)(i * m + (j + 1) % m), n = (int32_t)(((i + 1) % m) * m + j);
            pk_sparse_sym_add(A, k, k, 4 + shift);
            pk_sparse_sym_add(A, k < e ? k : e, k < e ? e : k, -1);
            pk_sparse_sym_add(A, k < n ? k : n, k < n ? n : k, -1);
        }
}

/* The supernodal LLᵀ path and its fallback: an SPD block solves to round-off
 * (residual 1e-12 of |b|: condition ≈ 8/shift = 800) with pivots read from
 * the supernodes (max/min ≤ the condition bound 8/shift); the unshifted
 * periodic Laplacian has exactly one zero eigenvalue (constants) and must be
 * reported singular (its last LLᵀ pivot is round-off: ~1e-15 of the largest,
 * below the 1e-12 share); shifted by minus half the smallest nonzero
 * eigenvalue 2(1−cos 2π/m) the block is indefinite with exactly one
 * negative pivot (inertia from the LDLᵀ refactorisation). */
static void test_sparse_solver_supernodal(void)
{
    const int m = 40;
    pk_sparse_sym A;
    pk_sparse_info info;
    grid_laplacian(m, 0.01, &A);
    pk_sparse_factor *f = pk_sparse_cholmod.factor(&A, &info);
    CHECK(f && info.status == PK_SPARSE_OK && info.npos == A.n && info.nneg == 0 &&
          info.nzero == 0);
    CHECK_MSG(info.min_abs_pivot > 0 && info.max_abs_pivot / info.min_abs_pivot < 8 / 0.01,
              "pivots %g .. %g", info.min_abs_pivot, info.max_abs_pivot);
    double *b = malloc(A.n * sizeof *b), *x = malloc(A.n * sizeof *x),
           *Ax = calloc(A.n, sizeof *Ax);
    for (size_t k = 0; k < A.n; k++)
        b[k] = sin(0.37 * (double)k) + 0.1;
    CHECK(f && pk_sparse_cholmod.solve(f, 1, b, x) == 0);
    for (size_t k = 0; k < A.nnz; k++) {
        Ax[A.row[k]] += A.val[k] * x[A.col[k]];
        if (A.row[k] != A.col[k])
            Ax[A.col[k]] += A.val[k] * x[A.row[k]];
    }
    double res = 0, nb = 0;
    for (size_t k = 0; k < A.n; k++)
        res += (Ax[k] - b[k]) * (Ax[k] - b[k]), nb += b[k] * b[k];
    CHECK_MSG(sqrt(res / nb) < 1e-12, "relative residual %g", sqrt(res / nb));
    pk_sparse_cholmod.release(f);
    pk_sparse_sym_free(&A);

    grid_laplacian(m, 0, &A);
    f = pk_sparse_cholmod.factor(&A, &info);
    CHECK_MSG(!f && info.status == PK_SPARSE_SINGULAR && info.nzero >= 1, "status %d nzero %zu",
              (int)info.status, info.nzero);
    pk_sparse_sym_free(&A);

    double lam1 = 2 * (1 - cos(2 * M_PI / m)); /* smallest nonzero eigenvalue (4-fold) */
    grid_laplacian(m, -0.5 * lam1, &A);
    f = pk_sparse_cholmod.factor(&A, &info);
    CHECK_MSG(info.status == PK_SPARSE_INDEFINITE && info.nneg == 1 && info.npos == A.n - 1,
              "status %d inertia %zu/%zu/%zu", (int)info.status, info.npos, info.nneg, info.nzero);
    pk_sparse_cholmod.release(f);
    pk_sparse_sym_free(&A);
    free(b), free(x), free(Ax);
}

/* factor_pd (Newton's question) agrees with factor on "positive definite?"
 * for the SPD, singular and indefinite blocks above, returns a factor that
 * solves like factor's for the SPD one (the same supernodal LLᵀ: equal to
 * round-off, 1e-14 relative), and nothing with status NOT_PD otherwise. */
static void test_sparse_solver_pd_only(void)
{
    const int m = 40;
    const double lam1 = 2 * (1 - cos(2 * M_PI / m));
    const double shifts[3] = {0.01, 0, -0.5 * lam1};
    for (int t = 0; t < 3; t++) {
        pk_sparse_sym A;
        pk_sparse_info full, pd;
        grid_laplacian(m, shifts[t], &A);
        pk_sparse_factor *f = pk_sparse_cholmod.factor(&A, &full);
        pk_sparse_factor *g = pk_sparse_cholmod.factor_pd(&A, &pd);
        CHECK_MSG((full.status == PK_SPARSE_OK) == (pd.status == PK_SPARSE_OK),
                  "shift %g: %s vs %s", shifts[t], pk_sparse_status_name(full.status),
                  pk_sparse_status_name(pd.status));
        if (t == 0) {
            double *b = malloc(A.n * sizeof *b), *x = malloc(A.n * sizeof *x),
                   *y = malloc(A.n * sizeof *y);
            for (size_t k = 0; k < A.n; k++)
                b[k] = cos(0.21 * (double)k);
            CHECK(f && g && pk_sparse_cholmod.solve(f, 1, b, x) == 0 &&
                  pk_sparse_cholmod.solve(g, 1, b, y) == 0);
            double d = 0, nx = 0;
            for (size_t k = 0; k < A.n; k++)
                d += (x[k] - y[k]) * (x[k] - y[k]), nx += x[k] * x[k];
            CHECK_MSG(sqrt(d / nx) < 1e-14, "factor vs factor_pd solution %g", sqrt(d / nx));
            free(b), free(x), free(y);
        } else {
            CHECK(!g && pd.status == PK_SPARSE_NOT_PD);
        }
        pk_sparse_cholmod.release(f);
        pk_sparse_cholmod.release(g);
        pk_sparse_sym_free(&A);
    }
}

/* Remark 6.1 analytically: A_1111 = A_2222 = E√N/(√N−1), all else 0
 * (basis erratum of (6.10)).  Exact formula: tolerance 1e-12 relative. */
static void test_square_lattice_tangent(void)
{
    for (int m = 2; m <= 10; m += 2) {
        size_t n = (size_t)(m * m);
        double *X = calloc(3 * n, sizeof *X), *r = malloc(n * sizeof *r);
        uint8_t *fx = malloc(n);
        for (size_t i = 0; i < n; i++) {
            X[3 * i] = 2.0 * (double)(i % (size_t)m) + 5,
                  X[3 * i + 1] = 2.0 * (double)(i / (size_t)m) - 3;
            r[i] = 1, fx[i] = 1;
        }
        pk_homog_rve rve;
        pk_homog_rve_from_arrays(2, PK_BC_TAYLOR, n, X, r, fx, 0, NULL, 4.0 * (m - 1) * (m - 1),
                                 &rve);
        pk_homog_opts o = opts(1);
        o.E_n = 50;
        pk_homog_state s0;
        pk_homog_state_init(&rve, &o, &s0);
        double A[81];
        pk_tangent_info info;
        CHECK(pk_homog_tangent(&rve, &o, &s0, &pk_sparse_cholmod, A, &info) == 0);
        double want = o.E_n * m / (m - 1.0);
        for (int I = 0; I < 9; I++)
            for (int J = 0; J < 9; J++) {
                double w = (I == J && (I == 0 || I == 4)) ? want : 0; /* 1111, 2222 */
                CHECK_NEAR(A[9 * I + J], w, 1e-12 * want);
            }
        pk_homog_state_free(&s0);
        pk_homog_rve_free(&rve);
        free(X), free(r), free(fx);
    }
}

/* Ā vs central differences of P̄ (each perturbed state relaxed from the same
 * committed state, fixed topology checked) for every BC, 2D and 3D; major
 * symmetry.  h = 1e-6, DR tol 1e-12: FD truncation O(h²·|A'|), P̄ error from
 * the relaxation residual ~1e-13 → relative error ≪ 1e-6 (required). */
static void test_tangent_vs_finite_differences(void)
{
    for (int dim = 2; dim <= 3; dim++) {
        pk_box b;
        pk_particles p;
        make_jammed(dim, dim == 2 ? 90 : 50, dim == 2 ? 0.88 : 0.68, 21, &b, &p);
        for (int bc = 0; bc < 3; bc++) {
            fixture fx;
            double F0[9];
            diagF(F0, 0.994, 1.0, 1.0);
            F0[3] = -0.004;
            fixture_make(&fx, &b, &p, (pk_homog_bc)bc, F0);
            double A[81];
            pk_tangent_info info;
            int rc = pk_homog_tangent(&fx.rve, &fx.o, &fx.s, &pk_sparse_cholmod, A, &info);
            CHECK_MSG(rc == 0, "dim %d bc %d: rc %d block %s", dim, bc, rc,
                      pk_sparse_status_name(info.block.status));
            int skipped = 0;
            double asym = 0, An = 0;
            double worst = fd_tangent_error(&fx, F0, dim, A, &info, &skipped, &asym, &An);
            CHECK(skipped <= 1); /* at most one F̄ component hits a switching contact */
            CHECK_MSG(worst < 1e-6, "dim %d %s: FD rel. error %g", dim,
                      pk_homog_bc_name((pk_homog_bc)bc), worst);
            CHECK_MSG(asym < 1e-12, "major symmetry defect %g", asym);
            printf("  dim %d %-17s |A| %.4g  FD rel. error %.2e  symmetry %.1e  free dofs %zu  "
                   "skipped %d\n",
                   dim, pk_homog_bc_name((pk_homog_bc)bc), An, worst, asym, info.free_dofs,
                   skipped);
            fixture_free(&fx);
        }
        pk_particles_free(&p);
    }
}

/* §9.3 at the tangent level: more constraints, stiffer — Taylor ≥ restricted
 * Taylor ≥ periodic for the compression modulus Ā_1111 of one RVE. */
static void test_constraint_ranking(void)
{
    pk_box b;
    pk_particles p;
    make_jammed(2, 150, 0.88, 31, &b, &p);
    double a1111[3];
    for (int bc = 0; bc < 3; bc++) {
        fixture fx;
        double F0[9];
        diagF(F0, 0.995, 0.995, 1);
        fixture_make(&fx, &b, &p, (pk_homog_bc)bc, F0);
        double A[81];
        pk_tangent_info info;
        CHECK(pk_homog_tangent(&fx.rve, &fx.o, &fx.s, &pk_sparse_cholmod, A, &info) == 0);
        a1111[bc] = A[0];
        fixture_free(&fx);
    }
    CHECK_MSG(a1111[0] > a1111[1] && a1111[1] > a1111[2], "A1111: T %g RT %g P %g", a1111[0],
              a1111[1], a1111[2]);
    pk_particles_free(&p);
}

/* A free block with a rigid mode is reported, not inverted: periodic RVE
 * without the pinned grain. */
static void test_singular_block_reported(void)
{
    pk_box b;
    pk_particles p;
    make_jammed(2, 60, 0.88, 41, &b, &p);
    fixture fx;
    double F0[9];
    diagF(F0, 0.995, 0.995, 1);
    fixture_make(&fx, &b, &p, PK_BC_PERIODIC, F0);
    fx.rve.fixed[0] = 0; /* unpin: translation is free */
    double A[81] = {0};
    pk_tangent_info info;
    CHECK(pk_homog_tangent(&fx.rve, &fx.o, &fx.s, &pk_sparse_cholmod, A, &info) == 1);
    CHECK(info.block.status == PK_SPARSE_SINGULAR);
    CHECK(A[0] == 0); /* untouched */
    fixture_free(&fx);
    pk_particles_free(&p);
}

/* Newton–Raphson (with line search, DR fallback/polish) reaches the same
 * equilibrium as dynamic relaxation: P̄ agrees to 1e-8 relative (both solved
 * to 1e-12), in a handful of Newton steps. */
static void test_newton_matches_dr(void)
{
    for (int dim = 2; dim <= 3; dim++) {
        pk_box b;
        pk_particles p;
        make_jammed(dim, dim == 2 ? 120 : 60, dim == 2 ? 0.88 : 0.68, 51, &b, &p);
        for (int bc = 1; bc < 3; bc++) {
            fixture fx;
            double F0[9], F1[9];
            diagF(F0, 0.996, 1.0, 1.0);
            fixture_make(&fx, &b, &p, (pk_homog_bc)bc, F0);
            diagF(F1, 0.993, 1.0, 1.0);
            F1[1] = 0.002;
            pk_homog_state t1 = {0}, t2 = {0};
            pk_homog_step sd, sn;
            CHECK(pk_homog_eval(&fx.rve, &fx.o, &fx.s, F1, &t1, &sd, NULL) == 0);
            pk_homog_opts on = fx.o;
            on.newton = &pk_sparse_cholmod;
            on.newton_max_iter = 50;
            CHECK(pk_homog_eval(&fx.rve, &on, &fx.s, F1, &t2, &sn, NULL) == 0);
            CHECK(sn.used_newton && pk_dr_stop_ok(sn.dr.stop) && pk_dr_stop_ok(sd.dr.stop));
            CHECK_MSG(sn.newton.iterations <= 20, "%zu Newton steps", sn.newton.iterations);
            double Pn = 0, d = 0;
            for (int k = 0; k < 9; k++) {
                Pn = fmax(Pn, fabs(sd.P[k]));
                d = fmax(d, fabs(sd.P[k] - sn.P[k]));
            }
            CHECK_MSG(d <= 1e-8 * Pn, "dim %d bc %d: |ΔP|/|P| = %g", dim, bc, d / Pn);
            printf("  dim %d %-17s DR %zu it, Newton %zu it (+%zu DR, exit %s), |ΔP|/|P| %.1e\n",
                   dim, pk_homog_bc_name((pk_homog_bc)bc), sd.dr.iterations, sn.newton.iterations,
                   sn.dr.iterations, pk_newton_exit_name(sn.newton.exit), d / Pn);
            pk_homog_state_free(&t1);
            pk_homog_state_free(&t2);
            fixture_free(&fx);
        }
        pk_particles_free(&p);
    }
}

int main(void)
{
    RUN(test_sparse_solver_status);
    RUN(test_sparse_solver_supernodal);
    RUN(test_sparse_solver_pd_only);
    RUN(test_square_lattice_tangent);
    RUN(test_tangent_vs_finite_differences);
    RUN(test_constraint_ranking);
    RUN(test_singular_block_reported);
    RUN(test_newton_matches_dr);
    return check_summary();
}
