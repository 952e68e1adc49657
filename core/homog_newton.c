#include "homog_newton.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "dem_rattler.h"
#include "homog_stiffness.h"

const char *pk_newton_exit_name(pk_newton_exit e)
{
    switch (e) {
    case PK_NEWTON_CONVERGED: return "converged";
    case PK_NEWTON_RATTLER_POLISH: return "rattler_polish";
    case PK_NEWTON_BLOCK_NOT_PD: return "block_not_positive_definite";
    case PK_NEWTON_LINE_SEARCH: return "line_search_failed";
    case PK_NEWTON_CAP: return "iteration_cap";
    case PK_NEWTON_STALLED: return "stalled";
    }
    return "unknown";
}

static double norm_on(const double *f, const uint8_t *m, size_t np, int dim)
{
    double s = 0;
    for (size_t i = 0; i < np; i++)
        if (m[i])
            for (int a = 0; a < dim; a++)
                s += f[3 * i + a] * f[3 * i + a];
    return sqrt(s);
}

/* Evaluate at x (rebuilding the candidate list when stale). */
static int eval_at(pk_dem_pairs *c, const pk_dem_geom *g, const double *x, const double *r,
                   size_t np, double E, const pk_dr_params *prm, double *f, double *phi)
{
    if (pk_dem_pairs_stale(c, x, g->dim)) {
        int rc = pk_dem_pairs_build(c, g, x, r, np, prm->skin);
        if (rc != 0)
            return rc;
    }
    pk_dem_eval(c, g, x, r, np, E, f, phi, NULL);
    return 0;
}

int pk_homog_newton(pk_dem_pairs *c, const pk_dem_geom *g, double *x, const double *r, size_t np,
                    double E, const uint8_t *is_free, const pk_dr_params *prm,
                    const pk_sparse_solver *solver, size_t max_newton, pk_monitor *mon,
                    pk_dr_stats *st, pk_newton_stats *ns)
{
    const int dim = g->dim;
    memset(ns, 0, sizeof *ns);
    memset(st, 0, sizeof *st);
    int rc = pk_dem_pairs_build(c, g, x, r, np, prm->skin);
    if (rc != 0)
        return rc;
    size_t n3 = 3 * (np ? np : 1);
    double *f = malloc(n3 * sizeof *f), *ft = malloc(n3 * sizeof *ft), *xt = malloc(n3 * sizeof *xt);
    double *rhs = malloc(n3 * sizeof *rhs), *dx = malloc(n3 * sizeof *dx);
    uint8_t *rat = malloc(np ? np : 1), *jam = malloc(np ? np : 1);
    int32_t *dof = malloc((np ? np : 1) * sizeof *dof);
    pk_sparse_sym K = {0};
    if (!f || !ft || !xt || !rhs || !dx || !rat || !jam || !dof) {
        rc = -1;
        goto out;
    }
    double phi;
    pk_dem_eval(c, g, x, r, np, E, f, &phi, NULL);
    double f0 = norm_on(f, is_free, np, dim), fn = f0;
    double target = fmax(prm->tol * f0, prm->abs_floor);
    ns->exit = PK_NEWTON_CAP;
    double best = fn;
    size_t best_it = 0;
    for (;;) {
        if (fn <= target) {
            ns->exit = PK_NEWTON_CONVERGED;
            break;
        }
        if (ns->iterations >= max_newton)
            break;
        if (fn < 0.5 * best) {
            best = fn;
            best_it = ns->iterations;
        } else if (ns->iterations >= best_it + 4) {
            ns->exit = PK_NEWTON_STALLED;
            break;
        }
        if (pk_dem_rattlers(c, dim, np, is_free, rat) == (size_t)-1) {
            rc = -1;
            goto out;
        }
        size_t nd = 0;
        for (size_t i = 0; i < np; i++) {
            jam[i] = is_free[i] && !rat[i];
            dof[i] = jam[i] ? (int32_t)(dim * nd++) : -1;
        }
        nd *= (size_t)dim;
        if (nd == 0 || norm_on(f, jam, np, dim) <= target) {
            ns->exit = PK_NEWTON_RATTLER_POLISH;
            break;
        }
        K.nnz = 0;
        K.n = nd;
        if (pk_homog_assemble_K(c, dim, E, dof, rat, &K) != 0) {
            rc = -1;
            goto out;
        }
        pk_sparse_info info;
        pk_sparse_factor *fac = solver->factor(&K, &info);
        if (info.status == PK_SPARSE_FAILED) {
            solver->release(fac);
            rc = -1;
            goto out;
        }
        if (info.status != PK_SPARSE_OK) {
            solver->release(fac);
            ns->exit = PK_NEWTON_BLOCK_NOT_PD;
            break;
        }
        for (size_t i = 0; i < np; i++)
            if (dof[i] >= 0)
                for (int a = 0; a < dim; a++)
                    rhs[dof[i] + a] = f[3 * i + a];
        int srv = solver->solve(fac, 1, rhs, dx);
        solver->release(fac);
        if (srv != 0) {
            rc = -1;
            goto out;
        }
        /* Armijo on Φ along Δx = K⁻¹f: dΦ/ds = −f·Δx < 0 */
        double slope = 0;
        for (size_t i = 0; i < np; i++)
            if (dof[i] >= 0)
                for (int a = 0; a < dim; a++)
                    slope -= f[3 * i + a] * dx[dof[i] + a];
        double s = 1, phit = phi, ftn = fn;
        int ok = 0;
        for (int cut = 0; cut < 30; cut++, s *= 0.5) {
            memcpy(xt, x, 3 * np * sizeof *x);
            for (size_t i = 0; i < np; i++)
                if (dof[i] >= 0)
                    for (int a = 0; a < dim; a++)
                        xt[3 * i + a] += s * dx[dof[i] + a];
            rc = eval_at(c, g, xt, r, np, E, prm, ft, &phit);
            if (rc != 0)
                goto out;
            ftn = norm_on(ft, is_free, np, dim);
            if (phit <= phi + 1e-4 * s * slope || ftn < 0.5 * fn) {
                ok = 1;
                break;
            }
            ns->cuts++;
        }
        ns->iterations++;
        if (!ok) {
            rc = eval_at(c, g, x, r, np, E, prm, f, &phi); /* back to the last point */
            if (rc != 0)
                goto out;
            ns->exit = PK_NEWTON_LINE_SEARCH;
            break;
        }
        memcpy(x, xt, 3 * np * sizeof *x);
        memcpy(f, ft, 3 * np * sizeof *f);
        phi = phit;
        fn = ftn;
        if (mon) {
            pk_progress pr = {.stage = "newton", .fraction = -1, .phi = -1, .eta_s = -1,
                              .done = ns->iterations};
            int t = pk_monitor_tick(mon, &pr, 0);
            if (t) {
                st->stop = t == 1 ? PK_DR_CANCELLED : PK_DR_WALL_TIME;
                st->f0 = f0;
                st->f = fn;
                goto out;
            }
        }
    }
    if (ns->exit == PK_NEWTON_CONVERGED) {
        st->stop = fn <= prm->tol * f0 ? PK_DR_CONVERGED : PK_DR_CONVERGED_ABS;
        st->f0 = f0;
        st->f = fn;
        goto out;
    }
    /* DR to the same absolute target from where Newton stopped */
    pk_dr_params p2 = *prm;
    p2.tol = fn > 0 ? fmin(1.0, target / fn) : prm->tol;
    rc = pk_homog_relax(c, g, x, r, np, E, is_free, &p2, mon, st);
    if (rc == 0 && pk_dr_stop_ok(st->stop))
        st->stop = st->f <= prm->tol * f0 ? PK_DR_CONVERGED : PK_DR_CONVERGED_ABS;
    st->f0 = f0;
out:
    free(f), free(ft), free(xt), free(rhs), free(dx), free(rat), free(jam), free(dof);
    pk_sparse_sym_free(&K);
    return rc;
}
