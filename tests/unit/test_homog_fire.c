/* test_homog_fire.c — FIRE (core/homog/homog_fire.h), the relaxation the Newton
 * hybrid switches to after failed attempts: the same minimum as DR on an
 * elastic step in fewer iterations, and the hook / cap contract it shares
 * with DR (core/homog/homog_relax.h), incl. DR's hand-over result. */
#include "check.h"
#include "core/homog/homog_eigen.h"
#include "core/homog/homog_fire.h"
#include "homog_fixture.h"

/* Energy, stress sum and free residual at x. */
static void measure(relax_problem *pb, const double *x, double *phi, double S[9], double *fres)
{
    size_t n = pb->rve.n;
    double *f = malloc(3 * n * sizeof *f);
    CHECK(pk_dem_pairs_build(&pb->c, &pb->g, x, pb->rve.r, n, pb->o.dr.skin) == 0);
    pk_dem_eval(&pb->c, &pb->g, x, pb->rve.r, n, pb->o.E_n, f, phi, S);
    *fres = sqrt(pk_homog_dot_mask(f, f, pb->is_free, n, 2));
    free(f);
}

static double *copy_x(const relax_problem *pb)
{
    double *x = malloc(3 * pb->rve.n * sizeof *x);
    memcpy(x, pb->x0, 3 * pb->rve.n * sizeof *x);
    return x;
}

/* Both to 1e-10·|f⁰|: the same minimum, so Φ agrees to 1e-12 relative (its
 * error is quadratic in the residual) and the stress sum to 1e-8 relative
 * (linear in it; measured ~1e-10, as Newton against DR in
 * test_homog_newton).  FIRE needs fewer iterations than DR (measured ratio
 * printed; the reason it is there). */
static void test_fire_reaches_dr_minimum(void)
{
    relax_problem pb;
    relax_problem_make(&pb);
    pk_dem_system sys = relax_problem_system(&pb);
    double *xd = copy_x(&pb), *xf = copy_x(&pb);
    pk_dr_stats sd, sf;
    pk_fire_params fp = pk_fire_params_default();
    CHECK(pk_homog_relax(&sys, xd, &pb.o.dr, NULL, &sd) == 0);
    CHECK(pk_homog_fire_hooked(&sys, xf, &pb.o.dr, &fp, NULL, NULL, &sf) == 0);
    CHECK_MSG(sf.stop == PK_DR_CONVERGED, "FIRE: %s", pk_dr_stop_name(sf.stop));
    CHECK(pk_dr_stop_ok(sd.stop));
    double phid, phif, Sd[9], Sf[9], fd, ff;
    measure(&pb, xd, &phid, Sd, &fd);
    measure(&pb, xf, &phif, Sf, &ff);
    CHECK_MSG(ff <= pb.o.dr.tol * sf.f0, "FIRE |f| %g > tol·|f0| %g", ff, pb.o.dr.tol * sf.f0);
    CHECK_NEAR(phif, phid, 1e-12 * phid);
    double Sn = 0, dS = 0;
    for (int k = 0; k < 9; k++) {
        Sn = fmax(Sn, fabs(Sd[k]));
        dS = fmax(dS, fabs(Sf[k] - Sd[k]));
    }
    CHECK_MSG(dS <= 1e-8 * Sn, "|ΔS|/|S| = %g", dS / Sn);
    CHECK_MSG(sf.iterations < sd.iterations, "FIRE %zu it, DR %zu", sf.iterations, sd.iterations);
    printf("  DR %zu it, FIRE %zu it (%zu restarts): %.1fx fewer; |ΔS|/|S| %.1e\n", sd.iterations,
           sf.iterations, sf.refreshes, (double)sd.iterations / (double)sf.iterations, dS / Sn);
    free(xd);
    free(xf);
    relax_problem_free(&pb);
}

/* FIRE in its textbook form: P = f·v, v ← v + Δt f, the mixed move
 * and |f| as four separate passes — the oracle of the fused loop
 * (homog_fire.c: one pass after each evaluation), which must follow it bit
 * for bit: near jamming a difference in the last bit moves the plastic
 * events.  Runs exactly `iters` iterations; returns the restarts. */
static size_t fire_reference(relax_problem *pb, double *x, const pk_fire_params *fp, size_t iters)
{
    const size_t n = pb->rve.n;
    const double E = pb->o.E_n, dt_min_share = 0.02; /* DT_MIN_SHARE */
    const uint8_t *fr = pb->is_free;
    double *f = malloc(3 * n * sizeof *f), *v = calloc(3 * n, sizeof *v);
    CHECK(pk_dem_pairs_build(&pb->c, &pb->g, x, pb->rve.r, n, pb->o.dr.skin) == 0);
    pk_dem_eval(&pb->c, &pb->g, x, pb->rve.r, n, E, f, NULL, NULL);
    double fn = sqrt(pk_homog_dot_mask(f, f, fr, n, 2));
    const double dt_max = fp->dt_scale * 2 / sqrt(pk_dem_gershgorin(&pb->c, 2, n, E, fr));
    double dt = 0.5 * dt_max, alpha = fp->alpha0;
    size_t n_pos = 0, restarts = 0;
    for (size_t k = 0; k < iters; k++) {
        if (pk_homog_dot_mask(f, v, fr, n, 2) > 0) {
            if (++n_pos > fp->n_min) {
                dt = fmin(dt * fp->f_inc, dt_max);
                alpha *= fp->f_alpha;
            }
        } else {
            n_pos = 0;
            dt = fmax(dt * fp->f_dec, dt_min_share * dt_max);
            alpha = fp->alpha0;
            for (size_t e = 0; e < 3 * n && k > 0; e++)
                x[e] -= fr[e / 3] ? 0.5 * dt * v[e] : 0;
            memset(v, 0, 3 * n * sizeof *v);
            restarts++;
        }
        double vv = 0;
        for (size_t e = 0; e < 3 * n; e++)
            if (fr[e / 3] && e % 3 < 2) {
                v[e] += dt * f[e];
                vv += v[e] * v[e];
            }
        pk_relax_coef cf = {dt, 1 - alpha, fn > 0 ? alpha * sqrt(vv) / fn : 0};
        if (pk_relax_move(x, v, f, fr, n, 2, cf, &pb->c))
            CHECK(pk_dem_pairs_build(&pb->c, &pb->g, x, pb->rve.r, n, pb->o.dr.skin) == 0);
        pk_dem_eval(&pb->c, &pb->g, x, pb->rve.r, n, E, f, NULL, NULL);
        fn = sqrt(pk_homog_dot_mask(f, f, fr, n, 2));
    }
    free(f);
    free(v);
    return restarts;
}

/* The fused loop against the oracle over a fixed number of iterations with
 * restarts among them (a 1 % compression: contacts close, uphill steps):
 * the same positions to the last bit and the same restarts. */
static void test_fused_loop_is_the_reference(void)
{
    relax_problem pb;
    relax_problem_make(&pb);
    pk_dem_system sys = relax_problem_system(&pb);
    size_t n = pb.rve.n;
    double F[9];
    diagF(F, 0.99, 1.0, 1.0);
    pk_dem_geom_set_F(&pb.g, F);
    for (size_t i = 0; i < n; i++)
        pk_m3_vec(F, &pb.rve.X[3 * i], &pb.x0[3 * i]), pb.x0[3 * i + 2] = 0;
    double *xr = copy_x(&pb), *xf = copy_x(&pb);
    pk_fire_params fp = pk_fire_params_default();
    const size_t iters = 600;
    size_t restarts = fire_reference(&pb, xr, &fp, iters);
    pk_dr_params prm = pb.o.dr;
    prm.tol = 0, prm.abs_floor = 0, prm.max_iter = iters; /* stops at the cap */
    pk_dr_stats st;
    CHECK(pk_homog_fire_hooked(&sys, xf, &prm, &fp, NULL, NULL, &st) == 0);
    CHECK(st.stop == PK_DR_MAX_ITER && st.iterations == iters);
    CHECK_MSG(st.refreshes == restarts, "restarts %zu, reference %zu", st.refreshes, restarts);
    CHECK_MSG(restarts >= 2, "only %zu restart(s): the uphill branch is not exercised", restarts);
    CHECK(memcmp(xf, xr, 3 * n * sizeof *xf) == 0);
    printf("  %zu iterations, %zu restarts, %zu rebuilds: bit-identical\n", iters, restarts,
           st.rebuilds);
    free(xr);
    free(xf);
    relax_problem_free(&pb);
}

/* A hook that records its calls; `answer` is what it returns. */
typedef struct spy {
    int answer;
    size_t calls, late; /* late: called with |f| above the threshold */
} spy;

static int spy_fn(void *ctx, double *x, double *fres, double *at)
{
    (void)x;
    spy *s = ctx;
    s->calls++;
    s->late += *fres > *at;
    *at *= 0.1;
    return s->answer;
}

/* The hook contract: called when |f| <= at; 0 leaves the iteration exactly
 * as without a hook (x bit for bit); 1 ends it at the hook's residual (here
 * |f| itself, above tol·|f⁰|: stop converged_absolute); DR stops on 2 with
 * handed_over at the point reached (its residual recomputed on a fresh pair
 * list: equal to 1e-9, the summation order may differ).  The cap ends FIRE
 * with max_iter. */
static void test_hook_and_cap(void)
{
    relax_problem pb;
    relax_problem_make(&pb);
    pk_dem_system sys = relax_problem_system(&pb);
    size_t n = pb.rve.n;
    pk_fire_params fp = pk_fire_params_default();
    double *xa = copy_x(&pb), *xb = copy_x(&pb);
    pk_dr_stats sa, sb;
    CHECK(pk_homog_fire_hooked(&sys, xa, &pb.o.dr, &fp, NULL, NULL, &sa) == 0);
    spy s0 = {0, 0, 0};
    pk_dr_hook h0 = {.fn = spy_fn, .ctx = &s0, .at = 1e-2 * sa.f0};
    CHECK(pk_homog_fire_hooked(&sys, xb, &pb.o.dr, &fp, &h0, NULL, &sb) == 0);
    CHECK(s0.calls >= 3 && s0.late == 0); /* thresholds 1e-2, 1e-3, 1e-4 … all passed */
    CHECK(sb.iterations == sa.iterations && memcmp(xa, xb, 3 * n * sizeof *xa) == 0);

    /* 1: solved by the hook at the first threshold */
    memcpy(xb, pb.x0, 3 * n * sizeof *xb);
    spy s1 = {1, 0, 0};
    pk_dr_hook h1 = {.fn = spy_fn, .ctx = &s1, .at = 1e-2 * sa.f0};
    CHECK(pk_homog_fire_hooked(&sys, xb, &pb.o.dr, &fp, &h1, NULL, &sb) == 0);
    CHECK(s1.calls == 1 && sb.f <= 1e-2 * sa.f0 && sb.iterations < sa.iterations);
    CHECK(sb.stop == PK_DR_CONVERGED_ABS); /* |f| > tol·|f⁰|: only the "floor" branch is left */

    /* 2: DR hands over at the first threshold */
    memcpy(xb, pb.x0, 3 * n * sizeof *xb);
    spy s2 = {2, 0, 0};
    pk_dr_hook h2 = {.fn = spy_fn, .ctx = &s2, .at = 1e-2 * sa.f0};
    CHECK(pk_homog_relax_hooked(&sys, xb, &pb.o.dr, &h2, NULL, &sb) == 0);
    CHECK_MSG(sb.stop == PK_DR_HANDED_OVER, "%s", pk_dr_stop_name(sb.stop));
    double phi, S[9], fr;
    measure(&pb, xb, &phi, S, &fr);
    CHECK(s2.calls == 1 && fr <= 1e-2 * sa.f0 * (1 + 1e-9));
    CHECK_NEAR(fr, sb.f, 1e-9 * sb.f);

    /* the cap */
    memcpy(xb, pb.x0, 3 * n * sizeof *xb);
    pk_dr_params capped = pb.o.dr;
    capped.max_iter = 5;
    CHECK(pk_homog_fire_hooked(&sys, xb, &capped, &fp, NULL, NULL, &sb) == 0);
    CHECK(sb.stop == PK_DR_MAX_ITER && sb.iterations == 5);
    free(xa);
    free(xb);
    relax_problem_free(&pb);
}

int main(void)
{
    RUN(test_fire_reaches_dr_minimum);
    RUN(test_hook_and_cap);
    RUN(test_fused_loop_is_the_reference);
    return check_summary();
}
