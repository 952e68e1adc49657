/* test_homog_relax_geom.c — DR and FIRE evaluate their iterations with
 * pk_dem_eval_forces (the pair geometry l, |l|, ε not stored) and put the
 * geometry of x back before its readers (the estimates' rattlers,
 * Gershgorin and Lanczos), before a hook and on return
 * (pk_relax_geom_refresh).  Checked: the whole relaxation — x, iterations,
 * refreshes, λ estimates, |f| — bit for bit the same as with the geometry
 * stored by every evaluation (pk_dem_forces_store = 1), and the pair data
 * at each hook call and on return equal to a fresh pk_dem_eval at x. */
#include "check.h"
#include "core/homog/homog_eigen.h"
#include "core/homog/homog_fire.h"
#include "homog_fixture.h"

/* The pair data of c equal those of a fresh evaluation at x? */
static int geometry_is_fresh(relax_problem *pb, const double *x)
{
    pk_dem_pairs *c = &pb->c;
    size_t n = c->n;
    double *l = malloc(3 * (n + 1) * sizeof *l), *le = malloc(2 * (n + 1) * sizeof *le);
    memcpy(l, c->l, 3 * n * sizeof *l);
    memcpy(le, c->len, n * sizeof *le);
    memcpy(le + n, c->eps, n * sizeof *le);
    pk_dem_eval(c, &pb->g, x, pb->rve.r, pb->rve.n, pb->o.E_n, NULL, NULL, NULL);
    int same = memcmp(l, c->l, 3 * n * sizeof *l) == 0 && memcmp(le, c->len, n * sizeof *le) == 0 &&
        memcmp(le + n, c->eps, n * sizeof *le) == 0;
    free(l), free(le);
    return same;
}

typedef struct hook_ctx {
    relax_problem *pb;
    int calls, stale;
} hook_ctx;

/* Looks at DR's pair data and lets it go on (the next call at |f|/10). */
static int look(void *vctx, double *x, double *fres, double *at)
{
    hook_ctx *h = vctx;
    h->calls++;
    h->stale += !geometry_is_fresh(h->pb, x);
    *at = 0.1 * *fres;
    return 0;
}

typedef struct outcome {
    double *x;
    size_t n;
    pk_dr_stats st;
    int calls, stale_at_hook, fresh_at_return;
} outcome;

static outcome relax(int store, int fire)
{
    relax_problem pb; /* (homog_fixture.h) relaxed from its affine start x0 in place */
    relax_problem_make(&pb);
    pk_dem_system sys = relax_problem_system(&pb);
    pb.o.dr.refresh = 25; /* many estimates, each after a forces-only evaluation */
    hook_ctx h = {&pb, 0, 0};
    pk_dr_hook hook = {.fn = look, .ctx = &h, .at = 1e-3};
    outcome o = {0};
    pk_dem_forces_store = store;
    pk_fire_params fp = pk_fire_params_default();
    int rc = fire ? pk_homog_fire_hooked(&sys, pb.x0, &pb.o.dr, &fp, &hook, NULL, &o.st)
                  : pk_homog_relax_hooked(&sys, pb.x0, &pb.o.dr, &hook, NULL, &o.st);
    pk_dem_forces_store = 0;
    CHECK(rc == 0);
    CHECK(pk_dr_stop_ok(o.st.stop));
    o.calls = h.calls;
    o.stale_at_hook = h.stale;
    o.fresh_at_return = geometry_is_fresh(&pb, pb.x0);
    o.n = pb.rve.n;
    size_t n3 = 3 * pb.rve.n;
    o.x = malloc(n3 * sizeof *o.x);
    memcpy(o.x, pb.x0, n3 * sizeof *o.x);
    relax_problem_free(&pb);
    return o;
}

static void same_bits(int fire)
{
    outcome a = relax(1, fire), b = relax(0, fire);
    printf("  %s: %zu iterations, %zu refreshes, %d hook calls\n", fire ? "FIRE" : "DR",
           b.st.iterations, b.st.refreshes, b.calls);
    CHECK(b.st.iterations > 50);
    CHECK(fire || b.st.refreshes >= 2); /* DR: estimates after forces-only evaluations */
    CHECK(b.calls >= 2);
    CHECK(a.calls == b.calls);
    CHECK(a.stale_at_hook == 0 && b.stale_at_hook == 0);
    CHECK(a.fresh_at_return && b.fresh_at_return);
    CHECK(a.st.iterations == b.st.iterations && a.st.refreshes == b.st.refreshes &&
          a.st.rebuilds == b.st.rebuilds && a.st.rattlers == b.st.rattlers);
    CHECK(memcmp(&a.st.f, &b.st.f, sizeof a.st.f) == 0);
    CHECK(memcmp(&a.st.lambda_min, &b.st.lambda_min, sizeof a.st.lambda_min) == 0);
    CHECK(memcmp(&a.st.lambda_max, &b.st.lambda_max, sizeof a.st.lambda_max) == 0);
    CHECK(a.n == b.n && memcmp(a.x, b.x, 3 * a.n * sizeof *a.x) == 0);
    free(a.x), free(b.x);
}

static void test_dr(void) { same_bits(0); }
static void test_fire(void) { same_bits(1); }

int main(void)
{
    RUN(test_dr);
    RUN(test_fire);
    return check_summary();
}
