/* test_homog_bc.c — boundary conditions, relaxation and stress of the RVE
 * (Meier 2009 §4.3–4.4, ch. 5).  The jammed RVEs are built here:
 * random overlapping disks/spheres relaxed under periodic BC at F̄ = 1. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "homog_fixture.h"

/* Remark 6.1 with its basis corrected (docs/homogenization.md, Tangent): square √N×√N lattice of
 * touching disks under Taylor: A_1111 = E √N/(√N−1), shear stiffness 0.
 * Contacts are linear in the compression (ε = 2rδ exactly), so the one-sided
 * difference is exact up to round-off: tolerance 1e-9 relative. */
static void test_square_lattice_taylor_factor(void)
{
    for (int m = 2; m <= 10; m += 4) {
        size_t n = (size_t)(m * m);
        double *X = calloc(3 * n, sizeof *X), *r = malloc(n * sizeof *r);
        uint8_t *fx = malloc(n);
        for (int a = 0; a < m; a++)
            for (int c = 0; c < m; c++) {
                size_t i = (size_t)(a * m + c);
                X[3 * i] = 2.0 * c, X[3 * i + 1] = 2.0 * a;
                r[i] = 1, fx[i] = 1;
            }
        double V = 4.0 * (m - 1) * (m - 1); /* (6.9) */
        pk_homog_rve rve;
        pk_homog_rve_from_arrays(2, PK_BC_TAYLOR, n, X, r, fx, 0, NULL, V, &rve);
        pk_homog_opts o = opts(1);
        o.E_n = 3.0;
        pk_homog_state s0, tr = {0};
        pk_homog_state_init(&rve, &o, &s0);
        CHECK(s0.ncontact == 2 * (n - (size_t)m)); /* 2[#P − √#P] contacts */
        const double d = 1e-4;
        double F[9];
        pk_homog_step st;
        diagF(F, 1 - d, 1, 1);
        CHECK(pk_homog_eval(&rve, &o, &s0, F, &tr, &st, NULL) == 0);
        CHECK(st.dr.stop == PK_DR_NOT_NEEDED);
        double want = o.E_n * m / (m - 1.0);
        CHECK_NEAR(-st.P[0] / d, want, 1e-9 * want);
        CHECK_NEAR(st.P[4], 0, 1e-15); /* vertical contacts stay at ε = 0 */
        CHECK_NEAR(st.P[1], 0, 1e-15);
        CHECK_NEAR(st.P_reaction[0], st.P[0], 1e-12 * want * d); /* (5.16) = contact sum */
        /* simple shear: A_1212 = 0 (the printed 1⊗̄1 basis would give E) */
        double G[9];
        pk_m3_identity(G);
        G[1] = d;
        CHECK(pk_homog_eval(&rve, &o, &s0, G, &tr, &st, NULL) == 0);
        CHECK_NEAR(st.P[1] / d, 0, 1e-12);
        pk_homog_state_free(&s0);
        pk_homog_state_free(&tr);
        pk_homog_rve_free(&rve);
        free(X), free(r), free(fx);
    }
}

/* Spec §3.4: chain B₁–I–B₂ under restricted Taylor: σ̄_11 = −2Eεd/v (the
 * printed (5.20) would give half).  The inner grain starts at its reference
 * position (no predictor), so DR must move it. */
static void test_three_particle_chain(void)
{
    double X[9] = {0, 0, 0, 2, 0, 0, 4, 0, 0}, r[3] = {1, 1, 1};
    uint8_t fx[3] = {1, 0, 1};
    double V = 16;
    pk_homog_rve rve;
    pk_homog_rve_from_arrays(2, PK_BC_RESTRICTED_TAYLOR, 3, X, r, fx, 0, NULL, V, &rve);
    pk_homog_opts o = opts(1);
    o.affine_predictor = 0;
    o.E_n = 50;
    pk_homog_state tr = {0};
    const double dl = 0.01;
    double F[9];
    diagF(F, 1 - dl, 1, 1);
    pk_homog_step st;
    CHECK(step_from_reference(&rve, &o, F, &tr, &st) == 0);
    CHECK_MSG(st.dr.stop == PK_DR_CONVERGED, "%s", pk_dr_stop_name(st.dr.stop));
    CHECK(st.dr.iterations > 0);
    double eps = 2 * dl, d = 2 * (1 - dl), v = V * (1 - dl);
    /* DR tol 1e-12 relative: σ within 1e-9 relative */
    CHECK_NEAR(st.sigma[0], -2 * o.E_n * eps * d / v, 1e-9 * o.E_n * eps * d / v);
    CHECK_NEAR(st.P_reaction[0], st.P[0], 1e-9 * fabs(st.P[0])); /* (5.19) */
    CHECK_NEAR(tr.x[3], 2 * (1 - dl), 1e-10);
    CHECK(st.rattlers == 1); /* two diametral contacts: a rattler in 2D (spec caveat) */
    CHECK(st.contacts == 2 && st.formed == 0 && st.broken == 0); /* ε = 0 counts (4.2) */
    pk_homog_state_free(&tr);
    pk_homog_rve_free(&rve);
}

/* Spec §3.4 "use this one": inner grain, three hull neighbours at 120°,
 * overlap ε, distance d: σ̄ = −(3/2) E ε d / v · 1 (printed (5.20): half). */
static void test_jammed_triad(void)
{
    double d = 1.9, X[12] = {0};
    for (int k = 0; k < 3; k++) {
        X[3 * (k + 1)] = d * cos(2 * M_PI * k / 3 + 0.3);
        X[3 * (k + 1) + 1] = d * sin(2 * M_PI * k / 3 + 0.3);
    }
    double r[4] = {1, 1, 1, 1}, V = 10;
    uint8_t fx[4] = {0, 1, 1, 1};
    pk_homog_rve rve;
    pk_homog_rve_from_arrays(2, PK_BC_RESTRICTED_TAYLOR, 4, X, r, fx, 0, NULL, V, &rve);
    pk_homog_opts o = opts(1);
    pk_homog_state tr = {0};
    double I[9];
    pk_m3_identity(I);
    pk_homog_step st;
    CHECK(step_from_reference(&rve, &o, I, &tr, &st) == 0);
    double eps = 2 - d, want = -1.5 * o.E_n * eps * d / V;
    CHECK_NEAR(st.sigma[0], want, 1e-12);
    CHECK_NEAR(st.sigma[4], want, 1e-12);
    CHECK_NEAR(st.sigma[1], 0, 1e-12);
    CHECK(st.rattlers == 0 && st.contacts == 3);
    pk_homog_state_free(&tr);
    pk_homog_rve_free(&rve);
}

/* Σf_i = 0, σ̄ symmetric (frictionless), compression → σ̄ < 0, DR converged,
 * σ̄ = J⁻¹P̄F̄ᵗ — for every BC, in 2D and 3D. */
static void test_identities(void)
{
    for (int dim = 2; dim <= 3; dim++) {
        pk_box b;
        pk_particles p;
        make_jammed(dim, dim == 2 ? 120 : 60, dim == 2 ? 0.88 : 0.68, 3, &b, &p);
        for (int bc = 0; bc < 3; bc++) {
            fixture fx;
            double F[9];
            diagF(F, 0.99, 0.995, dim == 3 ? 0.995 : 1);
            fixture_make(&fx, &b, &p, (pk_homog_bc)bc, F);
            pk_homog_step *st = &fx.st;
            double sc = fabs(st->sigma[0]);
            CHECK(st->contacts > 0);
            CHECK_MSG(st->sum_force <= 1e-12 * fx.o.E_n, "dim %d bc %d |Σf| = %g", dim, bc,
                      st->sum_force);
            for (int a = 0; a < dim; a++) {
                CHECK_MSG(st->sigma[4 * a] < 0, "dim %d bc %d σ_%d%d = %g", dim, bc, a, a,
                          st->sigma[4 * a]);
                for (int c = 0; c < dim; c++)
                    CHECK_NEAR(st->sigma_skew[3 * a + c], 0, 1e-14 * sc);
            }
            /* σ = J⁻¹ P Fᵗ (2.5) */
            for (int a = 0; a < dim; a++)
                for (int c = 0; c < dim; c++) {
                    double s = 0;
                    for (int k = 0; k < dim; k++)
                        s += st->P[3 * a + k] * F[3 * c + k];
                    CHECK_NEAR(s / st->J, st->sigma[3 * a + c], 1e-13 * sc);
                }
            if (bc == PK_BC_RESTRICTED_TAYLOR) /* (5.19) = contact sum at equilibrium */
                CHECK_MSG(st->reaction_defect < 1e-8, "defect %g", st->reaction_defect);
            if (bc == PK_BC_TAYLOR)
                CHECK(st->reaction_defect < 1e-12);
            fixture_free(&fx);
        }
        pk_particles_free(&p);
    }
}

/* P̄ = ∂Φ̄/∂F̄ by central differences, each perturbed state relaxed from the
 * same committed state at fixed topology (Remark 4.4).  h = 1e-6 with DR tol
 * 1e-12: truncation O(h²), round-off ~1e-16 Φ̄/h, relaxation error O(tol²)
 * in Φ̄ → relative error well below the required 1e-6. */
static void test_stress_is_energy_derivative(void)
{
    for (int dim = 2; dim <= 3; dim++) {
        pk_box b;
        pk_particles p;
        make_jammed(dim, dim == 2 ? 80 : 50, dim == 2 ? 0.88 : 0.68, 5, &b, &p);
        for (int bc = 0; bc < 3; bc++) {
            fixture fx;
            double F0[9];
            diagF(F0, 0.995, 1.0, 1.0);
            F0[1] = 0.003;
            fixture_make(&fx, &b, &p, (pk_homog_bc)bc, F0);
            double Pn = 0;
            for (int k = 0; k < 9; k++)
                Pn = fmax(Pn, fabs(fx.st.P[k]));
            const double h = 1e-6;
            pk_homog_state tr = {0};
            pk_homog_step sp, sm;
            int same_topology = 1;
            double worst = 0;
            for (int a = 0; a < dim; a++)
                for (int c = 0; c < dim; c++) {
                    double Fp[9], Fm[9];
                    memcpy(Fp, F0, sizeof Fp);
                    memcpy(Fm, F0, sizeof Fm);
                    Fp[3 * a + c] += h;
                    Fm[3 * a + c] -= h;
                    pk_homog_eval(&fx.rve, &fx.o, &fx.s, Fp, &tr, &sp, NULL);
                    pk_homog_eval(&fx.rve, &fx.o, &fx.s, Fm, &tr, &sm, NULL);
                    same_topology &=
                        sp.formed == 0 && sp.broken == 0 && sm.formed == 0 && sm.broken == 0;
                    double fd = (sp.energy_density - sm.energy_density) / (2 * h);
                    worst = fmax(worst, fabs(fd - fx.st.P[3 * a + c]) / Pn);
                }
            CHECK(same_topology);
            CHECK_MSG(worst < 1e-6, "dim %d bc %s: rel. error %g", dim,
                      pk_homog_bc_name((pk_homog_bc)bc), worst);
            pk_homog_state_free(&tr);
            fixture_free(&fx);
        }
        pk_particles_free(&p);
    }
}

/* Rotating F̄ rotates the response: P̄(QF̄) = QP̄, σ̄(QF̄) = Qσ̄Qᵗ (the
 * fluctuations live in the material frame, (4.18)). */
static void test_objectivity(void)
{
    pk_box b;
    pk_particles p;
    make_jammed(2, 100, 0.88, 9, &b, &p);
    for (int bc = 0; bc < 3; bc++) {
        char err[128];
        pk_homog_rve rve;
        pk_homog_rve_build(&b, &p, (pk_homog_bc)bc, 1.0, &rve, err, sizeof err);
        pk_homog_opts o = opts(1);
        pk_homog_state s0, t1 = {0}, t2 = {0};
        pk_homog_state_init(&rve, &o, &s0);
        double F[9], Q[9], QF[9];
        diagF(F, 0.99, 1.0, 1.0);
        F[1] = 0.01;
        double a = 0.7;
        pk_m3_identity(Q);
        Q[0] = cos(a), Q[1] = -sin(a), Q[3] = sin(a), Q[4] = cos(a);
        pk_m3_mul(Q, F, QF);
        pk_homog_step s_1, s_2;
        CHECK(pk_homog_eval(&rve, &o, &s0, F, &t1, &s_1, NULL) == 0);
        CHECK(pk_homog_eval(&rve, &o, &s0, QF, &t2, &s_2, NULL) == 0);
        double QP[9], Qs[9], QsQt[9], Qt[9];
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++)
                Qt[3 * i + j] = Q[3 * j + i];
        pk_m3_mul(Q, s_1.P, QP);
        pk_m3_mul(Q, s_1.sigma, Qs);
        pk_m3_mul(Qs, Qt, QsQt);
        double sc = fabs(s_1.sigma[0]);
        /* both relaxed to 1e-12: responses agree to ~1e-9 relative */
        for (int k = 0; k < 9; k++) {
            CHECK_NEAR(s_2.P[k], QP[k], 1e-8 * sc);
            CHECK_NEAR(s_2.sigma[k], QsQt[k], 1e-8 * sc);
        }
        CHECK_NEAR(s_2.energy, s_1.energy, 1e-9 * s_1.energy);
        pk_homog_state_free(&s0);
        pk_homog_state_free(&t1);
        pk_homog_state_free(&t2);
        pk_homog_rve_free(&rve);
    }
    pk_particles_free(&p);
}

/* Trial evaluations never touch the committed history (Remark 4.4). */
static void test_trial_commit(void)
{
    pk_box b;
    pk_particles p;
    make_jammed(2, 80, 0.88, 13, &b, &p);
    fixture fx;
    double F0[9], F1[9];
    diagF(F0, 0.995, 1, 1);
    fixture_make(&fx, &b, &p, PK_BC_PERIODIC, F0);
    pk_homog_state keep = {0}, t1 = {0}, t2 = {0}, t3 = {0};
    pk_homog_state_copy(&keep, &fx.s);
    diagF(F1, 0.98, 1.0, 1);
    pk_homog_step a, c, d;
    pk_homog_eval(&fx.rve, &fx.o, &fx.s, F1, &t1, &a, NULL);
    CHECK(memcmp(keep.x, fx.s.x, 3 * keep.n * sizeof(double)) == 0);
    CHECK(keep.ncontact == fx.s.ncontact);
    pk_homog_eval(&fx.rve, &fx.o, &fx.s, F1, &t2, &c, NULL); /* same trial again: identical */
    CHECK(memcmp(a.P, c.P, sizeof a.P) == 0);
    CHECK(memcmp(t1.x, t2.x, 3 * t1.n * sizeof(double)) == 0);
    CHECK(pk_homog_commit(&fx.s, &t1) == 0);
    /* from the new history the same F̄ is already in equilibrium: nothing changes */
    pk_homog_eval(&fx.rve, &fx.o, &fx.s, F1, &t3, &d, NULL);
    CHECK(d.formed == 0 && d.broken == 0 && d.dr.f0 <= 1e-11 * a.dr.f0);
    CHECK_NEAR(d.P[0], a.P[0], 1e-10 * fabs(a.P[0]));
    pk_homog_state_free(&keep);
    pk_homog_state_free(&t1);
    pk_homog_state_free(&t2);
    pk_homog_state_free(&t3);
    fixture_free(&fx);
    pk_particles_free(&p);
}

static void test_bad_F_refused(void)
{
    double X[3] = {0, 0, 0}, r[1] = {1};
    uint8_t fx[1] = {1};
    pk_homog_rve rve;
    pk_homog_rve_from_arrays(2, PK_BC_TAYLOR, 1, X, r, fx, 0, NULL, 1, &rve);
    pk_homog_opts o = opts(1);
    pk_homog_state s0, tr = {0};
    pk_homog_state_init(&rve, &o, &s0);
    pk_homog_step st;
    double F[9];
    diagF(F, -1, 1, 1);
    CHECK(pk_homog_eval(&rve, &o, &s0, F, &tr, &st, NULL) == -3);
    diagF(F, NAN, 1, 1);
    CHECK(pk_homog_eval(&rve, &o, &s0, F, &tr, &st, NULL) == -3);
    pk_homog_state_free(&s0);
    pk_homog_state_free(&tr);
    pk_homog_rve_free(&rve);
}

int main(void)
{
    RUN(test_square_lattice_taylor_factor);
    RUN(test_three_particle_chain);
    RUN(test_jammed_triad);
    RUN(test_identities);
    RUN(test_stress_is_energy_derivative);
    RUN(test_objectivity);
    RUN(test_trial_commit);
    RUN(test_bad_F_refused);
    return check_summary();
}
