/* test_edmd.c — EDMD engine: collision-time roots (spec §3.3a), list-exit
 * times, walled-cube limits (Titscher §6.1), overlap-free results under the
 * independent gap audit, stopping exactly at a target, cancellation. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "core/edmd/edmd_state.h"
#include "core/space/gap_audit.h"
#include "core/base/rng.h"

/* Independent check (core/space/gap_audit: its own cell grid, not the engine's
 * lists): no pair closer than Δd − 1e-9·d_min, no wall clearance below
 * Δd/2 − 1e-9·d_min.  1e-9 relative is the bar; the engine's own
 * round-off is ~1e-15 relative. */
static void check_no_overlap(const pk_box *b, const pk_particles *p, double delta_d)
{
    double rmin = INFINITY, rmax = 0;
    for (size_t i = 0; i < p->n; i++) {
        rmin = fmin(rmin, p->r[i]);
        rmax = fmax(rmax, p->r[i]);
    }
    pk_gap_report rep;
    CHECK(pk_gap_audit(b, p, delta_d, 1e-9 * 2 * rmin, fmax(rmax, delta_d), &rep) == 0);
    CHECK_MSG(rep.pairs_below == 0, "%zu pairs below, min gap %g", rep.pairs_below, rep.min_gap);
    CHECK_MSG(rep.walls_below == 0, "%zu grains below the wall gap", rep.walls_below);
}

static void box_cube(pk_box *b, int dim, double L, int periodic)
{
    memset(b, 0, sizeof *b);
    b->dim = dim;
    for (int k = 0; k < dim; k++) {
        b->L[k] = L;
        b->periodic[k] = periodic;
    }
}

/* Edge of the 3D cube that n spheres of radius r fill to phi. */
static double cube_edge(int n, double r, double phi)
{
    return cbrt(n * pk_ball_measure(3, r) / phi);
}

/* The common set-up: n grains (radius r, every 4th r4 — r4 = r for equal
 * grains) at the origin (the zero start places them) in a cube of edge L,
 * and the default parameters. */
static void setup(pk_box *b, pk_particles *p, pk_edmd_params *prm, int dim, double L, int periodic,
                  int n, double r, double r4)
{
    box_cube(b, dim, L, periodic);
    pk_particles_init(p, dim, (size_t)n);
    double x[3] = {0, 0, 0};
    for (int i = 0; i < n; i++)
        pk_particles_push(p, x, i % 4 == 0 ? r4 : r, 0);
    pk_edmd_params_default(prm);
}

/* Spec §3.3a check case: the (B + √Δ)/(−A) form stays exact where the
 * conjugate form loses 1e-4.  Exact answer: t = 9/(1 − Δv) (Δv exactly
 * representable difference, Sterbenz). */
static void test_pair_time_cancellation_free(void)
{
    double dv1 = 1 - 1e-12;
    double dp[3] = {10, 0, 0}, dv[3] = {dv1, 0, 0};
    double t = pk_edmd_pair_time(dp, dv, 1, 1, NULL);
    double ref = 9 / (1 - dv1);
    CHECK_NEAR(t / ref, 1, 1e-12); /* tolerance: a few ulps of the root, far below 1e-4 */
    dv[0] = 1 - 1e-15;
    t = pk_edmd_pair_time(dp, dv, 1, 1, NULL);
    ref = 9 / (1 - dv[0]);
    CHECK_NEAR(t / ref, 1, 1e-12);
}

static void test_pair_time_touching_cases(void)
{
    int ov = 0;
    /* touching and approaching: collide now */
    double dp[3] = {2, 0, 0}, dv[3] = {-1, 0, 0};
    CHECK(pk_edmd_pair_time(dp, dv, 2, 0.1, &ov) == 0);
    CHECK(!ov);
    /* touching, receding slower than growth (A < 0): next contact at −2B/A */
    dv[0] = 0.05;
    double A = 0.05 * 0.05 - 0.01, B = 2 * 0.05 - 2 * 0.1;
    double t = pk_edmd_pair_time(dp, dv, 2, 0.1, &ov);
    CHECK(t == 0); /* B < 0 here: the gap shrinks (0.05 < G): immediate */
    dv[0] = 0.3;   /* receding faster than growth: A > 0, never again */
    CHECK(isinf(pk_edmd_pair_time(dp, dv, 2, 0.1, &ov)));
    /* overlap by 1 % flagged */
    dp[0] = 1.98;
    dv[0] = -1;
    CHECK(pk_edmd_pair_time(dp, dv, 2, 0.1, &ov) == 0);
    CHECK(ov);
    (void)A;
    (void)B;
    /* C < 0 (round-off overlap), receding, growth catches up: larger root */
    double dp2[3] = {2 - 1e-14, 0, 0}, dv2[3] = {0.15, 0, 0};
    t = pk_edmd_pair_time(dp2, dv2, 2, 0.2, &ov);
    /* |2 + 0.15 t| = 2 + 0.2 t  =>  t ≈ 0 (the smaller root) or −2B/A ≈ ... the
     * pair opens (gap rate −0.05 < 0 means it does not): B = 2·0.15 − 0.4 < 0 → now */
    CHECK(t == 0);
    double dv3[3] = {0.1, 0, 0}; /* growth 0.05 */
    t = pk_edmd_pair_time(dp2, dv3, 2, 0.05, &ov);
    CHECK(isinf(t)); /* receding faster than growth, A > 0 */
}

/* Random pairs against an independent bisection on the gap function
 * g(t) = |Δp + Δv t| − (R + G t): the predicted root is the first sign
 * change.  Tolerance 1e-9 relative: bisection to 1e-13, round-off 1e-15. */
static void test_pair_time_random(void)
{
    pk_rng rng;
    pk_rng_seed(&rng, 7, 0);
    int checked = 0;
    for (int it = 0; it < 20000; it++) {
        double dp[3], dv[3];
        for (int k = 0; k < 3; k++) {
            dp[k] = pk_rng_range(&rng, -3, 3);
            dv[k] = pk_rng_range(&rng, -1, 1);
        }
        double R = pk_rng_range(&rng, 0.1, 1), G = pk_rng_range(&rng, 0, 0.5);
        double d0 = sqrt(dp[0] * dp[0] + dp[1] * dp[1] + dp[2] * dp[2]);
        if (d0 <= R)
            continue;
        double t = pk_edmd_pair_time(dp, dv, R, G, NULL);
        /* scan for the first sign change up to T */
        double T = 100, prev = 0, hit = INFINITY;
        for (int s = 1; s <= 20000; s++) {
            double tt = T * s / 20000;
            double x[3];
            for (int k = 0; k < 3; k++)
                x[k] = dp[k] + dv[k] * tt;
            double g = sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]) - R - G * tt;
            if (g <= 0) {
                double lo = prev, hi = tt;
                for (int q = 0; q < 100; q++) {
                    double mid = 0.5 * (lo + hi);
                    for (int k = 0; k < 3; k++)
                        x[k] = dp[k] + dv[k] * mid;
                    if (sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]) - R - G * mid <= 0)
                        hi = mid;
                    else
                        lo = mid;
                }
                hit = hi;
                break;
            }
            prev = tt;
        }
        if (isinf(hit)) {
            CHECK_MSG(t > T * 0.999, "predicted %g, none found below %g", t, T);
        } else {
            CHECK_MSG(fabs(t - hit) <= 1e-9 * fmax(1, hit), "predicted %.17g, scan %.17g", t, hit);
            checked++;
        }
    }
    CHECK(checked > 1000);
}

static void test_exit_time(void)
{
    pk_rng rng;
    pk_rng_seed(&rng, 9, 0);
    for (int it = 0; it < 2000; it++) {
        double q[3], v[3];
        for (int k = 0; k < 3; k++) {
            q[k] = pk_rng_range(&rng, -0.1, 0.1);
            v[k] = pk_rng_range(&rng, -1, 1) * (it % 3 == 0 ? 1e-3 : 1);
        }
        double rho = 1, g = it % 5 == 0 ? 0 : pk_rng_range(&rng, 0, 2), sigma = 1.5;
        double t = pk_edmd_exit_time(q, v, rho, g, sigma);
        CHECK(t > 0);
        if (!isfinite(t))
            continue;
        double x[3];
        for (int k = 0; k < 3; k++)
            x[k] = q[k] + v[k] * t;
        double ext = sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]) + rho + g * t;
        CHECK_NEAR(ext, sigma, 1e-12 * (1 + fabs(t))); /* residual of the root: round-off */
        for (int k = 0; k < 3; k++)
            x[k] = q[k] + v[k] * 0.5 * t;
        CHECK(sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]) + rho + g * 0.5 * t < sigma);
    }
}

static void run_walled_cube(int per_axis)
{
    int n = per_axis * per_axis * per_axis;
    pk_box b;
    pk_particles p;
    pk_edmd_params prm;
    setup(&b, &p, &prm, 3, 1.0, 0, n, 0.1, 0.1);
    prm.until = PK_EDMD_UNTIL_JAMMED;
    prm.growth_rate = 0.02;
    prm.seed = 3;
    pk_edmd_stats st;
    CHECK(pk_edmd_run(&b, &p, &prm, NULL, &st) == 0);
    /* Titscher §6.1: N = 1 and N = 8 equal spheres jam at π/6 (sphere of the
     * cube's edge, simple cubic).  The run ends when events come faster than
     * 1e-13 per 1000 (stall detector), i.e. gaps of ~1e-13: φ is within 1e-9
     * of π/6 well before that — 1e-6 leaves margin for the 8-sphere cage. */
    CHECK_NEAR(st.phi, M_PI / 6, 1e-6);
    CHECK(st.reason == PK_STOP_JAMMED || st.reason == PK_STOP_STALLED);
    check_no_overlap(&b, &p, 0);
    printf("  walled cube N=%d: phi=%.9f (%s/%s) events=%llu\n", n, st.phi,
           pk_stop_reason_name(st.reason), pk_edmd_criterion_name(st.criterion),
           (unsigned long long)st.events);
    pk_particles_free(&p);
}

static void test_walled_cube_one(void) { run_walled_cube(1); }
static void test_walled_cube_eight(void) { run_walled_cube(2); }

/* 3D periodic monodisperse from zero radii to a target φ: stops exactly
 * there (φ of the true radii equal to the target to 1e-12: bisection on the
 * growth polynomial), no overlap. */
static void test_target_phi_exact(void)
{
    int n = 300;
    pk_box b;
    pk_particles p;
    pk_edmd_params prm;
    setup(&b, &p, &prm, 3, cube_edge(n, 0.5, 0.55), 1, n, 0.5, 0.5);
    prm.phi_target = 0.5;
    prm.growth_rate = 0.05;
    pk_edmd_stats st;
    CHECK(pk_edmd_run(&b, &p, &prm, NULL, &st) == 0);
    CHECK(st.reason == PK_STOP_COMPLETE);
    double phi = pk_particles_solid_measure(&p) / pk_box_measure(&b);
    CHECK_NEAR(phi, 0.5, 1e-12);
    check_no_overlap(&b, &p, 0);
    pk_particles_free(&p);
}

/* Polydisperse 2D walled box with Δd: true radii at target, every gap ≥ Δd. */
static void test_walled_2d_delta_d(void)
{
    int n = 400;
    pk_box b;
    pk_particles p;
    pk_edmd_params prm;
    setup(&b, &p, &prm, 2, 45, 0, n, 0.5, 1.6); /* φ = 0.51 at the target sizes */
    b.periodic[1] = 1;                          /* mixed: walls on x, periodic on y */
    prm.delta_d = 0.1;
    prm.growth_rate = 0.05;
    pk_edmd_stats st;
    CHECK(pk_edmd_run(&b, &p, &prm, NULL, &st) == 0);
    CHECK(st.reason == PK_STOP_COMPLETE);
    CHECK_NEAR(p.r[0], 1.6, 1e-12);
    CHECK_NEAR(p.r[1], 0.5, 1e-12);
    check_no_overlap(&b, &p, 0.1);
    pk_particles_free(&p);
}

/* Kinetic-energy rescaling: with a tight tolerance it must fire (and the
 * re-prediction after it must keep the packing overlap-free) and hold K;
 * switched off it must never fire, and the growth push then raises K (the
 * switch changes the run: it once changed nothing). */
static void test_rescale_switch(void)
{
    double phi[2], kr[2];
    for (int on = 0; on <= 1; on++) {
        int n = 300;
        pk_box b;
        pk_particles p;
        pk_edmd_params prm;
        setup(&b, &p, &prm, 3, cube_edge(n, 0.5, 0.5), 1, n, 0.5, 0.5);
        prm.phi_target = 0.55;
        prm.growth_rate = 0.1;
        prm.rescale = on;
        prm.rescale_tol = 1e-2;
        pk_edmd_stats st;
        CHECK(pk_edmd_run(&b, &p, &prm, NULL, &st) == 0);
        CHECK(on ? st.rescales > 0 : st.rescales == 0);
        CHECK(st.reason == PK_STOP_COMPLETE);
        phi[on] = st.phi;
        kr[on] = st.kinetic_ratio;
        check_no_overlap(&b, &p, 0);
        pk_particles_free(&p);
    }
    printf("  K/K0 at phi 0.55: rescale off %.3g, on %.3g\n", kr[0], kr[1]);
    CHECK_NEAR(phi[0], phi[1], 1e-12);
    CHECK_MSG(kr[0] > 2, "K/K0 without rescaling %g", kr[0]);
    CHECK_MSG(fabs(kr[1] - 1) <= 0.011, "K/K0 with rescaling %g", kr[1]);
}

/* Titscher §6.2 start: RSA at δ·d with Δd, relative growth to the target
 * sizes at t_end = (1 − δ)/γ (Eq. 30); then Titscher §6.3: RSA without Δd,
 * the shell grows to Δd exactly (Eq. 31). */
static void test_rsa_start_relative_and_shell(void)
{
    int n = 200;
    pk_box b;
    box_cube(&b, 3, 12, 0);
    double *d = malloc((size_t)n * sizeof *d);
    int32_t *sp = calloc((size_t)n, sizeof *sp);
    for (int i = 0; i < n; i++)
        d[i] = i < 20 ? 2.0 : 1.0; /* descending */
    for (int shell = 0; shell <= 1; shell++) {
        pk_particles p;
        pk_particles_init(&p, 3, (size_t)n);
        pk_rsa_stats rs;
        double delta = shell ? 1.0 : 0.9, dd = 0.1;
        CHECK(pk_edmd_start_rsa(&b, d, sp, (size_t)n, delta, shell ? 0 : dd, 5, NULL, &p, &rs) ==
              0);
        CHECK(rs.placed == (size_t)n);
        pk_edmd_params prm;
        pk_edmd_params_default(&prm);
        prm.start_zero = 0;
        prm.delta = delta;
        prm.delta_d = dd;
        prm.growth = shell ? PK_EDMD_GROW_SHELL : PK_EDMD_GROW_RELATIVE;
        prm.growth_rate = 0.05;
        pk_edmd_stats st;
        CHECK(pk_edmd_run(&b, &p, &prm, NULL, &st) == 0);
        CHECK(st.reason == PK_STOP_COMPLETE);
        CHECK_NEAR(st.delta_d, dd, 1e-12);
        CHECK_NEAR(st.t_end, shell ? dd / (0.05 * (20 * 2.0 + 180 * 1.0) / n) : 0.1 / 0.05, 1e-9);
        CHECK_NEAR(p.r[0], 1.0, 1e-12); /* true radii at the target */
        CHECK_NEAR(p.r[n - 1], 0.5, 1e-12);
        check_no_overlap(&b, &p, dd);
        pk_particles_free(&p);
    }
    free(d);
    free(sp);
}

/* The default start's δ (pk_edmd_start_delta): the start's spheres δ·d/2 +
 * Δd/2, summed directly, fill exactly φ = 0.30 of the box (bisection to
 * 2^-60 of δ: 1e-12 relative is far above it); δ is capped at Titscher's
 * 0.9 when that fill stays below 0.30, and 0 when the shells alone exceed
 * it. */
static void test_start_delta(void)
{
    double d[300];
    for (int i = 0; i < 300; i++)
        d[i] = i < 30 ? 4.0 : i < 120 ? 2.0 : 1.0;
    for (int dim = 2; dim <= 3; dim++) {
        const double V = dim == 2 ? 40.0 * 40.0 : 14.0 * 14.0 * 14.0, dd = 0.05;
        const double delta = pk_edmd_start_delta(dim, d, 300, dd, V, 0.30);
        CHECK(delta > 0 && delta < 0.9);
        double filled = 0;
        for (int i = 0; i < 300; i++)
            filled += pk_ball_measure(dim, 0.5 * delta * d[i] + 0.5 * dd);
        CHECK_NEAR(filled / V, 0.30, 1e-12);
        CHECK(pk_edmd_start_delta(dim, d, 300, dd, 10 * V, 0.30) == 0.9);
        CHECK(pk_edmd_start_delta(dim, d, 300, 3.0, V, 0.30) == 0);
    }
}

/* From RESORT_MIN_N = 32768 grains on the engine renumbers the grains along
 * a Z-order curve every 10·N events and rebuilds lists and events there:
 * the result must stay overlap-free, give every grain its own size in the
 * caller's order (relative growth: r_i / target_i the same for all, to
 * round-off), and repeat bit for bit with the same seed.  N = 40000 from
 * zero radii to φ = 0.3 at a fast rate: 5.7·10⁵ events, one renumbering. */
static void test_renumbering_large_n(void)
{
    const int n = 40000;
    pk_box b;
    pk_particles p, q;
    pk_edmd_params prm;
    setup(&b, &p, &prm, 3, cube_edge(n, 0.5, 0.5), 1, n, 0.5, 0.7);
    pk_particles_init(&q, 3, (size_t)n);
    for (int i = 0; i < n; i++)
        pk_particles_push(&q, &p.x[3 * i], p.r[i], 0);
    prm.phi_target = 0.3;
    prm.growth_rate = 0.5;
    prm.rule = PK_EDMD_RULE_LIFT; /* the event count above (the default rule: 2.3·10⁵) */
    pk_edmd_stats st, st2;
    CHECK(pk_edmd_run(&b, &p, &prm, NULL, &st) == 0);
    CHECK(pk_edmd_run(&b, &q, &prm, NULL, &st2) == 0);
    CHECK(st.reason == PK_STOP_COMPLETE);
    CHECK_MSG(st.resorts >= 1, "%llu renumberings", (unsigned long long)st.resorts);
    CHECK(st2.events == st.events);
    CHECK(memcmp(p.x, q.x, 3 * (size_t)n * sizeof *p.x) == 0);
    CHECK(memcmp(p.r, q.r, (size_t)n * sizeof *p.r) == 0);
    const double scale = p.r[1] / 0.5;
    for (int i = 0; i < n; i++)
        CHECK_NEAR(p.r[i] / (i % 4 == 0 ? 0.7 : 0.5), scale, 1e-12 * scale);
    check_no_overlap(&b, &p, 0);
    printf("  N=%d: events=%llu renumberings=%llu phi=%.6f\n", n, (unsigned long long)st.events,
           (unsigned long long)st.resorts, st.phi);
    pk_particles_free(&p);
    pk_particles_free(&q);
}

/* Cancels once the run has made progress (events done), not after a time. */
typedef struct {
    size_t cancel_at, done_at_cancel;
    int calls_after_cancel, cancelled;
} cancel_probe;

static int cancel_when_done(const pk_progress *pr, void *ctx)
{
    cancel_probe *c = ctx;
    if (c->cancelled)
        c->calls_after_cancel++;
    else if (pr->done >= c->cancel_at) {
        c->cancelled = 1;
        c->done_at_cancel = pr->done;
    }
    return c->cancelled;
}

/* Cancel via the callback: the run stops at that check (the events count no
 * further than the check's stride of 1024) and says it was cancelled.  Its
 * growth rate would run for minutes; max_events is only a hang guard (a run
 * that ignored the cancel ends there, with another reason). */
static void test_cancel(void)
{
    int n = 2000;
    pk_box b;
    pk_particles p;
    pk_edmd_params prm;
    setup(&b, &p, &prm, 3, cube_edge(n, 0.5, 0.6), 1, n, 0.5, 0.5);
    prm.until = PK_EDMD_UNTIL_JAMMED;
    prm.growth_rate = 1e-4;
    prm.max_events = 50000000;
    cancel_probe probe = {.cancel_at = 200000};
    pk_monitor mon = {.fn = cancel_when_done, .ctx = &probe, .interval_s = 1e-9};
    pk_edmd_stats st;
    CHECK(pk_edmd_run(&b, &p, &prm, &mon, &st) == 0);
    CHECK_MSG(st.reason == PK_STOP_CANCELLED, "stop reason %d", (int)st.reason);
    CHECK(probe.cancelled && probe.calls_after_cancel == 0);
    CHECK_MSG(st.events >= probe.done_at_cancel && st.events < probe.done_at_cancel + 1024,
              "events %llu, cancelled at %zu", (unsigned long long)st.events, probe.done_at_cancel);
    check_no_overlap(&b, &p, 0);
    pk_particles_free(&p);
}

int main(void)
{
    RUN(test_pair_time_cancellation_free);
    RUN(test_pair_time_touching_cases);
    RUN(test_pair_time_random);
    RUN(test_exit_time);
    RUN(test_walled_cube_one);
    RUN(test_walled_cube_eight);
    RUN(test_target_phi_exact);
    RUN(test_walled_2d_delta_d);
    RUN(test_rescale_switch);
    RUN(test_rsa_start_relative_and_shell);
    RUN(test_start_delta);
    RUN(test_renumbering_large_n);
    RUN(test_cancel);
    return check_summary();
}
