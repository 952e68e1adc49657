/* test_homog_speculative.c — the Newton/DR hybrid with speculative attempts
 * (core/homog/homog_speculative.c: a pool of two threads or more)
 * gives the serial hybrid's step bit for bit: the end point, P̄, the energy
 * and every statistic of the path (DR/FIRE iterations, rebuilds, stop,
 * residuals, factorisations, quasi-Newton steps, attempts, FIRE
 * iterations, exit).  The cases cover each way a step can end: the Newton
 * phase from the start converges (elastic step); an attempt from one of DR's
 * points wins; attempts fail until FIRE has taken over and one from FIRE's
 * points wins; no attempt is made at all (factorisation budget spent after
 * the first phase: the relaxation ends alone). */
#include "check.h"
#include "homog_fixture.h"
#include "core/base/par.h"
#include "api/solver/sparse_cholmod.h"

typedef struct run {
    pk_homog_state t;
    pk_homog_step s;
} run;

static void step(const pk_homog_rve *rve, const pk_homog_opts *o, const double F[9], int threads,
                 run *out)
{
    pk_homog_opts on = *o;
    on.par = threads > 1 ? pk_par_new(threads) : NULL;
    CHECK(threads <= 1 || on.par);
    memset(out, 0, sizeof *out);
    CHECK(step_from_reference(rve, &on, F, &out->t, &out->s) == 0);
    pk_par_free(on.par);
}

static int same_bits(const void *a, const void *b, size_t n) { return memcmp(a, b, n) == 0; }

/* Every output of step b equal to a's, bit for bit. */
static void check_same(const pk_homog_rve *rve, const run *a, const run *b, const char *what)
{
    const pk_homog_step *x = &a->s, *y = &b->s;
    CHECK_MSG(same_bits(a->t.x, b->t.x, 3 * rve->n * sizeof *a->t.x), "%s: end points differ",
              what);
    CHECK_MSG(same_bits(x->P, y->P, sizeof x->P) &&
                  same_bits(&x->energy, &y->energy, sizeof x->energy),
              "%s: P̄ or Φ differ", what);
    CHECK_MSG(x->dr.iterations == y->dr.iterations && x->dr.rebuilds == y->dr.rebuilds &&
                  x->dr.refreshes == y->dr.refreshes && x->dr.stop == y->dr.stop &&
                  same_bits(&x->dr.f, &y->dr.f, sizeof x->dr.f) &&
                  same_bits(&x->dr.f0, &y->dr.f0, sizeof x->dr.f0) &&
                  same_bits(&x->dr.dt, &y->dr.dt, sizeof x->dr.dt),
              "%s: relaxation statistics differ (iterations %zu/%zu, rebuilds %zu/%zu, stop %d/%d)",
              what, x->dr.iterations, y->dr.iterations, x->dr.rebuilds, y->dr.rebuilds, x->dr.stop,
              y->dr.stop);
    const pk_newton_stats *m = &x->newton, *n = &y->newton;
    CHECK_MSG(m->iterations == n->iterations && m->steps == n->steps && m->cuts == n->cuts &&
                  m->attempts == n->attempts && m->shifts == n->shifts &&
                  m->fire_iterations == n->fire_iterations && m->exit == n->exit &&
                  m->reused == n->reused,
              "%s: Newton statistics differ (factorisations %zu/%zu, steps %zu/%zu, attempts "
              "%zu/%zu, FIRE %zu/%zu, exit %d/%d)",
              what, m->iterations, n->iterations, m->steps, n->steps, m->attempts, n->attempts,
              m->fire_iterations, n->fire_iterations, m->exit, n->exit);
    CHECK_MSG(x->contacts == y->contacts && x->rattlers == y->rattlers, "%s: contacts differ",
              what);
}

static void jammed(size_t n, double phi, uint64_t seed, pk_particles *p, pk_homog_rve *rve)
{
    pk_box b;
    make_jammed(2, n, phi, seed, &b, p);
    char err[128];
    CHECK(pk_homog_rve_build(&b, p, PK_BC_PERIODIC, 1.0, rve, err, sizeof err) == 0);
}

/* how the serial step ended, for the case list */
enum end { FIRST_PHASE, FROM_DR, FROM_FIRE, ALONE };

static enum end how_it_ended(const pk_homog_step *s)
{
    if (s->dr.iterations == 0)
        return FIRST_PHASE;
    if (s->newton.exit != PK_NEWTON_CONVERGED)
        return ALONE;
    return s->newton.fire_iterations ? FROM_FIRE : FROM_DR;
}

static void test_same_step_as_serial(void)
{
    const struct {
        size_t n;
        double phi, strain;
        uint64_t seed;
        size_t max_newton;
        enum end end; /* the serial path this case exercises */
    } cases[] = {
        {400, 0.90, 0.001, 1, 50, FIRST_PHASE}, /* dense, small step: elastic */
        {200, 0.86, 0.01, 2, 50, FROM_DR},
        {400, 0.88, 0.01, 5, 50, FROM_FIRE}, /* test_homog_newton's climbing case */
        {800, 0.86, 0.01, 1, 50, FROM_FIRE},
        {400, 0.88, 0.01, 5, 1, ALONE}, /* the budget spent by the first phase */
    };
    for (size_t k = 0; k < sizeof cases / sizeof *cases; k++) {
        pk_particles p;
        pk_homog_rve rve;
        jammed(cases[k].n, cases[k].phi, cases[k].seed, &p, &rve);
        pk_homog_opts o = opts(1.0);
        o.dr.tol = 1e-10;
        o.newton = &pk_sparse_cholmod;
        o.newton_max_iter = cases[k].max_newton;
        double F[9];
        diagF(F, 1 - cases[k].strain, 1.0, 1.0);
        run serial, two, three;
        step(&rve, &o, F, 1, &serial);
        enum end e = how_it_ended(&serial.s);
        CHECK_MSG(e == cases[k].end, "case %zu: the serial step ended by path %d, expected %d", k,
                  (int)e, (int)cases[k].end);
        step(&rve, &o, F, 2, &two);
        step(&rve, &o, F, 3, &three);
        char what[64];
        snprintf(what, sizeof what, "case %zu, 2 threads", k);
        check_same(&rve, &serial, &two, what);
        snprintf(what, sizeof what, "case %zu, 3 threads", k);
        check_same(&rve, &serial, &three, what);
        printf("  %zu grains seed %lu budget %zu: %zu factorisations, %zu attempts, %zu DR/FIRE "
               "iterations (%zu FIRE), path %d — the same bits on 2 and 3 threads\n",
               cases[k].n, (unsigned long)cases[k].seed, cases[k].max_newton,
               serial.s.newton.iterations, serial.s.newton.attempts, serial.s.dr.iterations,
               serial.s.newton.fire_iterations, (int)e);
        pk_homog_state_free(&serial.t);
        pk_homog_state_free(&two.t);
        pk_homog_state_free(&three.t);
        pk_homog_rve_free(&rve);
        pk_particles_free(&p);
    }
}

/* A cancel while the worker has attempts under way or queued: the step
 * returns promptly, cancelled, on 1 and on 2 threads (the worker stops at
 * its next factorisation or quasi-Newton step; ASan in `make sanitize`
 * checks that nothing is left behind). */
typedef struct cancel_after {
    int calls, at;
} cancel_after;

static int cancel_cb(const pk_progress *pr, void *ctx)
{
    (void)pr;
    cancel_after *c = ctx;
    return ++c->calls >= c->at;
}

static void test_cancel_mid_step(void)
{
    pk_particles p;
    pk_homog_rve rve;
    jammed(800, 0.86, 1, &p, &rve); /* 5 attempts, FIRE (test_same_step_as_serial) */
    pk_homog_opts o = opts(1.0);
    o.dr.tol = 1e-10;
    o.newton = &pk_sparse_cholmod;
    o.newton_max_iter = 50;
    double F[9];
    diagF(F, 0.99, 1.0, 1.0);
    for (int threads = 1; threads <= 2; threads++)
        for (int at = 2; at <= 40; at += 19) {
            pk_homog_opts on = o;
            on.par = threads > 1 ? pk_par_new(threads) : NULL;
            cancel_after c = {0, at};
            pk_monitor mon = {.fn = cancel_cb, .ctx = &c, .interval_s = 1e-9}; /* every tick */
            pk_monitor_begin(&mon);
            pk_homog_state s0, out = {0};
            CHECK(pk_homog_state_init(&rve, &on, &s0) == 0);
            pk_homog_step st;
            double t0 = pk_wall_seconds();
            int rc = pk_homog_eval(&rve, &on, &s0, F, &out, &st, &mon);
            double t = pk_wall_seconds() - t0;
            /* the uncancelled step takes ~0.1 s here; a hang would not return */
            CHECK_MSG(rc == 0 && st.dr.stop == PK_DR_CANCELLED,
                      "%d threads, cancel at call %d: rc %d, stop %s", threads, at, rc,
                      pk_dr_stop_name(st.dr.stop));
            printf("  %d thread(s), cancelled at the monitor's call %d: %s after %.3f s\n", threads,
                   at, pk_dr_stop_name(st.dr.stop), t);
            pk_homog_state_free(&s0);
            pk_homog_state_free(&out);
            pk_par_free(on.par);
        }
    pk_homog_rve_free(&rve);
    pk_particles_free(&p);
}

int main(void)
{
    RUN(test_same_step_as_serial);
    RUN(test_cancel_mid_step);
    return check_summary();
}
