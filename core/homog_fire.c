#include "homog_fire.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "homog_eigen.h"

/* Measured (round 7, whole near-jamming 10⁴ bench pipeline, seeds 5/6/8,
 * CPU s of the step; the RVEs move since they are relaxed by the same
 * hybrid): these 1.3/2.7/2.2; FIRE 2.0's α_start 0.25: 1.5/2.8/2.0 (the
 * same minima on 5 and 8, another on 6: ΔΦ/Φ −6.5e-8); with its N_delay 20
 * as well: 3.2/271/2.7 (seed 6: 1.28·10⁶ FIRE iterations) — kept. */
pk_fire_params pk_fire_params_default(void)
{
    pk_fire_params p = {.n_min = 5, .f_inc = 1.1, .f_dec = 0.5, .alpha0 = 0.1, .f_alpha = 0.99,
                        .dt_scale = 1.0};
    return p;
}

/* The smallest Δt relative to Δt_max (FIRE 2.0's Δt_min): a run of uphill
 * steps cannot stall the iteration. */
#define DT_MIN_SHARE 0.02

/* v ← v + Δt f, then the FIRE mixing v ← (1 − α) v + α |v| f/|f| (fn = |f|),
 * x ← x + Δt v on the free grains.  Returns pk_dem_pairs_stale in the same
 * pass (held grains do not move). */
static int fire_move(double *x, double *v, const double *f, double fn, const uint8_t *is_free,
                     size_t np, int dim, double dt, double alpha, const pk_dem_pairs *c)
{
    double vv = 0;
    for (size_t i = 0; i < np; i++)
        if (is_free[i])
            for (int a = 0; a < dim; a++) {
                v[3 * i + a] += dt * f[3 * i + a];
                vv += v[3 * i + a] * v[3 * i + a];
            }
    pk_relax_coef cf = {dt, 1 - alpha, fn > 0 ? alpha * sqrt(vv) / fn : 0};
    return pk_relax_move(x, v, f, is_free, np, dim, cf, c);
}

int pk_homog_fire_hooked(pk_dem_pairs *c, const pk_dem_geom *g, double *x, const double *r,
                         size_t np, double E, const uint8_t *is_free, const pk_dr_params *prm,
                         const pk_fire_params *fp, pk_dr_hook *hook, pk_monitor *mon,
                         pk_dr_stats *st)
{
    const int dim = g->dim;
    size_t nfree;
    int rc = pk_relax_begin(c, g, x, r, np, is_free, prm, st, &nfree);
    if (rc != 0)
        return rc;
    double *f = malloc(3 * (np ? np : 1) * sizeof *f), *v = calloc(3 * (np ? np : 1), sizeof *v);
    if (!f || !v) {
        rc = -1;
        goto out;
    }
    pk_dem_eval(c, g, x, r, np, E, f, NULL, NULL);
    st->f0 = st->f = sqrt(pk_homog_dot_mask(f, f, is_free, np, dim));
    double target;
    if (pk_relax_settled(st, prm, nfree == 0, &target))
        goto out;
    double lmax = pk_dem_gershgorin(c, dim, np, E, is_free);
    st->lambda_max = lmax > 0 ? lmax : E; /* no contact: any scale will do */
    const double dt_max = fp->dt_scale * 2 / sqrt(st->lambda_max);
    double dt = 0.5 * dt_max, alpha = fp->alpha0;
    size_t n_pos = 0;
    pk_progress pr = {.stage = "relax", .fraction = -1, .phi = -1, .eta_s = -1};
    for (size_t k = 0;; k++) {
        double P = pk_homog_dot_mask(f, v, is_free, np, dim);
        if (P > 0) {
            if (++n_pos > fp->n_min) {
                dt = fmin(dt * fp->f_inc, dt_max);
                alpha *= fp->f_alpha;
            }
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
        }
        int stale = dim == 2 ? fire_move(x, v, f, st->f, is_free, np, 2, dt, alpha, c)
                             : fire_move(x, v, f, st->f, is_free, np, dim, dt, alpha, c);
        st->iterations = k + 1;
        st->dt = dt;
        if (stale) {
            rc = pk_dem_pairs_build(c, g, x, r, np, prm->skin);
            if (rc != 0)
                goto out;
            st->rebuilds++;
        }
        pk_dem_eval(c, g, x, r, np, E, f, NULL, NULL);
        st->f = sqrt(pk_homog_dot_mask(f, f, is_free, np, dim));
        int e = pk_relax_iteration_end(st, prm, target, k, x, hook, mon, &pr);
        if (e < 0) {
            rc = e;
            goto out;
        }
        if (e)
            break;
    }
out:
    free(f);
    free(v);
    return rc;
}
