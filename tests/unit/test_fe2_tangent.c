/* test_fe2_tangent.c — the global macro tangent of FE² (issue 26 "Macro
 * tangent"): K assembled from Ā equals central finite differences of the
 * global residual R(u) on small meshes (Q1 and triangles), with the linear
 * surrogate and with real DEM RVEs (Taylor, restricted Taylor); and one
 * Gauss point under a homogeneous F̄ returns exactly what a direct
 * homogenization of the same RVE under that F̄ returns. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "homog_fixture.h"
#include "fe2_fixture.h"
#include "core/homog/homog_tangent.h"

/* max |K − K_fd| / max |K| over all dofs at u (amplitude amp, seeded),
 * perturbation h. */
static double fd_error(const pk_fe2_problem *pb, double amp, double h, uint64_t seed)
{
    const pk_fe2_mesh *m = pb->mesh;
    const size_t n = 2 * m->nnode;
    double *u = malloc(n * sizeof *u), *Rp = malloc(n * sizeof *Rp), *Rm = malloc(n * sizeof *Rm),
           *K = calloc(n * n, sizeof *K);
    pk_rng rng;
    pk_rng_seed(&rng, seed, 0);
    for (size_t d = 0; d < n; d++)
        u[d] = pk_rng_range(&rng, -amp, amp);
    pk_sparse_sym Ks = {0};
    char why[200];
    int rc = pk_fe2_residual(pb, u, NULL, Rp, &Ks, why, sizeof why);
    CHECK_MSG(rc == 0, "%s", why);
    CHECK(Ks.n == n);
    for (size_t k = 0; k < Ks.nnz; k++) {
        K[Ks.row[k] * n + Ks.col[k]] += Ks.val[k];
        if (Ks.row[k] != Ks.col[k])
            K[Ks.col[k] * n + Ks.row[k]] += Ks.val[k];
    }
    double Kn = 0, err = 0;
    for (size_t k = 0; k < n * n; k++)
        Kn = fmax(Kn, fabs(K[k]));
    for (size_t j = 0; j < n; j++) {
        const double uj = u[j];
        u[j] = uj + h;
        CHECK(pk_fe2_residual(pb, u, NULL, Rp, NULL, why, sizeof why) == 0);
        u[j] = uj - h;
        CHECK(pk_fe2_residual(pb, u, NULL, Rm, NULL, why, sizeof why) == 0);
        u[j] = uj;
        for (size_t i = 0; i < n; i++)
            err = fmax(err, fabs((Rp[i] - Rm[i]) / (2 * h) - K[i * n + j]));
    }
    pk_sparse_sym_free(&Ks);
    free(u), free(Rp), free(Rm), free(K);
    return err / Kn;
}

static void test_tangent_surrogate(void)
{
    pk_fe2_linear_elastic le = {.lambda = 2.0, .mu = 1.3};
    pk_fe2_material mat = pk_fe2_linear_elastic_material(&le);
    for (int which = 0; which < 2; which++) {
        pk_fe2_mesh m;
        if (which == 0)
            mesh_q1_distorted(&m);
        else
            mesh_triangles(&m, 0);
        pk_fe2_problem pb = {&m, &mat, 0, NULL, &pk_sparse_cholmod, NULL, NULL};
        double e = fd_error(&pb, 0.05, 1e-6, 3);
        CHECK_MSG(e < 1e-8, "%s: FD error %g", which ? "triangles" : "Q1", e);
        printf("  surrogate %-9s FD rel. error %.1e\n", which ? "triangles" : "Q1", e);
        pk_fe2_mesh_free(&m);
    }
}

/* Real RVEs at every Gauss point (two RVEs of different seeds, g mod 2),
 * from their prestressed start state, under a random displacement of 0.2 %
 * strain: h = 1e-6 (F̄ perturbed by ~1e-6; DR tol 1e-12) as in
 * test_homog_tangent.  Not periodic: its 40-grain RVEs switch contacts or
 * minima within ±h at some Gauss point (an FD error of 1e2 on triangles);
 * test_homog_tangent checks its Ā per column at fixed topology. */
static void test_tangent_rve(void)
{
    for (int bc = 0; bc < 2; bc++) {
        pk_homog_rve rve[2];
        pk_homog_opts o;
        make_rve(40, 11, (pk_homog_bc)bc, &rve[0], &o);
        make_rve(40, 12, (pk_homog_bc)bc, &rve[1], &o);
        for (int which = 0; which < 2; which++) {
            pk_fe2_mesh m;
            if (which == 0)
                mesh_q1_distorted(&m);
            else
                mesh_triangles(&m, 0);
            pk_fe2_rve fr;
            char err[200];
            int rc = pk_fe2_rve_init(&fr, rve, 2, &o, &pk_sparse_cholmod, pk_fe2_gauss_count(&m),
                                     NULL, err, sizeof err);
            CHECK_MSG(rc == 0, "%s", err);
            pk_fe2_material mat = pk_fe2_rve_material(&fr);
            pk_fe2_problem pb = {&m, &mat, 0, NULL, &pk_sparse_cholmod, NULL, NULL};
            double e = fd_error(&pb, 2e-3, 1e-6, 5);
            CHECK_MSG(e < 1e-6, "%s %s: FD error %g", pk_homog_bc_name((pk_homog_bc)bc),
                      which ? "triangles" : "Q1", e);
            printf("  %-17s %-9s FD rel. error %.1e (P0_11 %.3g)\n",
                   pk_homog_bc_name((pk_homog_bc)bc), which ? "triangles" : "Q1", e, fr.P0[0]);
            pk_fe2_rve_free(&fr);
            pk_fe2_mesh_free(&m);
        }
        pk_homog_rve_free(&rve[0]);
        pk_homog_rve_free(&rve[1]);
    }
}

/* One triangle, one Gauss point, every dof prescribed as u = H·X (Taylor,
 * restricted Taylor, periodic RVE): its P̄
 * and Ā are those of pk_homog_eval + pk_homog_tangent of the same RVE from
 * the same start state under the F̄ the point saw (to the bit), and that F̄
 * is 1 + H to round-off. */
static void test_one_gauss_point(void)
{
    const double xy[] = {0.3, 0.1, 2.1, 0.4, 0.9, 1.7};
    const int32_t conn[] = {0, 1, 2, -1};
    const double H[4] = {-0.004, 0.0015, 0.001, 0.002};
    for (int bc = 0; bc < 3; bc++) {
        pk_fe2_mesh m;
        mesh_from(&m, 3, xy, 1, conn);
        pk_homog_rve rve;
        pk_homog_opts o;
        make_rve(40, 13, (pk_homog_bc)bc, &rve, &o);
        pk_fe2_rve fr;
        char err[200];
        CHECK(pk_fe2_rve_init(&fr, &rve, 1, &o, &pk_sparse_cholmod, 1, NULL, err, sizeof err) == 0);
        pk_homog_state start = {0}, tr = {0};
        CHECK(pk_homog_state_copy(&start, &fr.committed[0]) == 0);
        pk_fe2_material mat = pk_fe2_rve_material(&fr);
        const int32_t fix[6] = {0, 1, 2, 3, 4, 5};
        double uD[6], fz[6] = {0};
        for (int k = 0; k < 6; k++)
            uD[k] = H[2 * (k % 2)] * xy[2 * (k / 2)] + H[2 * (k % 2) + 1] * xy[2 * (k / 2) + 1];
        pk_fe2_problem pb = {&m, &mat, 6, fix, &pk_sparse_cholmod, NULL, NULL};
        pk_fe2_state s;
        CHECK(pk_fe2_state_init(&s, &m) == 0);
        pk_fe2_newton_opts no = newton_opts();
        pk_fe2_step_report rep;
        CHECK_MSG(pk_fe2_step(&pb, &no, &s, uD, fz, &rep, NULL) == 0, "%s", rep.why);
        for (int I = 0; I < 4; I++)
            CHECK_NEAR(s.F[I], (I == 0 || I == 3) + H[I], 1e-15);
        const double F3[9] = {s.F[0], s.F[1], 0, s.F[2], s.F[3], 0, 0, 0, 1};
        pk_homog_step st;
        CHECK(pk_homog_eval(&rve, &o, &start, F3, &tr, &st, NULL) == 0);
        double A3[81];
        pk_tangent_info ti;
        CHECK(pk_homog_tangent(&rve, &o, &tr, &pk_sparse_cholmod, A3, &ti) == 0);
        const int emb[4] = {0, 1, 3, 4};
        double dP = 0, dA = 0;
        for (int I = 0; I < 4; I++) {
            dP = fmax(dP, fabs(s.P[I] - st.P[emb[I]]));
            for (int J = 0; J < 4; J++)
                dA = fmax(dA, fabs(s.A[4 * I + J] - A3[9 * emb[I] + emb[J]]));
        }
        CHECK_MSG(dP == 0 && dA == 0, "%s: |dP| %g |dA| %g", pk_homog_bc_name((pk_homog_bc)bc), dP,
                  dA);
        CHECK(fabs(st.P[0]) > 0 && s.gp[0].energy == st.energy_density);
        /* the committed micro state is the trial of the converged step */
        CHECK(fr.committed[0].n == tr.n &&
              !memcmp(fr.committed[0].x, tr.x, 3 * tr.n * sizeof *tr.x));
        printf("  %-17s P11 %.6g P12 %.6g P21 %.6g P22 %.6g (direct: equal bits)\n",
               pk_homog_bc_name((pk_homog_bc)bc), s.P[0], s.P[1], s.P[2], s.P[3]);
        pk_fe2_state_free(&s);
        pk_homog_state_free(&start), pk_homog_state_free(&tr);
        pk_fe2_rve_free(&fr);
        pk_homog_rve_free(&rve);
        pk_fe2_mesh_free(&m);
    }
}

int main(void)
{
    RUN(test_tangent_surrogate);
    RUN(test_one_gauss_point);
    RUN(test_tangent_rve);
    return check_summary();
}
