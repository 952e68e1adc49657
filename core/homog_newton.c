#include "homog_newton.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "dem_rattler.h"
#include "homog_stiffness.h"

/* Stiffness added on rattler DOFs (× E): a rattler without contacts has no
 * stiffness at all, and its force is zero, so any small shift gives the
 * right step (zero) without spoiling the conditioning of the jammed part. */
#define RATTLER_SHIFT 1e-6
/* Levenberg–Marquardt shifts (× E) tried on an indefinite block. */
#define MIN_SHIFT 1e-6
#define MAX_SHIFT 1e2
/* Accept a step when it achieves this share of the predicted decrease. */
#define ACCEPT_RATIO 1e-4
/* Below this relative size the energy difference is round-off: judge the
 * step by the residual instead (near convergence f·Δx ~ |f|²/λ is ~1e-18 Φ). */
#define ENERGY_ROUNDOFF 1e-11
/* Accepted steps without halving the residual before giving up to DR. */
#define STALL_STEPS 8
/* Trust-region shrinks per Newton step before the region is declared collapsed. */
#define MAX_SHRINKS 40

const char *pk_newton_exit_name(pk_newton_exit e)
{
    switch (e) {
    case PK_NEWTON_CONVERGED: return "converged";
    case PK_NEWTON_BLOCK_NOT_PD: return "block_not_positive_definite";
    case PK_NEWTON_TRUST_REGION: return "trust_region_collapsed";
    case PK_NEWTON_CAP: return "iteration_cap";
    case PK_NEWTON_STALLED: return "stalled";
    }
    return "unknown";
}

static double dot(const double *a, const double *b, size_t n)
{
    double s = 0;
    for (size_t k = 0; k < n; k++)
        s += a[k] * b[k];
    return s;
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

/* K + μ1 over every free DOF: the exact Hessian (4.11)–(4.14) on contacts
 * between jammed grains — what makes Newton quadratic and what the tangent
 * uses — and the Gauss–Newton part E n⊗n (positive semi-definite) on contacts
 * that touch a rattler, plus a small shift on rattler DOFs, which may have no
 * stiffness at all.  A rattler is thus pushed out of its overlaps along n in
 * one step instead of being left to a separate relaxation.  μ > 0 is the
 * Levenberg–Marquardt shift used when the exact block is indefinite (a
 * buckling grain away from equilibrium). */
static int assemble(const pk_dem_pairs *c, int dim, double E, const int32_t *dof,
                    const uint8_t *rat, double mu, size_t np, pk_sparse_sym *K)
{
    for (size_t p = 0; p < c->n; p++) {
        if (!(c->eps[p] >= 0) || !(c->len[p] > 0))
            continue;
        size_t i = (size_t)c->i[p], j = (size_t)c->j[p];
        if (dof[i] < 0 && dof[j] < 0)
            continue;
        double H[9];
        const double *l = &c->l[3 * p];
        double Ep = pk_dem_pair_E(c, p, E);
        if (rat[i] || rat[j]) {
            double s = Ep / (c->len[p] * c->len[p]);
            for (int a = 0; a < 3; a++)
                for (int b = 0; b < 3; b++)
                    H[3 * a + b] = s * l[a] * l[b];
        } else {
            pk_homog_pair_hessian(Ep, c->len[p], c->eps[p], l, H);
        }
        if (pk_homog_add_pair_K(K, dim, dof[i], dof[j], H) != 0)
            return -1;
    }
    for (size_t i = 0; i < np; i++)
        if (dof[i] >= 0 && (mu > 0 || rat[i]))
            for (int a = 0; a < dim; a++)
                if (pk_sparse_sym_add(K, dof[i] + a, dof[i] + a,
                                      mu + (rat[i] ? RATTLER_SHIFT * E : 0)) != 0)
                    return -1;
    return 0;
}

/* Dogleg point of the trust region |p| <= radius (Nocedal & Wright §4.1)
 * between the Cauchy point pc = (f·f / f·Kf) f and the Newton point pn. */
static void dogleg(const double *f, const double *Kf, const double *pn, size_t n, double radius,
                   double *p)
{
    double nn = sqrt(dot(pn, pn, n));
    if (nn <= radius) {
        memcpy(p, pn, n * sizeof *p);
        return;
    }
    double ff = dot(f, f, n), fKf = dot(f, Kf, n);
    double tc = fKf > 0 ? ff / fKf : INFINITY;
    double nc = tc * sqrt(ff);
    if (nc >= radius) {
        double s = radius / sqrt(ff);
        for (size_t k = 0; k < n; k++)
            p[k] = s * f[k];
        return;
    }
    /* |pc + τ(pn − pc)| = radius, τ in [0, 1] */
    double a = 0, b = 0, cc = nc * nc - radius * radius;
    for (size_t k = 0; k < n; k++) {
        double d = pn[k] - tc * f[k];
        a += d * d;
        b += 2 * tc * f[k] * d;
    }
    double tau = a > 0 ? (-b + sqrt(fmax(0, b * b - 4 * a * cc))) / (2 * a) : 0;
    for (size_t k = 0; k < n; k++)
        p[k] = tc * f[k] + tau * (pn[k] - tc * f[k]);
}

typedef struct newton_work {
    double *x0, *f, *ft, *xt, *rhs, *pn, *p, *Kf, *Kp;
    uint8_t *rat;
    int32_t *dof;
    pk_sparse_sym K;
} newton_work;

static int work_alloc(newton_work *w, size_t np)
{
    size_t n3 = 3 * (np ? np : 1), n1 = np ? np : 1;
    memset(w, 0, sizeof *w);
    double **v[] = {&w->x0, &w->f, &w->ft, &w->xt, &w->rhs, &w->pn, &w->p, &w->Kf, &w->Kp};
    for (size_t k = 0; k < sizeof v / sizeof *v; k++)
        if (!(*v[k] = malloc(n3 * sizeof **v[k])))
            return -1;
    w->rat = malloc(n1);
    w->dof = malloc(n1 * sizeof *w->dof);
    return w->rat && w->dof ? 0 : -1;
}

static void work_free(newton_work *w)
{
    free(w->x0), free(w->f), free(w->ft), free(w->xt), free(w->rhs), free(w->pn), free(w->p), free(w->Kf),
        free(w->Kp), free(w->rat), free(w->dof);
    pk_sparse_sym_free(&w->K);
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
    newton_work w;
    if (work_alloc(&w, np) != 0) {
        rc = -1;
        goto out;
    }
    memcpy(w.x0, x, 3 * np * sizeof *x);
    double phi;
    pk_dem_eval(c, g, x, r, np, E, w.f, &phi, NULL);
    double f0 = norm_on(w.f, is_free, np, dim), fn = f0;
    double target = fmax(prm->tol * f0, prm->abs_floor);
    double radius = -1, best = fn;
    size_t best_it = 0;
    double mu = 0; /* Levenberg–Marquardt shift, kept (decaying) across steps */
    ns->exit = PK_NEWTON_CAP;
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
        } else if (ns->iterations >= best_it + STALL_STEPS) {
            ns->exit = PK_NEWTON_STALLED;
            break;
        }
        if (pk_dem_rattlers(c, dim, np, is_free, w.rat) == (size_t)-1) {
            rc = -1;
            goto out;
        }
        size_t nd = 0;
        for (size_t i = 0; i < np; i++)
            w.dof[i] = is_free[i] ? (int32_t)(dim * nd++) : -1;
        nd *= (size_t)dim;
        w.K.nnz = 0;
        w.K.n = nd;
        if (assemble(c, dim, E, w.dof, w.rat, mu, np, &w.K) != 0) {
            rc = -1;
            goto out;
        }
        pk_sparse_info info;
        pk_sparse_factor *fac = solver->factor(&w.K, &info);
        if (info.status == PK_SPARSE_FAILED) {
            solver->release(fac);
            rc = -1;
            goto out;
        }
        if (info.status != PK_SPARSE_OK) {
            solver->release(fac);
            if (mu < MAX_SHIFT * E) { /* indefinite: shift until positive definite */
                mu = mu > 0 ? 10 * mu : MIN_SHIFT * E;
                continue;
            }
            ns->exit = PK_NEWTON_BLOCK_NOT_PD;
            break;
        }
        for (size_t i = 0; i < np; i++)
            if (w.dof[i] >= 0)
                for (int a = 0; a < dim; a++)
                    w.rhs[w.dof[i] + a] = w.f[3 * i + a];
        int srv = solver->solve(fac, 1, w.rhs, w.pn);
        solver->release(fac);
        if (srv != 0) {
            rc = -1;
            goto out;
        }
        pk_sparse_sym_mv(&w.K, w.rhs, w.Kf);
        /* Newton first: a trial costs one evaluation, a factorisation ~30 */
        radius = fmax(radius, sqrt(dot(w.pn, w.pn, nd)));
        /* Trust region on the potential Φ_n: the contact set changes inside
         * the Newton step of a packing near jamming (soft modes give steps of
         * a fraction of a radius for a 1e-3 strain), so the quadratic model
         * is trusted only as far as it predicted the energy well. */
        int accepted = 0;
        double phit = phi, ftn = fn;
        for (int shrink = 0; shrink < MAX_SHRINKS && !accepted; shrink++) {
            dogleg(w.rhs, w.Kf, w.pn, nd, radius, w.p);
            pk_sparse_sym_mv(&w.K, w.p, w.Kp);
            double plen = sqrt(dot(w.p, w.p, nd));
            double pred = dot(w.rhs, w.p, nd) - 0.5 * dot(w.p, w.Kp, nd);
            memcpy(w.xt, x, 3 * np * sizeof *x);
            for (size_t i = 0; i < np; i++)
                if (w.dof[i] >= 0)
                    for (int a = 0; a < dim; a++)
                        w.xt[3 * i + a] += w.p[w.dof[i] + a];
            rc = eval_at(c, g, w.xt, r, np, E, prm, w.ft, &phit);
            if (rc != 0)
                goto out;
            ftn = norm_on(w.ft, is_free, np, dim);
            double rho;
            if (pred <= ENERGY_ROUNDOFF * fabs(phi))
                rho = ftn < fn ? 1 : 0; /* energy change lost in round-off */
            else
                rho = (phi - phit) / pred;
            if (rho < 0.25)
                radius = 0.25 * plen;
            else if (rho > 0.75 && plen >= 0.99 * radius)
                radius *= 2;
            if (rho > ACCEPT_RATIO)
                accepted = 1;
            else
                ns->cuts++;
        }
        ns->iterations++;
        mu = mu > 10 * MIN_SHIFT * E ? 0.1 * mu : 0;
        if (!accepted) {
            rc = eval_at(c, g, x, r, np, E, prm, w.f, &phi); /* back to the last point */
            if (rc != 0)
                goto out;
            ns->exit = PK_NEWTON_TRUST_REGION;
            break;
        }
        memcpy(x, w.xt, 3 * np * sizeof *x);
        memcpy(w.f, w.ft, 3 * np * sizeof *w.f);
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
    /* DR from the start point, as if Newton had not been asked: where Newton
     * stalls the configuration is near an instability (negative curvature,
     * contacts chattering), and DR's eigenvalue estimates taken there cost
     * it several times the iterations it needs from the start. */
    memcpy(x, w.x0, 3 * np * sizeof *x);
    rc = pk_homog_relax(c, g, x, r, np, E, is_free, prm, mon, st);
out:
    work_free(&w);
    return rc;
}
