/* homog_fire.c — FIRE relaxation of the free particles, the Newton hybrid's
 * inner relaxation after DR.  Contract: homog_fire.h. */
#include "homog_fire.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "homog_eigen.h"

/* Bitzek et al.'s parameters; FIRE 2.0's α_start 0.25 and N_delay 20 were
 * slower on the near-jamming 10⁴ bench steps (docs/perf/homog.md). */
pk_fire_params pk_fire_params_default(void)
{
    pk_fire_params p = {
        .n_min = 5, .f_inc = 1.1, .f_dec = 0.5, .alpha0 = 0.1, .f_alpha = 0.99, .dt_scale = 1.0};
    return p;
}

/* The smallest Δt relative to Δt_max (FIRE 2.0's Δt_min): a run of uphill
 * steps cannot stall the iteration. */
#define DT_MIN_SHARE 0.02

/* v ← v + Δt f on the free grains (v = 0 after a restart); returns |v|². */
static double velocity_step(double *v, const double *f, const uint8_t *is_free, size_t np, int dim,
                            double dt)
{
    double vv = 0;
    for (size_t i = 0; i < np; i++)
        if (is_free[i])
            for (int a = 0; a < dim; a++) {
                v[3 * i + a] += dt * f[3 * i + a];
                vv += v[3 * i + a] * v[3 * i + a];
            }
    return vv;
}

/* The one pass after each evaluation: |f|², P = f·v, and the velocity of
 * the next step should P > 0, w = v + Δt₊ f with |w|² (Δt₊ is known
 * before P: it depends only on the count of downhill steps).  Each sum in
 * the order of pk_homog_dot_mask and velocity_step: bit-identical to the
 * separate passes.  dim a constant (2 or 3) at the call. */
typedef struct fire_sums {
    double ff, fv, ww;
} fire_sums;

static inline fire_sums fire_pass(const double *f, const double *v, double *w,
                                  const uint8_t *is_free, size_t np, const int dim, double dt)
{
    fire_sums s = {0, 0, 0};
    for (size_t i = 0; i < np; i++)
        if (is_free[i])
            for (int a = 0; a < dim; a++) {
                double fa = f[3 * i + a], va = v[3 * i + a], wa = va + dt * fa;
                s.ff += fa * fa;
                s.fv += fa * va;
                w[3 * i + a] = wa;
                s.ww += wa * wa;
            }
    return s;
}

static fire_sums fire_sums_at(const double *f, const double *v, double *w, const uint8_t *is_free,
                              size_t np, int dim, double dt)
{
    return dim == 2 ? fire_pass(f, v, w, is_free, np, 2, dt)
                    : fire_pass(f, v, w, is_free, np, dim, dt);
}

int pk_homog_fire_hooked(const pk_dem_system *sy, double *x, const pk_dr_params *prm,
                         const pk_fire_params *fp, pk_dr_hook *hook, pk_monitor *mon,
                         pk_dr_stats *st)
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
    const size_t n3 = 3 * (np ? np : 1);
    double *f = malloc(n3 * sizeof *f), *v = calloc(n3, sizeof *v), *w = calloc(n3, sizeof *w);
    if (!f || !v || !w) {
        rc = -1;
        goto out;
    }
    pk_dem_eval(c, g, x, r, np, E, f, NULL, NULL);
    size_t n_pos = 0;
    /* one pass after each evaluation (fire_pass) and the shared move: the
     * same bits as separate passes (test_homog_fire) */
    fire_sums s = fire_sums_at(f, v, w, is_free, np, dim, 0);
    st->f0 = st->f = sqrt(s.ff);
    double target;
    if (pk_relax_settled(st, prm, nfree == 0, &target))
        goto out;
    double lmax = pk_dem_gershgorin(c, dim, np, E, is_free);
    st->lambda_max = lmax > 0 ? lmax : E; /* no contact: any scale will do */
    const double dt_max = fp->dt_scale * 2 / sqrt(st->lambda_max);
    double dt = 0.5 * dt_max, alpha = fp->alpha0;
    pk_progress pr = {.stage = "relax", .fraction = -1, .phi = -1, .eta_s = -1};
    pk_relax_geom geo = {sy, 1}; /* pk_dem_eval_forces */
    for (size_t k = 0;; k++) {
        double vv;
        if (s.fv > 0) { /* P = f·v > 0: downhill; v + Δt f is in w (fire_pass) */
            if (++n_pos > fp->n_min) {
                dt = fmin(dt * fp->f_inc, dt_max);
                alpha *= fp->f_alpha;
            }
            double *t = v;
            v = w;
            w = t;
            vv = s.ww;
        } else { /* uphill: stop, half a step back (FIRE 2.0), smaller Δt */
            n_pos = 0;
            dt = fmax(dt * fp->f_dec, DT_MIN_SHARE * dt_max);
            alpha = fp->alpha0;
            if (k > 0)
                for (size_t i = 0; i < np; i++)
                    if (is_free[i])
                        for (int a = 0; a < dim; a++)
                            x[3 * i + a] -= 0.5 * dt * v[3 * i + a];
            memset(v, 0, 3 * np * sizeof *v);
            st->refreshes++; /* counts the restarts */
            vv = velocity_step(v, f, is_free, np, dim, dt);
        }
        /* the FIRE mixing v ← (1 − α) v + α |v| f/|f|, x ← x + Δt v */
        pk_relax_coef cf = {dt, 1 - alpha, st->f > 0 ? alpha * sqrt(vv) / st->f : 0};
        int stale = pk_relax_move(x, v, f, is_free, np, dim, cf, c);
        st->iterations = k + 1;
        st->dt = dt;
        if (stale) {
            rc = pk_dem_pairs_build(c, g, x, r, np, prm->skin);
            if (rc != 0)
                goto out;
            st->rebuilds++;
        }
        pk_dem_eval_forces(c, g, x, r, np, E, f);
        geo.fresh = 0;
        /* Δt of the next step should it be downhill (as in the branch above) */
        double dt_up = n_pos + 1 > fp->n_min ? fmin(dt * fp->f_inc, dt_max) : dt;
        s = fire_sums_at(f, v, w, is_free, np, dim, dt_up);
        st->f = sqrt(s.ff);
        int e = pk_relax_iteration_end(st, prm, target, k, x, hook, mon, &pr, &geo);
        if (e < 0) {
            rc = e;
            goto out;
        }
        if (e)
            break;
    }
    pk_relax_geom_refresh(&geo, x);
out:
    free(f);
    free(v);
    free(w);
    return rc;
}
