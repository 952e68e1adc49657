#include "homog_relax.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "dem_rattler.h"
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
    }
    return "unknown";
}

int pk_dr_stop_ok(pk_dr_stop s)
{
    return s == PK_DR_CONVERGED || s == PK_DR_CONVERGED_ABS || s == PK_DR_NOT_NEEDED;
}

static double free_norm(const double *f, const uint8_t *is_free, size_t np, int dim)
{
    double s = 0;
    for (size_t i = 0; i < np; i++)
        if (is_free[i])
            for (int a = 0; a < dim; a++)
                s += f[3 * i + a] * f[3 * i + a];
    return sqrt(s);
}

/* (4.47): Δt = 2/√(λmin+λmax), γ = 2√(λmin λmax/(λmin+λmax)) */
static void optimal_params(pk_dr_stats *st)
{
    double lmin = st->lambda_min, lmax = st->lambda_max;
    st->dt = 2 / sqrt(lmin + lmax);
    st->gamma = 2 * sqrt(lmin * lmax / (lmin + lmax));
}

/* Fresh estimates on the jammed free grains (rattlers re-detected):
 * λ_max by Gershgorin, λ_min by Lanczos, lowered further by the Rayleigh
 * quotient of the current residual f (dominated by the slow modes late in a
 * relaxation).  A non-positive λ_min (indefinite block under large overlaps,
 * or no jammed grain) falls back to the residual's Rayleigh quotient on the
 * free grains, and only then to a tiny share of λ_max (flagged). */
static int estimate(pk_dem_pairs *c, int dim, size_t np, double E, const uint8_t *is_free,
                    const double *f, uint8_t *rat, uint8_t *mask, double *work, int lanczos,
                    pk_dr_stats *st)
{
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
    double lmin = nj ? pk_homog_lanczos_min(c, dim, np, E, mask, lanczos) : 0;
    if (isnan(lmin))
        return -1;
    double rq = pk_homog_rayleigh(c, dim, np, E, m, f, work);
    if (rq > 0 && (rq < lmin || !(lmin > 0)))
        lmin = rq;
    const double floor_share = 1e-8; /* λ_min/λ_max below this counts as singular */
    st->clamped = !(lmin > floor_share * st->lambda_max);
    st->lambda_min = st->clamped ? floor_share * st->lambda_max : fmin(lmin, st->lambda_max);
    optimal_params(st);
    return 0;
}

int pk_homog_relax(pk_dem_pairs *c, const pk_dem_geom *g, double *x, const double *r, size_t np,
                   double E, const uint8_t *is_free, const pk_dr_params *prm, pk_monitor *mon,
                   pk_dr_stats *st)
{
    const int dim = g->dim;
    memset(st, 0, sizeof *st);
    size_t nfree = 0;
    for (size_t i = 0; i < np; i++)
        nfree += is_free[i] != 0;
    int rc = pk_dem_pairs_build(c, g, x, r, np, prm->skin);
    if (rc != 0)
        return rc;
    double *f = malloc(3 * np * sizeof *f), *v = calloc(3 * np, sizeof *v);
    double *work = malloc(3 * np * sizeof *work);
    uint8_t *rat = malloc(np ? np : 1), *mask = malloc(np ? np : 1);
    if (!f || !v || !work || !rat || !mask) {
        rc = -1;
        goto out;
    }
    pk_dem_eval(c, g, x, r, np, E, f, NULL, NULL);
    st->f0 = st->f = free_norm(f, is_free, np, dim);
    if (nfree == 0) {
        st->stop = PK_DR_NOT_NEEDED;
        goto out;
    }
    double target = fmax(prm->tol * st->f0, prm->abs_floor);
    if (st->f0 <= prm->abs_floor) {
        st->stop = PK_DR_CONVERGED_ABS;
        goto out;
    }
    if (estimate(c, dim, np, E, is_free, f, rat, mask, work, prm->lanczos_steps, st) != 0) {
        rc = -1;
        goto out;
    }
    pk_progress pr = {.stage = "relax", .fraction = -1, .phi = -1, .eta_s = -1};
    double fbest = st->f0;
    for (size_t k = 0;; k++) {
        double dt = st->dt, gm = st->gamma;
        for (size_t i = 0; i < np; i++) {
            if (!is_free[i])
                continue;
            for (int a = 0; a < dim; a++) {
                double *vi = &v[3 * i + a], fi = f[3 * i + a];
                if (k == 0)
                    *vi = 0.5 * dt * fi; /* (4.41) */
                else
                    *vi = ((2 - gm * dt) * *vi + 2 * dt * fi) / (2 + gm * dt); /* (4.39) */
                x[3 * i + a] += dt * *vi;                                      /* (4.40) */
            }
        }
        st->iterations = k + 1;
        if (pk_dem_pairs_stale(c, x, dim)) {
            rc = pk_dem_pairs_build(c, g, x, r, np, prm->skin);
            if (rc != 0)
                goto out;
            st->rebuilds++;
        }
        pk_dem_eval(c, g, x, r, np, E, f, NULL, NULL);
        st->f = free_norm(f, is_free, np, dim);
        if (st->f <= target) {
            st->stop = st->f <= prm->tol * st->f0 ? PK_DR_CONVERGED : PK_DR_CONVERGED_ABS;
            break;
        }
        if (st->iterations >= prm->max_iter) {
            st->stop = PK_DR_MAX_ITER;
            break;
        }
        if (!isfinite(st->f) || st->f > 1e3 * fbest) {
            /* diverging: the spectrum moved (new contacts) — fresh estimates, restart at rest */
            if (estimate(c, dim, np, E, is_free, f, rat, mask, work, prm->lanczos_steps, st) != 0) {
                rc = -1;
                goto out;
            }
            memset(v, 0, 3 * np * sizeof *v);
            fbest = st->f;
            st->refreshes++;
            continue;
        }
        fbest = fmin(fbest, st->f);
        if (prm->refresh && st->iterations % prm->refresh == 0) {
            if (estimate(c, dim, np, E, is_free, f, rat, mask, work, prm->lanczos_steps, st) != 0) {
                rc = -1;
                goto out;
            }
            st->refreshes++;
        }
        if ((k & 63) == 63 && mon) {
            pr.done = st->iterations;
            pr.fraction = log(st->f / st->f0) / log(target / st->f0);
            int t = pk_monitor_tick(mon, &pr, 0);
            if (t) {
                st->stop = t == 1 ? PK_DR_CANCELLED : PK_DR_WALL_TIME;
                break;
            }
        }
    }
out:
    free(f);
    free(v);
    free(work);
    free(rat);
    free(mask);
    return rc;
}
