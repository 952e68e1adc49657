/* test_homog_crawl.c — the crawl rule of the relaxation hook
 * (core/homog/homog_relax.h, pk_dr_hook.crawl; the Newton hybrid calls its next
 * attempt when DR creeps): pk_relax_iteration_end driven with made-up
 * residual sequences, so the iterations of the calls are known exactly. */
#include "check.h"
#include "core/homog/homog_relax.h"

/* The hook records the iterations it is called at and sets a threshold the
 * sequences never reach (only the crawl rule calls it again). */
typedef struct spy {
    pk_dr_stats st; /* the relaxation's statistics (iterations) */
    size_t n, iter[64];
} spy;

static int spy_fn(void *ctx, double *x, double *fres, double *at)
{
    (void)x, (void)fres;
    spy *s = ctx;
    if (s->n < 64)
        s->iter[s->n] = s->st.iterations;
    s->n++;
    *at = 1e-30;
    return 0;
}

/* Runs iterations 1..n with residual f(k) through pk_relax_iteration_end;
 * the first call comes when f <= 0.5 (hook.at). */
static void drive(double (*f)(size_t), size_t n, size_t crawl, spy *s)
{
    *s = (spy){.st = {.f0 = 1}};
    pk_dr_stats *st = &s->st;
    pk_dr_params prm = {.tol = 1e-20, .max_iter = 1000000};
    pk_dr_hook h = {.fn = spy_fn, .ctx = s, .at = 0.5, .crawl = crawl};
    pk_progress pr = {0};
    double x[3] = {0, 0, 0};
    for (size_t k = 0; k < n; k++) {
        st->iterations = k + 1;
        st->f = f(k + 1);
        CHECK(pk_relax_iteration_end(st, &prm, 1e-25, k, x, &h, NULL, &pr, NULL) == 0);
    }
}

/* a creep: 0.1 % less per iteration, never rising (0.5 at iteration 693) */
static double creep(size_t k) { return pow(0.999, (double)k); }

/* the creep, but 50 iterations after the first call the residual jumps up
 * (an event under way) and creeps down from there, never back to 0.5 */
static double event(size_t k) { return k < 743 ? creep(k) : 4 * creep(k); }

static void test_creep_calls_every_crawl_iterations(void)
{
    spy s;
    drive(creep, 2000, 200, &s);
    /* first call where f <= 0.5 (iteration 693), then every 200 iterations
     * of creep: 893, 1093, …, 1893 */
    CHECK_MSG(s.n == 7, "%zu calls", s.n);
    CHECK(s.iter[0] == 693);
    for (size_t c = 1; c < s.n && c < 64; c++)
        CHECK_MSG(s.iter[c] == s.iter[c - 1] + 200, "call %zu at %zu", c, s.iter[c]);
}

static void test_no_crawl_call_after_a_rise_or_without_crawl(void)
{
    spy s;
    drive(event, 2000, 200, &s);
    CHECK_MSG(s.n == 1 && s.iter[0] == 693, "%zu calls", s.n);
    drive(creep, 2000, 0, &s);
    CHECK_MSG(s.n == 1 && s.iter[0] == 693, "%zu calls", s.n);
}

int main(void)
{
    RUN(test_creep_calls_every_crawl_iterations);
    RUN(test_no_crawl_call_after_a_rise_or_without_crawl);
    return check_summary();
}
