/* Pair-specific normal stiffness E_n,ij by species (Meier 2009 Eq. 4.3:
 * "E_n ij may be pair-specific"). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "homog_fixture.h"
#include "homog_fd.h"

/* Three grains in a line, species 0 | 1 | 2, ends prescribed (restricted
 * Taylor), the middle free; compress by dl.  Two springs in series: the
 * total overlap 4·dl splits as ε₁ = 4dl·E₁₂/(E₀₁+E₁₂), ε₂ = 4dl·E₀₁/(E₀₁+E₁₂),
 * the force is f = 4dl·E₀₁E₁₂/(E₀₁+E₁₂), the middle sits at 2 − ε₁ and
 * σ̄₁₁ = −f·(|l₁| + |l₂|)/v.  DR (tol 1e-12) and Newton must both get it. */
static void test_series_springs(void)
{
    double X[9] = {0, 0, 0, 2, 0, 0, 4, 0, 0}, r[3] = {1, 1, 1};
    uint8_t fxd[3] = {1, 0, 1};
    double V = 16, E01 = 50, E12 = 150;
    double Em[9] = {1, E01, 1, E01, 1, E12, 1, E12, 1}; /* 3 × 3, symmetric */
    for (int newton = 0; newton <= 1; newton++) {
        pk_homog_rve rve;
        pk_homog_rve_from_arrays(2, PK_BC_RESTRICTED_TAYLOR, 3, X, r, fxd, 0, NULL, V, &rve);
        for (int i = 0; i < 3; i++)
            rve.species[i] = i;
        pk_homog_opts o = opts(1);
        o.affine_predictor = 0;
        o.E_n = 50;
        o.E_n_species = Em;
        o.n_species = 3;
        o.newton = newton ? &pk_sparse_cholmod : NULL;
        o.newton_max_iter = 50;
        pk_homog_state tr = {0};
        const double dl = 0.01;
        double F[9];
        diagF(F, 1 - dl, 1, 1);
        pk_homog_step st;
        CHECK(step_from_reference(&rve, &o, F, &tr, &st) == 0);
        CHECK_MSG(pk_dr_stop_ok(st.dr.stop), "%s", pk_dr_stop_name(st.dr.stop));
        double e1 = 4 * dl * E12 / (E01 + E12), e2 = 4 * dl * E01 / (E01 + E12);
        double f = E01 * e1, v = V * (1 - dl);
        double want = -f * ((2 - e1) + (2 - e2)) / v;
        /* relative residual 1e-12 of f (~2 N): position within ~1e-12·f/E */
        CHECK_NEAR(tr.x[3], 2 - e1, 1e-10);
        CHECK_NEAR(st.sigma[0], want, 1e-9 * fabs(want));
        pk_homog_state_free(&tr);
        pk_homog_rve_free(&rve);
    }
}

/* A jammed 2D packing of 90 grains, species alternating 0, 1. */
static void two_species_packing(pk_box *b, pk_particles *p)
{
    make_jammed(2, 90, 0.88, 21, b, p);
    for (size_t i = 0; i < p->n; i++)
        p->species[i] = (int32_t)(i % 2);
}

/* A matrix of E_n everywhere is the uniform model, bit for bit; a matrix of
 * 2·E_n doubles P̄ (equilibrium positions do not depend on a common factor),
 * to the relaxation tolerance. */
static void test_uniform_matrix_and_scaling(void)
{
    pk_box b;
    pk_particles p;
    two_species_packing(&b, &p);
    double same[4] = {1, 1, 1, 1}, twice[4] = {2, 2, 2, 2};
    double F0[9];
    diagF(F0, 0.995, 1.0, 1.0);
    F0[1] = 0.003;
    fixture u, s1, s2;
    pk_homog_opts o = opts(1.0);
    fixture_make_opts(&u, &b, &p, PK_BC_PERIODIC, F0, &o);
    o.E_n_species = same, o.n_species = 2;
    fixture_make_opts(&s1, &b, &p, PK_BC_PERIODIC, F0, &o);
    o.E_n_species = twice;
    fixture_make_opts(&s2, &b, &p, PK_BC_PERIODIC, F0, &o);
    CHECK(memcmp(u.st.P, s1.st.P, sizeof u.st.P) == 0);
    double Pn = 0, d = 0;
    for (int k = 0; k < 9; k++) {
        Pn = fmax(Pn, fabs(u.st.P[k]));
        d = fmax(d, fabs(s2.st.P[k] - 2 * u.st.P[k]));
    }
    CHECK_MSG(d <= 1e-8 * Pn, "P(2E) − 2P(E) = %g of %g", d, Pn); /* DR tol 1e-12 */
    fixture_free(&u), fixture_free(&s1), fixture_free(&s2);
    pk_particles_free(&p);
}

/* Mixed stiffness: the tangent (which assembles E_n,ij per contact) still
 * matches central differences of P̄, and the ordering of stiffness is kept:
 * stiffer contacts between species 1 give a stiffer Ā₁₁₁₁. */
static void test_tangent_mixed_stiffness(void)
{
    pk_box b;
    pk_particles p;
    two_species_packing(&b, &p);
    double mixed[4] = {1, 2, 2, 5};
    double F0[9];
    diagF(F0, 0.994, 1.0, 1.0);
    F0[3] = -0.004;
    for (int bc = 1; bc <= 2; bc++) {
        fixture fx;
        pk_homog_opts o = opts(1.0);
        o.E_n_species = mixed, o.n_species = 2;
        fixture_make_opts(&fx, &b, &p, (pk_homog_bc)bc, F0, &o);
        double A[81], A1[81];
        pk_tangent_info info, i1;
        CHECK(pk_homog_tangent(&fx.rve, &fx.o, &fx.s, &pk_sparse_cholmod, A, &info) == 0);
        int skipped = 0;
        double asym = 0, An = 0;
        double worst = fd_tangent_error(&fx, F0, 2, A, &info, &skipped, &asym, &An);
        CHECK(skipped <= 1);
        CHECK_MSG(worst < 1e-6, "%s: FD rel. error %g", pk_homog_bc_name((pk_homog_bc)bc), worst);
        CHECK_MSG(asym < 1e-12, "major symmetry defect %g", asym);
        fixture u;
        fixture_make(&u, &b, &p, (pk_homog_bc)bc, F0);
        CHECK(pk_homog_tangent(&u.rve, &u.o, &u.s, &pk_sparse_cholmod, A1, &i1) == 0);
        CHECK_MSG(A[0] > A1[0], "A1111 mixed %g vs uniform %g", A[0], A1[0]);
        printf("  %-17s mixed E: FD rel. error %.2e, A1111 %.4g (uniform E_n: %.4g)\n",
               pk_homog_bc_name((pk_homog_bc)bc), worst, A[0], A1[0]);
        fixture_free(&fx), fixture_free(&u);
    }
    pk_particles_free(&p);
}

int main(void)
{
    RUN(test_series_springs);
    RUN(test_uniform_matrix_and_scaling);
    RUN(test_tangent_mixed_stiffness);
    return check_summary();
}
