/* The Rayleigh quotient of DR's increments (pk_increment_rq, homog_eigen.h)
 * on a linear system f = −K x with K = diag(λ) known: the book-keeping across
 * steps (step k's force after the move comes with step k+1's update) against
 * the quotient Σ Δxᵀ K Δx / Σ Δxᵀ Δx computed directly, its Rayleigh bounds,
 * and what DR relies on: with λ_min over-estimated (as a short Lanczos run
 * does near jamming) the slow mode takes over the increments and the
 * quotient finds λ_min. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "check.h"
#include "homog_eigen.h"

#define N 6

static const double lam[N] = {1e-4, 3e-3, 0.02, 0.3, 1.0, 4.0};

/* DR's update (4.39)–(4.41) as homog_relax.c does it, with the dot products
 * of pk_increment_rq_add; f = −K x. */
static void dr_step(double *x, double *v, double *f, double dt, double cv, double cf, double d[3])
{
    d[0] = d[1] = d[2] = 0;
    for (int i = 0; i < N; i++) {
        d[0] += v[i] * f[i];
        v[i] = cv * v[i] + cf * f[i];
        d[1] += v[i] * f[i];
        d[2] += v[i] * v[i];
        x[i] += dt * v[i];
    }
    for (int i = 0; i < N; i++)
        f[i] = -lam[i] * x[i];
}

/* Runs `steps` DR steps with parameters (4.47) from the estimate lmin_est,
 * taking the quotient every `window` steps; checks each window against the
 * direct sums, returns the last window's quotient. */
static double run(double lmin_est, int steps, int window)
{
    const double lmax = lam[N - 1];
    const double dt = 2 / sqrt(lmin_est + lmax), gm = 2 * sqrt(lmin_est * lmax / (lmin_est + lmax));
    double x[N], v[N] = {0}, f[N];
    for (int i = 0; i < N; i++) {
        x[i] = 1.0 / (1 + i);
        f[i] = -lam[i] * x[i];
    }
    pk_increment_rq q = {0};
    double num = 0, den = 0, last = 0;
    for (int k = 0; k < steps; k++) {
        double x0[N], d[3];
        memcpy(x0, x, sizeof x);
        double cv = k == 0 ? 0 : (2 - gm * dt) / (2 + gm * dt);
        double cf = k == 0 ? 0.5 * dt : 2 * dt / (2 + gm * dt);
        dr_step(x, v, f, dt, cv, cf, d);
        pk_increment_rq_add(&q, d, dt);
        if (k > 0 && k % window == 0) {
            /* the add of step k books step k−1: the direct sums so far */
            double got = pk_increment_rq_take(&q);
            last = num / den;
            /* the same sums in another order: round-off relative to the terms,
             * which shrink with x at the same rate — 1e-9 leaves 5 orders of
             * margin over the worst cancellation seen (|f|/|Δf| ≤ 1e4 here) */
            CHECK_MSG(fabs(got - last) <= 1e-9 * last, "window at %d: %.17g vs direct %.17g", k,
                      got, last);
            /* a Rayleigh quotient of K */
            CHECK(got >= lam[0] * (1 - 1e-9) && got <= lmax * (1 + 1e-9));
            num = den = 0;
        }
        /* step k completed: its increment and its force change, directly */
        double kk = 0, xx = 0;
        for (int i = 0; i < N; i++) {
            double dx = x[i] - x0[i];
            kk += lam[i] * dx * dx;
            xx += dx * dx;
        }
        num += kk;
        den += xx;
    }
    return last;
}

static void test_matches_direct_sums_and_bounds(void)
{
    run(lam[0], 3000, 200);  /* exact parameters */
    run(1e-8, 3000, 200);    /* λ_min under-estimated: underdamped */
    run(0.5, 3000, 37);      /* over-estimated, an odd window */
}

static void test_finds_lambda_min_when_overestimated(void)
{
    /* Lanczos's 40 steps near jamming: 4e-3 for ~1e-5 (homog_eigen.h); here
     * 30x over: the slow mode overdamped, the others decay at ≥ 40x its rate,
     * so after 3000 steps the increments are the slow mode alone.  Within 10 %
     * (measured 1e-4 to 4 digits; the fast modes' share decays like e^{-k/50}). */
    double q = run(3e-3, 3000, 200);
    printf("  λ_min 1e-4, estimate 3e-3: increments' quotient %.6g\n", q);
    CHECK_NEAR(q, lam[0], 0.1 * lam[0]);
}

static void test_restart_and_empty_window(void)
{
    pk_increment_rq q = {0};
    CHECK(pk_increment_rq_take(&q) == 0);
    /* one move, no force after it yet: nothing booked */
    double d[3] = {0, 2.0, 1.0};
    pk_increment_rq_add(&q, d, 0.5);
    CHECK(pk_increment_rq_take(&q) == 0);
    /* its force after: v·f went 2 → 1.5 with Δt 0.5, |v|² 1: (0.5·0.5)/(0.25·1) */
    double d2[3] = {1.5, 0, 0};
    pk_increment_rq_add(&q, d2, 0.5);
    CHECK_NEAR(pk_increment_rq_take(&q), 1.0, 1e-15);
}

int main(void)
{
    RUN(test_matches_direct_sums_and_bounds);
    RUN(test_finds_lambda_min_when_overestimated);
    RUN(test_restart_and_empty_window);
    return check_summary();
}
