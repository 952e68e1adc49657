#include "homog_newton.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "dem_rattler.h"
#include "homog_eigen.h"
#include "homog_stiffness.h"

/* Stiffness added on rattler DOFs (× E): a rattler without contacts has no
 * stiffness at all, and its force is zero, so any small shift gives the
 * right step (zero) without spoiling the conditioning of the jammed part. */
#define RATTLER_SHIFT 1e-6
/* Levenberg–Marquardt shifts (× E) tried on an indefinite block. */
#define MIN_SHIFT 1e-6
#define MAX_SHIFT 1e2
/* Armijo: accept a step achieving this share of the linear decrease. */
#define ARMIJO 1e-4
/* Below this relative size the energy difference is round-off: judge the
 * step by the residual instead (near convergence f·Δx ~ |f|²/λ is ~1e-18 Φ). */
#define ENERGY_ROUNDOFF 1e-11
/* Factorisations without halving the residual before giving up to DR. */
#define STALL_FACTORS 6
/* Quasi-Newton steps per factorisation: at most, and the window within which
 * the residual must halve before the preconditioner is refreshed. */
#define MAX_INNER 60
#define REFRESH_WINDOW 12
/* Line-search halvings before the direction is given up. */
#define MAX_CUTS 30
/* L-BFGS memory (pairs). */
#define MEMORY 8

const char *pk_newton_exit_name(pk_newton_exit e)
{
    switch (e) {
    case PK_NEWTON_CONVERGED: return "converged";
    case PK_NEWTON_BLOCK_NOT_PD: return "block_not_positive_definite";
    case PK_NEWTON_LINE_SEARCH: return "line_search_failed";
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

/* L-BFGS memory in DOF space: ring of (s, y, 1/s·y). */
typedef struct qn_memory {
    size_t nd, count, head;
    double *s, *y, rho[MEMORY], alpha[MEMORY];
} qn_memory;

static void qn_push(qn_memory *q, const double *sv, const double *yv)
{
    double sy = dot(sv, yv, q->nd);
    if (!(sy > 1e-14 * sqrt(dot(sv, sv, q->nd) * dot(yv, yv, q->nd))))
        return; /* curvature condition fails (non-convex region): skip the pair */
    memcpy(&q->s[q->head * q->nd], sv, q->nd * sizeof *sv);
    memcpy(&q->y[q->head * q->nd], yv, q->nd * sizeof *yv);
    q->rho[q->head] = 1 / sy;
    q->head = (q->head + 1) % MEMORY;
    if (q->count < MEMORY)
        q->count++;
}

/* d = −H g by the two-loop recursion with H₀ = M⁻¹ (Nocedal & Wright Alg.
 * 7.4): M the factorised stiffness, so the first step is Newton's. */
static int qn_direction(qn_memory *q, const pk_sparse_solver *solver, pk_sparse_factor *fac,
                        const double *gv, double *qv, double *d)
{
    size_t nd = q->nd;
    memcpy(qv, gv, nd * sizeof *qv);
    for (size_t k = 0; k < q->count; k++) {
        size_t i = (q->head + MEMORY - 1 - k) % MEMORY;
        q->alpha[i] = q->rho[i] * dot(&q->s[i * nd], qv, nd);
        for (size_t e = 0; e < nd; e++)
            qv[e] -= q->alpha[i] * q->y[i * nd + e];
    }
    if (solver->solve(fac, 1, qv, d) != 0)
        return -1;
    for (size_t k = q->count; k-- > 0;) {
        size_t i = (q->head + MEMORY - 1 - k) % MEMORY;
        double beta = q->rho[i] * dot(&q->y[i * nd], d, nd);
        for (size_t e = 0; e < nd; e++)
            d[e] += q->s[i * nd + e] * (q->alpha[i] - beta);
    }
    for (size_t e = 0; e < nd; e++)
        d[e] = -d[e];
    return 0;
}

typedef struct newton_work {
    double *x0, *f, *ft, *xt, *g, *gt, *d, *qv, *sv, *yv;
    qn_memory mem;
    uint8_t *rat;
    int32_t *dof;
    pk_sparse_sym K;
} newton_work;

static int work_alloc(newton_work *w, size_t np, int dim)
{
    size_t n3 = 3 * (np ? np : 1), n1 = np ? np : 1, nd = (size_t)dim * n1;
    memset(w, 0, sizeof *w);
    double **v3[] = {&w->x0, &w->f, &w->ft, &w->xt};
    double **vd[] = {&w->g, &w->gt, &w->d, &w->qv, &w->sv, &w->yv};
    for (size_t k = 0; k < sizeof v3 / sizeof *v3; k++)
        if (!(*v3[k] = malloc(n3 * sizeof **v3[k])))
            return -1;
    for (size_t k = 0; k < sizeof vd / sizeof *vd; k++)
        if (!(*vd[k] = malloc(nd * sizeof **vd[k])))
            return -1;
    w->mem.s = malloc(MEMORY * nd * sizeof *w->mem.s);
    w->mem.y = malloc(MEMORY * nd * sizeof *w->mem.y);
    w->rat = malloc(n1);
    w->dof = malloc(n1 * sizeof *w->dof);
    return w->mem.s && w->mem.y && w->rat && w->dof ? 0 : -1;
}

static void work_free(newton_work *w)
{
    free(w->x0), free(w->f), free(w->ft), free(w->xt), free(w->g), free(w->gt), free(w->d),
        free(w->qv), free(w->sv), free(w->yv), free(w->mem.s), free(w->mem.y), free(w->rat),
        free(w->dof);
    pk_sparse_sym_free(&w->K);
}

/* g = −f on the DOFs (the gradient of Φ_n). */
static void gather_gradient(const double *f, const int32_t *dof, size_t np, int dim, double *gv)
{
    for (size_t i = 0; i < np; i++)
        if (dof[i] >= 0)
            for (int a = 0; a < dim; a++)
                gv[dof[i] + a] = -f[3 * i + a];
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
    if (work_alloc(&w, np, dim) != 0) {
        rc = -1;
        goto out;
    }
    memcpy(w.x0, x, 3 * np * sizeof *x);
    double phi;
    pk_dem_eval(c, g, x, r, np, E, w.f, &phi, NULL);
    double f0 = sqrt(pk_homog_dot_mask(w.f, w.f, is_free, np, dim)), fn = f0;
    double target = fmax(prm->tol * f0, prm->abs_floor);
    double best = fn;
    size_t best_it = 0;
    double mu = 0; /* Levenberg–Marquardt shift, kept (decaying) across factorisations */
    size_t nd = 0;
    for (size_t i = 0; i < np; i++)
        w.dof[i] = is_free[i] ? (int32_t)(dim * nd++) : -1;
    nd *= (size_t)dim;
    w.mem.nd = nd;
    ns->exit = PK_NEWTON_CAP;
    while (fn > target) {
        if (ns->iterations >= max_newton)
            break;
        if (fn < 0.5 * best) {
            best = fn;
            best_it = ns->iterations;
        } else if (ns->iterations >= best_it + STALL_FACTORS) {
            ns->exit = PK_NEWTON_STALLED;
            break;
        }
        if (pk_dem_rattlers(c, dim, np, is_free, w.rat) == (size_t)-1) {
            rc = -1;
            goto out;
        }
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
        ns->iterations++;
        mu = mu > 10 * MIN_SHIFT * E ? 0.1 * mu : 0;
        /* Quasi-Newton steps preconditioned by this factor: exact Newton first,
         * then L-BFGS corrections as contacts open and close, until the
         * residual stops halving within the window (refresh the factor). */
        w.mem.count = w.mem.head = 0;
        gather_gradient(w.f, w.dof, np, dim, w.g);
        double f_window = fn;
        size_t window_start = 0;
        int failed_first = 0;
        for (size_t inner = 0; inner < MAX_INNER && fn > target; inner++) {
            if (qn_direction(&w.mem, solver, fac, w.g, w.qv, w.d) != 0) {
                solver->release(fac);
                rc = -1;
                goto out;
            }
            double gd = dot(w.g, w.d, nd);
            if (!(gd < 0)) { /* memory spoilt the direction: plain preconditioned step */
                w.mem.count = w.mem.head = 0;
                if (qn_direction(&w.mem, solver, fac, w.g, w.qv, w.d) != 0) {
                    solver->release(fac);
                    rc = -1;
                    goto out;
                }
                gd = dot(w.g, w.d, nd);
                if (!(gd < 0))
                    break;
            }
            double s = 1, phit = phi, ftn = fn;
            int ok = 0;
            for (int cut = 0; cut < MAX_CUTS; cut++, s *= 0.5) {
                memcpy(w.xt, x, 3 * np * sizeof *x);
                for (size_t i = 0; i < np; i++)
                    if (w.dof[i] >= 0)
                        for (int a = 0; a < dim; a++)
                            w.xt[3 * i + a] += s * w.d[w.dof[i] + a];
                rc = eval_at(c, g, w.xt, r, np, E, prm, w.ft, &phit);
                if (rc != 0) {
                    solver->release(fac);
                    goto out;
                }
                ftn = sqrt(pk_homog_dot_mask(w.ft, w.ft, is_free, np, dim));
                double lin = -s * gd; /* predicted decrease to first order */
                if (lin <= ENERGY_ROUNDOFF * fabs(phi))
                    ok = ftn < fn; /* energy change lost in round-off */
                else
                    ok = phit <= phi - ARMIJO * lin;
                if (ok)
                    break;
                ns->cuts++;
            }
            if (!ok) {
                failed_first = inner == 0;
                break;
            }
            gather_gradient(w.ft, w.dof, np, dim, w.gt);
            for (size_t e = 0; e < nd; e++) {
                w.sv[e] = s * w.d[e];
                w.yv[e] = w.gt[e] - w.g[e];
            }
            qn_push(&w.mem, w.sv, w.yv);
            memcpy(w.g, w.gt, nd * sizeof *w.g);
            memcpy(x, w.xt, 3 * np * sizeof *x);
            memcpy(w.f, w.ft, 3 * np * sizeof *w.f);
            phi = phit;
            fn = ftn;
            ns->steps++;
            if (fn < 0.5 * f_window) {
                f_window = fn;
                window_start = inner;
            } else if (inner >= window_start + REFRESH_WINDOW) {
                break;
            }
            if (mon) {
                pk_progress pr = {.stage = "newton", .fraction = -1, .phi = -1, .eta_s = -1,
                                  .done = ns->steps};
                int t = pk_monitor_tick(mon, &pr, 0);
                if (t) {
                    solver->release(fac);
                    st->stop = t == 1 ? PK_DR_CANCELLED : PK_DR_WALL_TIME;
                    st->f0 = f0;
                    st->f = fn;
                    goto out;
                }
            }
        }
        solver->release(fac);
        rc = eval_at(c, g, x, r, np, E, prm, w.f, &phi); /* contacts of the current point */
        if (rc != 0)
            goto out;
        if (failed_first) {
            ns->exit = PK_NEWTON_LINE_SEARCH;
            break;
        }
    }
    if (fn <= target) {
        ns->exit = PK_NEWTON_CONVERGED;
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
