/* homog_relax.c — dynamic relaxation of the free particles (Meier 2009 §4.4)
 * and the iteration parts it shares with FIRE.  Contract: homog_relax.h. */
#include "homog_relax.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/dem/dem_rattler.h"
#include "homog_eigen.h"

const char *pk_dr_stop_name(pk_dr_stop s)
{
    switch (s) {
    case PK_DR_CONVERGED: return "converged";
    case PK_DR_CONVERGED_ABS: return "converged_absolute";
    case PK_DR_NOT_NEEDED: return "not_needed";
    case PK_DR_MAX_ITER: return "max_iter";
    case PK_DR_CANCELLED: return "cancelled";
    case PK_DR_WALL_TIME: return "wall_time";
    case PK_DR_HANDED_OVER: return "handed_over";
    }
    return "unknown";
}

int pk_dr_stop_ok(pk_dr_stop s)
{
    return s == PK_DR_CONVERGED || s == PK_DR_CONVERGED_ABS || s == PK_DR_NOT_NEEDED;
}

/* (4.47): Δt = 2/√(λmin+λmax), γ = 2√(λmin λmax/(λmin+λmax)) */
static void optimal_params(pk_dr_stats *st)
{
    double lmin = st->lambda_min, lmax = st->lambda_max;
    st->dt = 2 / sqrt(lmin + lmax);
    st->gamma = 2 * sqrt(lmin * lmax / (lmin + lmax));
}

/* One relaxation: the system, its friction and the work arrays of the
 * estimates. */
typedef struct relax_run {
    const pk_dem_system *s;
    pk_fric_ctx *fc; /* NULL: frictionless */
    int fric_active;
    int lanczos; /* Lanczos steps of an estimate */
    uint8_t *rat, *mask;
    double *work;
} relax_run;

/* Forces at (x, u): normal (4.10) plus, with friction, tangential (7.19) and
 * couples gu (7.23).  -1 on allocation failure. */
static int forces(const relax_run *R, const double *x, const double *u, double *f, double *gu,
                  pk_fric_totals *tot)
{
    const pk_dem_system *s = R->s;
    pk_dem_eval(s->c, s->g, x, s->r, s->np, s->E, f, NULL, NULL);
    if (!R->fc)
        return 0;
    return pk_dem_fric_eval(s->c, R->fc, x, u, s->r, s->np, s->E, f, gu, NULL, tot);
}

void pk_relax_geom_refresh(pk_relax_geom *gm, const double *x)
{
    if (gm->fresh)
        return;
    const pk_dem_system *s = gm->s;
    pk_dem_eval(s->c, s->g, x, s->r, s->np, s->E, NULL, NULL, NULL);
    gm->fresh = 1;
}

static double resid_norm(const relax_run *R, const double *f, const double *gu, const double *v,
                         double *fv)
{
    const pk_dem_system *s = R->s;
    double a = sqrt(v ? pk_homog_dot2_mask(f, f, v, s->is_free, s->np, s->g->dim, fv)
                      : pk_homog_dot_mask(f, f, s->is_free, s->np, s->g->dim)),
           b = 0;
    if (R->fc)
        for (size_t i = 0; i < s->np; i++)
            b += gu[i] * gu[i];
    return sqrt(a * a + b);
}

/* Rayleigh quotient vᵀKv/vᵀv of the frictional system along the residual v,
 * by a forward difference of the force (K = −∂F/∂z); restores the pair data
 * at (x, u).  0 when not available. */
static double fric_rayleigh(const relax_run *R, double *x, double *u, const double *f,
                            const double *gu, double *work)
{
    const pk_dem_system *s = R->s;
    const int dim = s->g->dim;
    size_t np = s->np;
    double vv = 0, rmean = 0;
    for (size_t i = 0; i < np; i++) {
        rmean += s->r[i] / (double)np;
        vv += gu[i] * gu[i];
        if (s->is_free[i])
            for (int a = 0; a < dim; a++)
                vv += f[3 * i + a] * f[3 * i + a];
    }
    if (!(vv > 0))
        return 0;
    double eta = 1e-7 * rmean / sqrt(vv); /* a step of 1e-7 r̄ */
    double *f2 = work, *g2 = work + 3 * np;
    for (size_t i = 0; i < np; i++) {
        u[i] += eta * gu[i];
        if (s->is_free[i])
            for (int a = 0; a < dim; a++)
                x[3 * i + a] += eta * f[3 * i + a];
    }
    int rc = forces(R, x, u, f2, g2, NULL);
    double num = 0;
    for (size_t i = 0; i < np; i++) {
        u[i] -= eta * gu[i];
        num -= (g2[i] - gu[i]) * gu[i];
        if (s->is_free[i])
            for (int a = 0; a < dim; a++) {
                x[3 * i + a] -= eta * f[3 * i + a];
                num -= (f2[3 * i + a] - f[3 * i + a]) * f[3 * i + a];
            }
    }
    if (rc != 0 || forces(R, x, u, f2, g2, NULL) != 0)
        return NAN;
    return num / (eta * vv);
}

/* Fresh estimates on the jammed free grains (rattlers re-detected):
 * λ_max by Gershgorin, λ_min by Lanczos, lowered further by the Rayleigh
 * quotient of the current residual f (dominated by the slow modes late in a
 * relaxation).  A non-positive λ_min (indefinite block under large overlaps,
 * or no jammed grain) falls back to the residual's Rayleigh quotient on the
 * free grains, and only then to a tiny share of λ_max (flagged).
 * λ_min also from the Rayleigh quotient of DR's own increments since the
 * last estimate, Σ −Δx·Δf / Σ Δx·Δx (adaptive DR, Underwood 1983,
 * Papadrakakis 1981), its magnitude when negative (DR then crosses a
 * region of negative curvature: a plastic event), unless
 * pk_dr_params.plain_lambda_min.  Late in a relaxation the increments run
 * along the softest modes, which a 40-step Lanczos run misses by orders of
 * magnitude near jamming, over-damping DR there (with the increments DR
 * alone takes 5–17× fewer iterations near jamming: docs/perf/homog.md).
 * The two sums ride on the move and on the residual's pass. */
static int estimate(const relax_run *R, const double *f, double *x, double *u, const double *gu,
                    double inc_rq, pk_dr_stats *st)
{
    pk_dem_pairs *c = R->s->c;
    const int dim = R->s->g->dim;
    const size_t np = R->s->np;
    const double E = R->s->E;
    const uint8_t *is_free = R->s->is_free;
    uint8_t *rat = R->rat, *mask = R->mask;
    double *work = R->work;
    size_t nr = pk_dem_rattlers(c, dim, np, is_free, rat);
    if (nr == (size_t)-1)
        return -1;
    st->rattlers = nr;
    size_t nj = 0;
    for (size_t i = 0; i < np; i++) {
        mask[i] = is_free[i] && !rat[i];
        nj += mask[i];
    }
    const uint8_t *m = nj ? mask : is_free;
    /* stability needs λ_max over every moving DOF, rattlers included */
    double lmax = pk_dem_gershgorin(c, dim, np, E, is_free);
    st->lambda_max = lmax > 0 ? lmax : E; /* no contact: any scale will do */
    double lmin = nj ? pk_homog_lanczos_min(c, dim, np, E, mask, R->lanczos) : 0;
    if (isnan(lmin))
        return -1;
    double rq = pk_homog_rayleigh(c, dim, np, E, m, f, work);
    if (rq > 0 && (rq < lmin || !(lmin > 0)))
        lmin = rq;
    if (inc_rq != 0 && (fabs(inc_rq) < lmin || !(lmin > 0)))
        lmin = fabs(inc_rq);
    if (R->fric_active) {
        st->lambda_max += pk_dem_fric_gershgorin(c, R->fc, np);
        double fq = fric_rayleigh(R, x, u, f, gu, work);
        if (isnan(fq))
            return -1;
        if (fq > 0 && (fq < lmin || !(lmin > 0)))
            lmin = fq;
    }
    const double floor_share = 1e-8; /* λ_min/λ_max below this counts as singular */
    st->clamped = !(lmin > floor_share * st->lambda_max);
    st->lambda_min = st->clamped ? floor_share * st->lambda_max : fmin(lmin, st->lambda_max);
    optimal_params(st);
    return 0;
}

/* v ← cv·v + cf·f, x ← x + Δt·v on the free grains; stale = some grain
 * moved beyond half the skin since the pair list was built (held grains do
 * not move within a relaxation).  dim a constant (2 or 3) at the call: the
 * axis loops unrolled.  want (a constant too): acc[0] += v·v, acc[1] += v·f
 * with the new v and the f given (the increments' Rayleigh quotient, see
 * estimate), each axis summed apart and the axes added at the end. */
static inline int move(double *restrict x, double *restrict v, const double *restrict f,
                       const uint8_t *restrict is_free, size_t np, const int dim, pk_relax_coef cf,
                       const double *restrict xb, double lim2, const int want, double *acc)
{
    int stale = 0;
    double vv[3] = {0, 0, 0}, vf[3] = {0, 0, 0};
    for (size_t i = 0; i < np; i++) {
        if (!is_free[i])
            continue;
        double s = 0;
        for (int a = 0; a < dim; a++) {
            double *vi = &v[3 * i + a];
            *vi = cf.cv * *vi + cf.cf * f[3 * i + a];
            x[3 * i + a] += cf.dt * *vi;
            double d = x[3 * i + a] - xb[3 * i + a];
            s += d * d;
            if (want) {
                vv[a] += *vi * *vi;
                vf[a] += *vi * f[3 * i + a];
            }
        }
        stale |= s > lim2;
    }
    if (want)
        for (int a = 0; a < dim; a++)
            acc[0] += vv[a], acc[1] += vf[a];
    return stale;
}

#if defined(__SSE2__)
#include <emmintrin.h>
/* move for dim 2 with the x, y components of a grain in one SSE2 register
 * (baseline x86-64): the same elementwise products and sums, and s = d0² +
 * d1² (move's 0 + d0² + d1²: 0 + d0² = d0², as d0² is +0, positive or NaN),
 * so the same bits (tests/unit/test_homog_relax_move.c).  ~27 instructions
 * per grain against the generic loop's ~44 (docs/perf/homog.md); the branch
 * on is_free is kept: nearly every grain is free (predicted). */
static inline int move_2d_sse2(double *restrict x, double *restrict v, const double *restrict f,
                               const uint8_t *restrict is_free, size_t np, pk_relax_coef cf,
                               const double *restrict xb, double lim2, const int want, double *acc)
{
    const __m128d CV = _mm_set1_pd(cf.cv), CF = _mm_set1_pd(cf.cf), DT = _mm_set1_pd(cf.dt);
    __m128d VV = _mm_setzero_pd(), VF = _mm_setzero_pd(); /* per axis, as move */
    int stale = 0;
    for (size_t i = 0; i < np; i++) {
        if (!is_free[i])
            continue;
        const __m128d fi = _mm_loadu_pd(&f[3 * i]);
        __m128d vi = _mm_add_pd(_mm_mul_pd(CV, _mm_loadu_pd(&v[3 * i])), _mm_mul_pd(CF, fi));
        __m128d xi = _mm_add_pd(_mm_loadu_pd(&x[3 * i]), _mm_mul_pd(DT, vi));
        _mm_storeu_pd(&v[3 * i], vi);
        _mm_storeu_pd(&x[3 * i], xi);
        __m128d d = _mm_sub_pd(xi, _mm_loadu_pd(&xb[3 * i]));
        __m128d dd = _mm_mul_pd(d, d);
        double s = _mm_cvtsd_f64(_mm_add_sd(dd, _mm_unpackhi_pd(dd, dd)));
        stale |= s > lim2;
        if (want) {
            VV = _mm_add_pd(VV, _mm_mul_pd(vi, vi));
            VF = _mm_add_pd(VF, _mm_mul_pd(vi, fi));
        }
    }
    if (want) {
        double a[2], b[2];
        _mm_storeu_pd(a, VV);
        _mm_storeu_pd(b, VF);
        acc[0] += a[0], acc[0] += a[1];
        acc[1] += b[0], acc[1] += b[1];
    }
    return stale;
}
#endif

int pk_relax_scalar_move = 0;

int pk_relax_move_acc(double *x, double *v, const double *f, const uint8_t *is_free, size_t np,
                      int dim, pk_relax_coef cf, const pk_dem_pairs *c, double acc[2])
{
    const double lim2 = 0.25 * c->skin * c->skin;
#if defined(__SSE2__)
    if (dim == 2 && !pk_relax_scalar_move)
        return acc ? move_2d_sse2(x, v, f, is_free, np, cf, c->xb, lim2, 1, acc)
                   : move_2d_sse2(x, v, f, is_free, np, cf, c->xb, lim2, 0, NULL);
#endif
    if (acc)
        return dim == 2 ? move(x, v, f, is_free, np, 2, cf, c->xb, lim2, 1, acc)
                        : move(x, v, f, is_free, np, dim, cf, c->xb, lim2, 1, acc);
    return dim == 2 ? move(x, v, f, is_free, np, 2, cf, c->xb, lim2, 0, NULL)
                    : move(x, v, f, is_free, np, dim, cf, c->xb, lim2, 0, NULL);
}

int pk_relax_move(double *x, double *v, const double *f, const uint8_t *is_free, size_t np, int dim,
                  pk_relax_coef cf, const pk_dem_pairs *c)
{
    return pk_relax_move_acc(x, v, f, is_free, np, dim, cf, c, NULL);
}

int pk_relax_begin(const pk_dem_system *s, const double *x, const pk_dr_params *prm,
                   pk_dr_stats *st, size_t *nfree)
{
    memset(st, 0, sizeof *st);
    *nfree = 0;
    for (size_t i = 0; i < s->np; i++)
        *nfree += s->is_free[i] != 0;
    return pk_dem_pairs_build(s->c, s->g, x, s->r, s->np, prm->skin);
}

void pk_relax_hook_solved(pk_dr_stats *st, const pk_dr_params *prm, double fres)
{
    st->f = fres;
    st->stop = fres <= prm->tol * st->f0 ? PK_DR_CONVERGED : PK_DR_CONVERGED_ABS;
}

int pk_relax_iteration_end(pk_dr_stats *st, const pk_dr_params *prm, double target, size_t k,
                           double *x, pk_dr_hook *hook, pk_monitor *mon, pk_progress *pr,
                           pk_relax_geom *gm)
{
    if (st->f <= target) {
        st->stop = st->f <= prm->tol * st->f0 ? PK_DR_CONVERGED : PK_DR_CONVERGED_ABS;
        return 1;
    }
    if (hook && hook->poll && hook->poll(hook->ctx)) {
        st->stop = PK_DR_HANDED_OVER;
        return 1;
    }
    if (hook)
        hook->f_peak = fmax(hook->f_peak, st->f);
    if (hook &&
        (st->f <= hook->at ||
         (hook->crawl && hook->last && st->iterations >= hook->last + hook->crawl &&
          hook->f_peak <= hook->f_last))) {
        hook->last = st->iterations; /* >= 1 */
        hook->f_last = hook->f_peak = st->f;
        double fh = st->f;
        if (gm)
            pk_relax_geom_refresh(gm, x);
        hook->running = st;
        int h = hook->fn(hook->ctx, x, &fh, &hook->at);
        hook->running = NULL;
        if (h < 0)
            return h;
        if (h == 1) { /* the hook solved the step from here */
            pk_relax_hook_solved(st, prm, fh);
            return 1;
        }
        if (h == 2) {
            st->stop = PK_DR_HANDED_OVER;
            return 1;
        }
    }
    if (st->iterations >= prm->max_iter) {
        st->stop = PK_DR_MAX_ITER;
        return 1;
    }
    if ((k & 63) == 63 && mon) {
        pr->done = st->iterations;
        pr->fraction = log(st->f / st->f0) / log(target / st->f0);
        int t = pk_monitor_tick(mon, pr, 0);
        if (t) {
            st->stop = t == 1 ? PK_DR_CANCELLED : PK_DR_WALL_TIME;
            return 1;
        }
    }
    return 0;
}

int pk_relax_settled(pk_dr_stats *st, const pk_dr_params *prm, int nothing_moves, double *target)
{
    *target = fmax(prm->tol * st->f0, prm->abs_floor);
    if (nothing_moves)
        st->stop = PK_DR_NOT_NEEDED;
    else if (st->f0 <= prm->abs_floor)
        st->stop = PK_DR_CONVERGED_ABS;
    else
        return 0;
    return 1;
}

/* Σ −Δx·Δf and Σ Δx·Δx over the iterations since the last estimate
 * (frictionless: the increments of x alone), Δx = Δt v: their quotient is
 * the Rayleigh quotient of DR's own increments (estimate). */
typedef struct increments {
    double df, dd;
} increments;

/* Fresh estimates at x (geometry refreshed first), seeded by the increments'
 * Rayleigh quotient; the increments start again.  -1 when out of memory. */
static int re_estimate(const relax_run *sys, pk_relax_geom *geo, const double *f, double *x,
                       double *u, const double *gu, increments *inc, pk_dr_stats *st)
{
    pk_relax_geom_refresh(geo, x);
    if (estimate(sys, f, x, u, gu, inc->dd > 0 ? inc->df / inc->dd : 0, st) != 0)
        return -1;
    st->refreshes++;
    inc->df = inc->dd = 0;
    return 0;
}

static int relax(const pk_dem_system *sy, double *x, const pk_dr_params *prm, pk_fric_ctx *fc,
                 double *u, pk_dr_hook *hook, pk_monitor *mon, pk_dr_stats *st, pk_fric_totals *tot)
{
    pk_dem_pairs *c = sy->c;
    const pk_dem_geom *g = sy->g;
    const double *r = sy->r;
    const size_t np = sy->np;
    const double E = sy->E;
    const uint8_t *is_free = sy->is_free;
    const int dim = g->dim;
    size_t nfree;
    int rc = pk_relax_begin(sy, x, prm, st, &nfree);
    if (rc != 0)
        return rc;
    double *f = malloc(3 * np * sizeof *f), *v = calloc(3 * np, sizeof *v);
    double *work = malloc(4 * (np ? np : 1) * sizeof *work);
    double *gu = calloc(np ? np : 1, sizeof *gu), *vu = calloc(np ? np : 1, sizeof *vu);
    uint8_t *rat = malloc(np ? np : 1), *mask = malloc(np ? np : 1);
    relax_run sys = {sy,   fc,  fc && pk_fric_law_active(fc->law), prm->lanczos_steps, rat,
                     mask, work};
    if (!f || !v || !work || !gu || !vu || !rat || !mask || forces(&sys, x, u, f, gu, tot) != 0) {
        rc = -1;
        goto out;
    }
    st->f0 = st->f = resid_norm(&sys, f, gu, NULL, NULL);
    double target;
    if (pk_relax_settled(st, prm, nfree == 0 && !sys.fric_active, &target))
        goto out;
    if (estimate(&sys, f, x, u, gu, 0, st) != 0) {
        rc = -1;
        goto out;
    }
    pk_progress pr = {.stage = "relax", .fraction = -1, .phi = -1, .eta_s = -1};
    double fbest = st->f0;
    pk_relax_geom geo = {sy, 1}; /* pk_dem_eval_forces */
    increments inc = {0, 0};
    for (size_t k = 0;; k++) {
        double dt = st->dt, gm = st->gamma;
        /* one step of (4.39)–(4.41): cv = (2 − γΔt)/(2 + γΔt), cf = 2Δt/(2 + γΔt),
         * or cv = 0, cf = Δt/2 on the first step (4.41) */
        pk_relax_coef cf = {dt, k == 0 ? 0 : (2 - gm * dt) / (2 + gm * dt),
                            k == 0 ? 0.5 * dt : 2 * dt / (2 + gm * dt)};
        double mv[2] = {0, 0}; /* v·v, v·f before the evaluation */
        const int incr = !sys.fric_active && !prm->plain_lambda_min;
        int stale = pk_relax_move_acc(x, v, f, is_free, np, dim, cf, c, incr ? mv : NULL);
        if (sys.fric_active) /* the rotations, same scheme (unit pseudo-mass of u = rθ) */
            for (size_t i = 0; i < np; i++) {
                vu[i] = cf.cv * vu[i] + cf.cf * gu[i];
                u[i] += dt * vu[i];
            }
        st->iterations = k + 1;
        if (stale) {
            rc = pk_dem_pairs_build(c, g, x, r, np, prm->skin);
            if (rc != 0)
                goto out;
            st->rebuilds++;
        }
        if (!fc) { /* frictionless: the forces alone (friction reads the geometry) */
            pk_dem_eval_forces(c, g, x, r, np, E, f);
            geo.fresh = 0;
        } else if (forces(&sys, x, u, f, gu, tot) != 0) {
            rc = -1;
            goto out;
        }
        double vf1 = 0;
        st->f = resid_norm(&sys, f, gu, incr ? v : NULL, &vf1);
        inc.df -= vf1 - mv[1]; /* Δx·Δf / Δt */
        inc.dd += dt * mv[0];  /* Δx·Δx / Δt */
        int e = pk_relax_iteration_end(st, prm, target, k, x, hook, mon, &pr, &geo);
        if (e < 0) {
            rc = e;
            goto out;
        }
        if (e)
            break;
        if (!isfinite(st->f) || st->f > 1e3 * fbest) {
            /* diverging: the spectrum moved (new contacts) — fresh estimates, restart at rest */
            if (re_estimate(&sys, &geo, f, x, u, gu, &inc, st) != 0) {
                rc = -1;
                goto out;
            }
            memset(v, 0, 3 * np * sizeof *v);
            memset(vu, 0, np * sizeof *vu);
            fbest = st->f;
            continue;
        }
        fbest = fmin(fbest, st->f);
        if (prm->refresh && st->iterations % prm->refresh == 0 &&
            re_estimate(&sys, &geo, f, x, u, gu, &inc, st) != 0) {
            rc = -1;
            goto out;
        }
    }
    pk_relax_geom_refresh(&geo, x);
out:
    free(f);
    free(v);
    free(work);
    free(gu);
    free(vu);
    free(rat);
    free(mask);
    return rc;
}

int pk_homog_relax(const pk_dem_system *s, double *x, const pk_dr_params *prm, pk_monitor *mon,
                   pk_dr_stats *st)
{
    return relax(s, x, prm, NULL, NULL, NULL, mon, st, NULL);
}

int pk_homog_relax_hooked(const pk_dem_system *s, double *x, const pk_dr_params *prm,
                          pk_dr_hook *hook, pk_monitor *mon, pk_dr_stats *st)
{
    return relax(s, x, prm, NULL, NULL, hook, mon, st, NULL);
}

int pk_homog_relax_fric(const pk_dem_system *s, double *x, const pk_dr_params *prm, pk_fric_ctx *fc,
                        double *u, pk_monitor *mon, pk_dr_stats *st, pk_fric_totals *tot)
{
    return relax(s, x, prm, fc, u, NULL, mon, st, tot);
}
