/* test_homog_audit.c — the per-step audit of a homogenization (core/homog/homog_audit.h)
 * and the job clock of the wall-time limit (core/base/progress.h, issue 21 case 1). */
#include "check.h"

#include <math.h>
#include <string.h>

#include "core/homog/homog_audit.h"
#include "core/space/mat3.h"
#include "core/base/progress.h"

/* A limit set on a monitor nobody began (as pk_homog_run did): the clock must
 * start with the job, not at the machine's boot — a limit of half the
 * monotonic clock's reading (far above the test's run time, below the
 * uptime) must not stop it, and elapsed_s starts near 0. */
static int seen;
static double first_elapsed;
static int note(const pk_progress *p, void *ctx)
{
    (void)ctx;
    if (!seen++)
        first_elapsed = p->elapsed_s;
    return 0;
}

static void test_wall_limit_counts_from_the_job(void)
{
    double now = pk_wall_seconds();
    CHECK(now > 2); /* the monotonic clock counts from boot */
    pk_monitor m = {.fn = note};
    m.wall_limit_s = now / 2;
    pk_progress p = {.stage = "t"};
    seen = 0;
    CHECK(pk_monitor_tick(&m, &p, 1) == 0);
    CHECK(seen == 1 && first_elapsed < 1);

    pk_monitor m2 = {.fn = note};
    pk_monitor_start(&m2, now / 2);
    seen = 0;
    CHECK(pk_monitor_tick(&m2, &p, 1) == 0);
    CHECK(seen == 1 && first_elapsed < 1);
    pk_monitor_begin(&m2); /* a later stage restarts elapsed_s, not the job's clock */
    CHECK(pk_monitor_tick(&m2, &p, 1) == 0);

    pk_monitor m3 = {0}; /* a tiny limit does stop the job */
    pk_monitor_start(&m3, 1e-9);
    double t0 = pk_wall_seconds();
    while (pk_wall_seconds() - t0 < 1e-6) {}
    CHECK(pk_monitor_tick(&m3, &p, 0) == 2);
}

/* 4 prescribed corners and one free grain in a 4×4 box */
static void rve_of(pk_homog_bc bc, pk_homog_rve *rve)
{
    double X[15] = {0, 0, 0, 4, 0, 0, 0, 4, 0, 4, 4, 0, 2, 2, 0}, r[5] = {1, 1, 1, 1, 0.5};
    uint8_t fixed[5] = {1, 1, 1, 1, 0};
    double L[3] = {4, 4, 0};
    CHECK(pk_homog_rve_from_arrays(2, bc, 5, X, r, fixed, bc == PK_BC_PERIODIC, L, 16, rve) == 0);
}

static void good_step(pk_homog_step *st, pk_homog_opts *o)
{
    memset(st, 0, sizeof *st);
    memset(o, 0, sizeof *o);
    o->dr.tol = 1e-8;
    o->dr.abs_floor = 1e-13;
    st->dr.stop = PK_DR_CONVERGED;
    st->dr.f0 = 1;
    st->dr.f = 0.5e-8;
    st->free_force = 0.5e-8;
    st->max_overlap_ratio = 0.1;
    st->J = 1;
    st->P[0] = st->sigma[0] = -1;
}

static void test_audit_checks(void)
{
    for (int b = 0; b < 2; b++) {
        pk_homog_bc bc = b ? PK_BC_PERIODIC : PK_BC_RESTRICTED_TAYLOR;
        pk_homog_rve rve;
        rve_of(bc, &rve);
        pk_homog_state s = {.n = 5};
        double x[15];
        memcpy(x, rve.X, sizeof x);
        s.x = x;
        pk_m3_identity(s.F);
        pk_homog_step st;
        pk_homog_opts o;
        pk_homog_audit a;
        good_step(&st, &o);
        CHECK(pk_homog_audit_step(&rve, &o, &s, &st, &a) == 0);
        CHECK_NEAR(a.residual_ratio, 0.5, 1e-12);

        st.dr.stop =
            PK_DR_MAX_ITER; /* a step at max_iter is not converged, whatever its residual */
        CHECK(pk_homog_audit_step(&rve, &o, &s, &st, &a) == PK_AUDIT_NOT_CONVERGED);
        good_step(&st, &o);
        st.dr.f = 2e-8;
        CHECK(pk_homog_audit_step(&rve, &o, &s, &st, &a) & PK_AUDIT_NOT_CONVERGED);
        good_step(&st, &o);
        st.free_force = 3e-8;
        CHECK(pk_homog_audit_step(&rve, &o, &s, &st, &a) == PK_AUDIT_UNBALANCED);
        good_step(&st, &o);
        st.max_overlap_ratio = 1.2;
        CHECK(pk_homog_audit_step(&rve, &o, &s, &st, &a) == PK_AUDIT_OVERLAP);
        good_step(&st, &o);
        st.P[3] = NAN;
        CHECK(pk_homog_audit_step(&rve, &o, &s, &st, &a) == PK_AUDIT_NOT_FINITE);
        good_step(&st, &o);
        st.energy = INFINITY;
        CHECK(pk_homog_audit_step(&rve, &o, &s, &st, &a) == PK_AUDIT_NOT_FINITE);

        /* containment: restricted Taylor — the centre in the box; periodic — a
         * fluctuation shorter than the cell */
        good_step(&st, &o);
        x[12] = 4.5; /* beyond the right side, inside one cell of fluctuation */
        unsigned f = pk_homog_audit_step(&rve, &o, &s, &st, &a);
        CHECK(f == (bc == PK_BC_PERIODIC ? 0u : (unsigned)PK_AUDIT_ESCAPED));
        x[12] = 2 + 775; /* issue 21: an inner grain at +775 mm in a cell of 20 */
        CHECK(pk_homog_audit_step(&rve, &o, &s, &st, &a) == PK_AUDIT_ESCAPED);
        CHECK(a.outside == 1 && a.escape > 100);
        x[12] = NAN;
        CHECK(pk_homog_audit_step(&rve, &o, &s, &st, &a) & PK_AUDIT_NOT_FINITE);
        x[12] = 2;
        /* under F̄ the cell deforms with it */
        double F[9] = {0.8, 0.1, 0, 0, 0.9, 0, 0, 0, 1};
        memcpy(s.F, F, sizeof F);
        pk_m3_vec(F, &rve.X[12], &x[12]);
        CHECK(pk_homog_audit_step(&rve, &o, &s, &st, &a) == 0);
        pk_homog_rve_free(&rve);
    }
}

int main(void)
{
    RUN(test_wall_limit_counts_from_the_job);
    RUN(test_audit_checks);
    return check_summary();
}
