/* bench/homog — speed of the RVE homogenization (issue 6 bar: one periodic
 * load step of a 10⁴-grain 2D RVE relaxed to 1e-8 in < 2 s, tangent < 1 s).
 * Prints one line per case:
 *   bench=homog case=NAME n=N iterations=K seconds=S particle_iter_per_s=R
 *   bench=homog case=NAME n=N tangent_s=S free_dofs=D
 * and the ratio line of the per-particle rates 1e4/1e3 (flat = DR scales).
 * The jammed RVE is made here: random overlapping disks (radii 0.8–1.2)
 * relaxed under periodic BC at F̄ = 1 (its time is reported as 'jam').
 * Only dynamic relaxation exists so far (no Newton solver to compare). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "homog_tangent.h"
#include "homog_tensor.h"
#include "rng.h"
#include "sparse_cholmod.h"

static pk_homog_opts opts(double tol)
{
    pk_homog_opts o = {.E_n = 1, .affine_predictor = 1};
    o.dr.tol = tol;
    o.dr.abs_floor = 0;
    o.dr.max_iter = 2000000;
    o.dr.lanczos_steps = 40;
    o.dr.refresh = 200;
    o.dr.skin = 0.3;
    return o;
}

static double rate_case(size_t n)
{
    pk_rng rng;
    pk_rng_seed(&rng, 5, 0);
    pk_particles p;
    pk_particles_init(&p, 2, n);
    double meas = 0;
    double *r = malloc(n * sizeof *r);
    for (size_t i = 0; i < n; i++) {
        r[i] = pk_rng_range(&rng, 0.8, 1.2);
        meas += M_PI * r[i] * r[i];
    }
    double L = sqrt(meas / 0.86);
    pk_box b = {.dim = 2, .L = {L, L, 0}, .periodic = {true, true, false}};
    for (size_t i = 0; i < n; i++) {
        double x[3] = {pk_rng_range(&rng, 0, L), pk_rng_range(&rng, 0, L), 0};
        pk_particles_push(&p, x, r[i], 0);
    }
    free(r);
    char err[128];
    pk_homog_rve rve;
    pk_homog_rve_build(&b, &p, PK_BC_PERIODIC, 1.0, &rve, err, sizeof err);
    pk_homog_opts o = opts(1e-10);
    pk_homog_state s0, tr = {0};
    pk_homog_state_init(&rve, &o, &s0);
    double F[9];
    pk_m3_identity(F);
    pk_homog_step st;
    double t0 = pk_wall_seconds();
    pk_homog_eval(&rve, &o, &s0, F, &tr, &st, NULL);
    double tj = pk_wall_seconds() - t0;
    printf("bench=homog case=jam_2d n=%zu iterations=%zu seconds=%.3f stop=%s\n", n,
           st.dr.iterations, tj, pk_dr_stop_name(st.dr.stop));
    pk_homog_commit(&s0, &tr);
    /* one periodic load step: 0.1 % uniaxial compression, tol 1e-8 (thesis) */
    o = opts(1e-8);
    F[0] = 0.999;
    t0 = pk_wall_seconds();
    pk_homog_eval(&rve, &o, &s0, F, &tr, &st, NULL);
    double ts = pk_wall_seconds() - t0;
    double rate = (double)n * (double)st.dr.iterations / ts;
    printf("bench=homog case=periodic_step_2d n=%zu iterations=%zu seconds=%.3f "
           "particle_iter_per_s=%.3g stop=%s contacts=%zu rattlers=%zu\n",
           n, st.dr.iterations, ts, rate, pk_dr_stop_name(st.dr.stop), st.contacts, st.rattlers);
    double A[81];
    pk_tangent_info ti;
    int rc = pk_homog_tangent(&rve, &o, &tr, &pk_sparse_cholmod, A, &ti);
    printf("bench=homog case=tangent_periodic_2d n=%zu tangent_s=%.3f free_dofs=%zu status=%s rc=%d "
           "A1111=%.4g\n",
           n, ti.seconds, ti.free_dofs, pk_sparse_status_name(ti.block.status), rc, A[0]);
    pk_homog_state_free(&s0);
    pk_homog_state_free(&tr);
    pk_homog_rve_free(&rve);
    pk_particles_free(&p);
    return rate;
}

int main(void)
{
    setvbuf(stdout, NULL, _IOLBF, 0); /* one line per case, as it comes */
    double r3 = rate_case(1000), r4 = rate_case(10000);
    printf("bench=homog case=ratio rate_1e4_over_1e3=%.3f\n", r4 / r3);
    return 0;
}
