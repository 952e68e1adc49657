/* homog_newton.c — the serial Newton/DR/FIRE hybrid and its step in parts.
 * Contract: homog_newton.h (public), homog_hybrid.h (the parts). */
#include "homog_newton.h"
#include "homog_hybrid.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/dem/dem_rattler.h"
#include "homog_eigen.h"
#include "homog_fire.h"
#include "homog_stiffness.h"

/* Tuned constants: the measurements behind each are in docs/perf/homog.md,
 * under its name; the figures quoted come from bench/homog (near-jamming
 * and dense 10⁴-grain RVEs, one 0.1 % compression step). */
/* Stiffness added on rattler DOFs (× E): a rattler without contacts has no
 * stiffness at all, and its force is zero, so any small shift gives the
 * right step (zero) without spoiling the conditioning of the jammed part. */
#define RATTLER_SHIFT 1e-6
/* Armijo: accept a step achieving this share of the linear decrease. */
#define ARMIJO 1e-4
/* Below this relative size the energy difference is round-off: judge the
 * step by the residual instead (near convergence f·Δx ~ |f|²/λ is ~1e-18 Φ). */
#define ENERGY_ROUNDOFF 1e-11
/* Factorisations without halving the residual after which Newton hands the
 * step to DR (from the step's start: DR restarts there anyway) or gives an
 * attempt up (more: it may first slide along a soft mode; 5 seen at 10⁴). */
#define STALL_FACTORS 1
#define ATTEMPT_STALL 6
/* Residual rises between factorisation points that end an attempt: a
 * converging one rises at most once (near-jamming 10⁴: 19 → 11 factorisations). */
#define ATTEMPT_RISES 2
/* Residuals (× |f⁰|) of DR's (then FIRE's) points where Newton attempts to
 * finish the step: HANDOVER, × HANDOVER_STEP, …; 0.3–0.7 all end in DR's
 * minimum, 0.5 fewest factorisations (near-jamming 10⁴: 7). */
#define HANDOVER 1e-3
#define HANDOVER_STEP 0.5
/* DR iterations after a failed attempt without reaching the next threshold
 * nor rising (pk_dr_hook.crawl) after which the next attempt is made anyway:
 * DR creeps along a mode softer than its λ_min (one 10⁴ RVE: 8,750 iterations). */
#define CRAWL 1000
/* Unsolved attempt points after which FIRE replaces DR: with 1 FIRE leaves
 * DR's path during the rearrangement (2 of 3 plastic test cases end higher);
 * with 2 every case measured ends in DR's minimum. */
#define FIRE_AFTER 2
/* Quasi-Newton steps per factorisation: at most, and the window within which
 * the residual must halve before the preconditioner is refreshed. */
#define MAX_INNER 60
#define REFRESH_WINDOW 12
/* Line-search cuts before the direction is given up; a cut takes the minimiser
 * of the quadratic through Φ(0), Φ'(0), Φ(s) (Nocedal & Wright §3.5) within
 * [CUT_MIN, CUT_MAX]·s: 2.5–3.5 evaluations per step near jamming, halving 7. */
#define MAX_CUTS 12
#define CUT_MIN 0.1
#define CUT_MAX 0.5
/* Largest displacement of a grain per step, × the Verlet skin (a trust region
 * in the max norm); 0.2–0.4 faster on four 10⁴ seeds, slower on the worst. */
#define MAX_MOVE 0.5
/* Levenberg–Marquardt shifts (× E) of an attempt: first, largest, dropped
 * below; at most SHIFT_RAISES raises (a converging 10⁴ attempt needed 2), and
 * none once the residual rose above DR's point (0 of 10 such ones converged). */
#define SHIFT_FIRST 1e-3
#define SHIFT_MAX 1e-1
#define SHIFT_MIN 1e-6
#define SHIFT_RAISES 3

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

/* K over every free DOF: the exact Hessian (4.11)–(4.14) on contacts
 * between jammed grains — what makes Newton quadratic and what the tangent
 * uses — and the Gauss–Newton part E n⊗n (positive semi-definite) on contacts
 * that touch a rattler, plus a small shift on rattler DOFs, which may have no
 * stiffness at all.  A rattler is thus pushed out of its overlaps along n in
 * one step instead of being left to a separate relaxation.  μ > 0: the
 * Levenberg–Marquardt shift of an attempt from DR's point (pk_hybrid_newton_phase). */
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
        if (dof[i] >= 0 && (rat[i] || mu > 0))
            for (int a = 0; a < dim; a++)
                if (pk_sparse_sym_add(K, dof[i] + a, dof[i] + a,
                                      mu + (rat[i] ? RATTLER_SHIFT * E : 0)) != 0)
                    return -1;
    return 0;
}

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

/* Rattlers at the current contacts, K + μ1 assembled and factorised (one
 * factorisation counted).  NULL with info->status FAILED on error. */
static pk_sparse_factor *factor_block(const newton_run *sy, newton_work *w, double mu,
                                      size_t *budget, pk_newton_stats *ns, pk_sparse_info *info)
{
    const int dim = sy->s.g->dim;
    info->status = PK_SPARSE_FAILED;
    if (pk_dem_rattlers(sy->s.c, dim, sy->s.np, sy->s.is_free, w->rat) == (size_t)-1)
        return NULL;
    w->K.nnz = 0;
    w->K.n = w->mem.nd;
    if (assemble(sy->s.c, dim, sy->s.E, w->dof, w->rat, mu, sy->s.np, &w->K) != 0)
        return NULL;
    if (*budget > 0) /* the check of a shifted end point may come with the budget spent */
        (*budget)--;
    ns->iterations++;
    /* Newton asks "PD?" only; an unchanged contact pattern reuses the
     * previous analysis, same numbers (it repeats across elastic steps of a
     * load path, not within one relaxation: the context spans the path) */
    pk_sparse_factor *F = sy->sctx ? sy->solver->factor_pd_ctx(sy->sctx, &w->K, info)
                                   : sy->solver->factor_pd(&w->K, info);
    ns->reused += info->reused_analysis != 0;
    return F;
}

/* Trust region in the max norm: no grain moves more than MAX_MOVE Verlet
 * skins per step — along a soft mode the step is cut to the region where
 * contacts are known (trial points keep their candidate list, no rebuild per
 * line-search cut).  Scales d (nd entries, dim per grain) and *gd with it. */
static void trust_region(double *d, size_t nd, int dim, double skin, double *gd)
{
    double dmax2 = 0;
    for (size_t e = 0; e < nd; e += (size_t)dim) {
        double q = 0;
        for (int a = 0; a < dim; a++)
            q += d[e + a] * d[e + a];
        dmax2 = fmax(dmax2, q);
    }
    double reach = MAX_MOVE * skin;
    if (dmax2 > reach * reach) {
        double shrink = reach / sqrt(dmax2);
        for (size_t e = 0; e < nd; e++)
            d[e] *= shrink;
        *gd *= shrink;
    }
}

/* A line-search outcome: step s to the trial point w->xt (forces w->ft),
 * its energy and residual, and whether it was accepted. */
typedef struct trial {
    double s, phi, fn;
    int ok;
} trial;

/* Backtracking line search from x along w->d (slope gd < 0): accept by
 * Armijo's rule, or by a lower residual where the energy change is lost in
 * round-off; each cut takes the minimiser of the quadratic through Φ(0),
 * Φ'(0), Φ(s) (Nocedal & Wright §3.5) within [CUT_MIN, CUT_MAX]·s.  Returns
 * the force evaluation's error, else 0 with *t. */
static int line_search(const newton_run *sy, newton_work *w, const double *x, double phi, double fn,
                       double gd, pk_newton_stats *ns, trial *t)
{
    const int dim = sy->s.g->dim;
    const size_t np = sy->s.np;
    double s = 1, phit = phi, ftn = fn, cut_by = CUT_MAX;
    int ok = 0, rc = 0;
    for (int cut = 0; cut < MAX_CUTS; cut++, s *= cut_by) {
        memcpy(w->xt, x, 3 * np * sizeof *x);
        for (size_t i = 0; i < np; i++)
            if (w->dof[i] >= 0)
                for (int a = 0; a < dim; a++)
                    w->xt[3 * i + a] += s * w->d[w->dof[i] + a];
        rc = eval_at(sy->s.c, sy->s.g, w->xt, sy->s.r, np, sy->s.E, sy->prm, w->ft, &phit);
        if (rc != 0)
            break;
        ftn = sqrt(pk_homog_dot_mask(w->ft, w->ft, sy->s.is_free, np, dim));
        double lin = -s * gd; /* predicted decrease to first order */
        if (lin <= ENERGY_ROUNDOFF * fabs(phi))
            ok = ftn < fn; /* energy change lost in round-off */
        else
            ok = phit <= phi - ARMIJO * lin;
        if (ok)
            break;
        ns->cuts++;
        /* Φ(t) ≈ Φ + t·gd + c t² through Φ(s): its minimiser over s */
        cut_by = lin > ENERGY_ROUNDOFF * fabs(phi)
            ? fmax(CUT_MIN, fmin(CUT_MAX, 0.5 * lin / (phit - phi + lin)))
            : CUT_MAX;
    }
    *t = (trial){.s = s, .phi = phit, .fn = ftn, .ok = ok};
    return rc;
}

/* Move to the accepted trial point: the L-BFGS pair (s·d, Δg) joins the
 * memory, the point, its forces, energy and residual become current. */
static void take_step(const newton_run *sy, newton_work *w, const trial *t, double *x, double *phi,
                      double *fn)
{
    const int dim = sy->s.g->dim;
    const size_t np = sy->s.np, nd = w->mem.nd;
    gather_gradient(w->ft, w->dof, np, dim, w->gt);
    for (size_t e = 0; e < nd; e++) {
        w->sv[e] = t->s * w->d[e];
        w->yv[e] = w->gt[e] - w->g[e];
    }
    qn_push(&w->mem, w->sv, w->yv);
    memcpy(w->g, w->gt, nd * sizeof *w->g);
    memcpy(x, w->xt, 3 * np * sizeof *x);
    memcpy(w->f, w->ft, 3 * np * sizeof *w->f);
    *phi = t->phi;
    *fn = t->fn;
}

/* The stop checks between steps: 1 when the abort flag is set or the monitor
 * asks to stop (st->stop set then), else 0. */
static int newton_tick(const newton_run *sy, const pk_newton_stats *ns, pk_dr_stats *st)
{
    if (sy->abort && atomic_load(sy->abort))
        return 1;
    if (sy->mon) {
        pk_progress pr = {
            .stage = "newton", .fraction = -1, .phi = -1, .eta_s = -1, .done = ns->steps};
        int t = pk_monitor_tick(sy->mon, &pr, 0);
        if (t) {
            st->stop = t == 1 ? PK_DR_CANCELLED : PK_DR_WALL_TIME;
            return 1;
        }
    }
    return 0;
}

/* Quasi-Newton steps preconditioned by the factor fac: exact Newton first,
 * then L-BFGS corrections as contacts open and close, until the residual
 * stops halving within REFRESH_WINDOW steps (the caller refreshes the
 * factor), reaches target, or MAX_INNER steps.  *failed_first: the first
 * step's line search failed.  Returns 0, -1 (memory), -2 (box), 1 (stop). */
static int qn_steps(const newton_run *sy, newton_work *w, pk_sparse_factor *fac, double *x,
                    double *phi, double *fn, double target, int *failed_first, pk_newton_stats *ns,
                    pk_dr_stats *st)
{
    const size_t nd = w->mem.nd;
    w->mem.count = w->mem.head = 0;
    gather_gradient(w->f, w->dof, sy->s.np, sy->s.g->dim, w->g);
    double f_window = *fn;
    size_t window_start = 0;
    *failed_first = 0;
    for (size_t inner = 0; inner<MAX_INNER && * fn> target; inner++) {
        if (qn_direction(&w->mem, sy->solver, fac, w->g, w->qv, w->d) != 0)
            return -1;
        double gd = dot(w->g, w->d, nd);
        if (!(gd < 0)) { /* memory spoilt the direction: plain preconditioned step */
            w->mem.count = w->mem.head = 0;
            if (qn_direction(&w->mem, sy->solver, fac, w->g, w->qv, w->d) != 0)
                return -1;
            gd = dot(w->g, w->d, nd);
            if (!(gd < 0))
                return 0;
        }
        trust_region(w->d, nd, sy->s.g->dim, sy->prm->skin, &gd);
        trial t;
        int rc = line_search(sy, w, x, *phi, *fn, gd, ns, &t);
        if (rc != 0)
            return rc;
        if (!t.ok) {
            *failed_first = inner == 0;
            return 0;
        }
        take_step(sy, w, &t, x, phi, fn);
        ns->steps++;
        if (*fn < 0.5 * f_window) {
            f_window = *fn;
            window_start = inner;
        } else if (inner >= window_start + REFRESH_WINDOW) {
            return 0;
        }
        if (newton_tick(sy, ns, st))
            return 1;
    }
    return 0;
}

/* A point reached with a Levenberg–Marquardt shift is a minimum only if the
 * unshifted block is positive definite there: ns->exit says which. */
static int confirm_minimum(const newton_run *sy, newton_work *w, size_t *budget,
                           pk_newton_stats *ns)
{
    pk_sparse_info info;
    pk_sparse_factor *fac = factor_block(sy, w, 0, budget, ns, &info);
    sy->solver->release(fac);
    if (info.status == PK_SPARSE_FAILED)
        return -1;
    ns->exit = info.status == PK_SPARSE_OK ? PK_NEWTON_CONVERGED : PK_NEWTON_BLOCK_NOT_PD;
    return 0;
}

/* The Levenberg–Marquardt shift of an attempt (see pk_hybrid_newton_phase). */
typedef struct lm_shift {
    double mu, mu_used;
    int stable_start; /* the block was positive definite at the entry point */
    int raises, hold; /* hold: keep μ at the next positive definite factorisation */
} lm_shift;

/* After an indefinite block: 1 if μ is raised (×10, or SHIFT_FIRST·E) for
 * another factorisation, 0 if the phase ends. */
static int lm_raise(lm_shift *m, double E, int shift, double fn, double f_entry,
                    pk_newton_stats *ns)
{
    if (!(shift && m->stable_start && m->raises < SHIFT_RAISES && m->mu < SHIFT_MAX * E &&
          fn <= f_entry))
        return 0;
    m->mu = m->mu > 0 ? 10 * m->mu : SHIFT_FIRST * E;
    ns->shifts++;
    m->raises++;
    m->hold = 1;
    return 1;
}

/* After a positive definite factorisation with μ: μ ÷ 10 for the next one
 * (held once after a raise), 0 below SHIFT_MIN·E. */
static void lm_factored(lm_shift *m, double E)
{
    m->mu_used = m->mu;
    if (m->hold)
        m->hold = 0;
    else
        m->mu = m->mu > 10 * SHIFT_MIN * E ? 0.1 * m->mu : 0;
    m->stable_start = 1;
}

/* One Newton phase from x (w->f, *phi, *fn describe x on entry and on exit):
 * factorisations of the stiffness at the current point, each followed by
 * L-BFGS steps it preconditions, until |f| <= target.  It hands back
 * (ns->exit != CONVERGED, x at its last, lowest-energy point) as soon as
 * the step leaves the region where Newton is fast: the exact block is not
 * positive definite (an instability — the configuration must rearrange), a
 * fresh Newton direction finds no decrease, or the residual does not halve
 * over `stall` factorisations (an attempt also when it rises ATTEMPT_RISES
 * times from one factorisation's point to the next).
 * With `shift` (an attempt from DR's point) and a positive definite block at
 * the entry point (DR is past the instability; Newton's own path met one) an
 * indefinite block gets a Levenberg–Marquardt shift μ instead: SHIFT_FIRST·E,
 * ×10 while indefinite (at most SHIFT_RAISES times), ÷10 per positive
 * definite factorisation except the first after a raise (held once: the
 * lower μ was just found indefinite), 0 below SHIFT_MIN·E — but only while
 * the residual is at most its value at the entry point (above: the phase
 * ends).  A point
 * reached with μ > 0 counts as converged only if the unshifted block is
 * positive definite there (a minimum, not a saddle).
 * *budget factorisations at most (decremented).
 * Returns 0, -1 (memory), -2 (box), 1 (cancelled: st->stop set). */
int pk_hybrid_newton_phase(const newton_run *sy, newton_work *w, double *x, double *phi, double *fn,
                           double target, size_t stall, int shift, size_t *budget,
                           pk_newton_stats *ns, pk_dr_stats *st)
{
    const double E = sy->s.E;
    const double f_entry = *fn; /* no shift once the residual rose above it */
    double best = *fn;
    size_t since_best = 0;
    int rises = 0; /* of the residual between factorisation points (attempts) */
    lm_shift m = {0};
    ns->exit = PK_NEWTON_CAP;
    while (*fn > target) {
        if (*budget == 0)
            return 0;
        if (sy->abort && atomic_load(sy->abort))
            return 1;
        if (since_best >= stall) {
            ns->exit = PK_NEWTON_STALLED;
            return 0;
        }
        pk_sparse_info info;
        pk_sparse_factor *fac = factor_block(sy, w, m.mu, budget, ns, &info);
        if (info.status != PK_SPARSE_OK) {
            sy->solver->release(fac);
            if (info.status == PK_SPARSE_FAILED)
                return -1;
            if (lm_raise(&m, E, shift, *fn, f_entry, ns))
                continue;
            ns->exit = PK_NEWTON_BLOCK_NOT_PD;
            return 0;
        }
        lm_factored(&m, E);
        const double f_factor = *fn;
        int failed_first;
        int rc = qn_steps(sy, w, fac, x, phi, fn, target, &failed_first, ns, st);
        sy->solver->release(fac);
        if (rc != 0)
            return rc;
        rc = eval_at(sy->s.c, sy->s.g, x, sy->s.r, sy->s.np, E, sy->prm, w->f,
                     phi); /* contacts of the current point */
        if (rc != 0)
            return rc;
        if (failed_first) {
            ns->exit = PK_NEWTON_LINE_SEARCH;
            return 0;
        }
        if (*fn < 0.5 * best) {
            best = *fn;
            since_best = 0;
        } else {
            since_best++;
        }
        if (shift && *fn > f_factor && ++rises >= ATTEMPT_RISES && *fn > target) {
            ns->exit = PK_NEWTON_STALLED;
            return 0;
        }
    }
    if (m.mu_used > 0) /* converged on a shifted model: a minimum only if K itself is PD */
        return confirm_minimum(sy, w, budget, ns);
    ns->exit = PK_NEWTON_CONVERGED;
    return 0;
}

/* The threshold of the next attempt after one at *at. */
void pk_hybrid_next_threshold(double *at, double target)
{
    *at *= HANDOVER_STEP;
    if (*at <= target)
        *at = 0; /* the relaxation finishes alone */
}

/* Newton from xn, a copy of a relaxation's point: 1 when it converged (xn
 * the solution, *fres its residual), 0 when not — or not tried, the budget
 * being spent —, < 0 on an error. */
int pk_hybrid_attempt_from(attempt_ctx *a, double *xn, double *fres)
{
    newton_work *w = a->w;
    const int dim = a->sy.s.g->dim;
    const size_t np = a->sy.s.np;
    if (*a->budget == 0)
        return 0;
    int rc = pk_dem_pairs_build(a->sy.s.c, a->sy.s.g, xn, a->sy.s.r, np, a->sy.prm->skin);
    if (rc != 0)
        return rc;
    double phi;
    pk_dem_eval(a->sy.s.c, a->sy.s.g, xn, a->sy.s.r, np, a->sy.s.E, w->f, &phi, NULL);
    double fn = sqrt(pk_homog_dot_mask(w->f, w->f, a->sy.s.is_free, np, dim));
    a->ns->attempts++;
    pk_dr_stop keep = a->st->stop;
    rc = pk_hybrid_newton_phase(&a->sy, w, xn, &phi, &fn, a->target, ATTEMPT_STALL, 1, a->budget,
                                a->ns, a->st);
    if (rc < 0)
        return rc;
    if (rc == 1) { /* cancelled: the relaxation's monitor sees it within 64 iterations */
        a->st->stop = keep;
        return 0;
    }
    if (a->ns->exit != PK_NEWTON_CONVERGED)
        return 0;
    *fres = fn;
    return 1;
}

/* The hook's answer at an attempt point that was not solved.  A point where
 * the budget was spent counts as well: where DR stops for FIRE then depends
 * on the points alone, not on how the attempts ended — which the
 * speculative attempts below need (they learn it later). */
static int unsolved(attempt_ctx *a)
{
    return a->fire_after && ++a->failed >= a->fire_after ? 2 : 0;
}

static int newton_attempt(void *vctx, double *x, double *fres, double *at)
{
    attempt_ctx *a = vctx;
    pk_hybrid_next_threshold(at, a->target);
    double *xn = a->w->x0;
    memcpy(xn, x, 3 * a->sy.s.np * sizeof *x);
    int rc = pk_hybrid_attempt_from(a, xn, fres);
    if (rc < 0)
        return rc;
    if (rc == 1) {
        memcpy(x, xn, 3 * a->sy.s.np * sizeof *x);
        return 1;
    }
    return unsolved(a);
}

/* The parameters FIRE runs with after DR (fire_on): the step's target as
 * an absolute floor (it is relative to the step's |f⁰|, not FIRE's). */
pk_dr_params pk_hybrid_fire_params(const pk_dr_params *prm, double target, const pk_dr_stats *st)
{
    pk_dr_params p = *prm;
    p.tol = 0;
    p.abs_floor = target;
    p.max_iter = prm->max_iter > st->iterations ? prm->max_iter - st->iterations : 1;
    return p;
}

/* st (DR's statistics) with FIRE's fs after it added, and its end. */
void pk_hybrid_fire_merge(pk_dr_stats *st, const pk_dr_stats *fs, const pk_dr_params *prm,
                          pk_newton_stats *ns)
{
    st->iterations += fs->iterations;
    ns->fire_iterations = fs->iterations;
    st->rebuilds += fs->rebuilds;
    st->f = fs->f;
    st->dt = fs->dt;
    st->gamma = 0;
    st->stop = !pk_dr_stop_ok(fs->stop) ? fs->stop
        : fs->f <= prm->tol * st->f0    ? PK_DR_CONVERGED
                                        : PK_DR_CONVERGED_ABS;
}

/* FIRE from DR's point after a failed attempt (the attempts go on from
 * FIRE's points through the same hook) to the step's target; st (DR's
 * statistics so far) gets FIRE's iterations added and its end (the
 * alternatives measured against it: docs/perf/homog.md, fire_on). */
static int fire_on(const newton_run *sy, double *x, double target, pk_dr_hook *hook,
                   pk_dr_stats *st, pk_newton_stats *ns)
{
    pk_fire_params fp = pk_fire_params_default();
    pk_dr_params p = pk_hybrid_fire_params(sy->prm, target, st);
    pk_dr_stats fs;
    int rc = pk_homog_fire_hooked(&sy->s, x, &p, &fp, hook, sy->mon, &fs);
    pk_hybrid_fire_merge(st, &fs, sy->prm, ns);
    return rc;
}

/* DR, then FIRE (homog_hybrid.h): the path the serial step and the
 * speculative runner share. */
int pk_hybrid_relax_then_fire(const newton_run *sy, double *x, double target, pk_dr_hook *hook,
                              size_t *fire_after, int *in_fire, pk_dr_stats *st, pk_dr_stats *st_dr,
                              pk_newton_stats *ns)
{
    int rc = pk_homog_relax_hooked(&sy->s, x, sy->prm, hook, sy->mon, st);
    *st_dr = *st;
    if (rc == 0 && st->stop == PK_DR_HANDED_OVER && !(hook->poll && hook->poll(hook->ctx))) {
        *fire_after = 0;
        *in_fire = 1;
        hook->crawl = 0; /* FIRE does not creep: a slow FIRE climbs out of a saddle */
        rc = fire_on(sy, x, target, hook, st, ns);
    }
    return rc;
}

int pk_hybrid_begin(pk_hybrid *h, const pk_dem_system *s, const double *x, const pk_dr_params *prm,
                    const pk_newton_opts *no, pk_monitor *mon, pk_dr_stats *st, pk_newton_stats *ns)
{
    pk_dem_pairs *c = s->c;
    const int dim = s->g->dim;
    const size_t np = s->np;
    memset(h, 0, sizeof *h);
    memset(ns, 0, sizeof *ns);
    memset(st, 0, sizeof *st);
    int rc = pk_dem_pairs_build(c, s->g, x, s->r, np, prm->skin);
    if (rc != 0)
        return rc;
    newton_work *w = &h->w;
    pk_dem_pairs_stiffness(&h->c2, c->kclass, c->kmat, c->nclass, c->kref);
    h->c2.par = c->par;
    if (work_alloc(w, np, dim) != 0)
        return -1;
    h->sy = (newton_run){*s, prm, no->solver, no->sctx, mon, NULL};
    pk_dem_eval(c, s->g, x, s->r, np, s->E, w->f, &h->phi0, NULL);
    h->f0 = sqrt(pk_homog_dot_mask(w->f, w->f, s->is_free, np, dim));
    h->target = fmax(prm->tol * h->f0, prm->abs_floor);
    size_t nd = 0;
    for (size_t i = 0; i < np; i++)
        w->dof[i] = s->is_free[i] ? (int32_t)(dim * nd++) : -1;
    w->mem.nd = nd * (size_t)dim;
    h->budget = no->max_iter;
    return 0;
}

void pk_hybrid_end(pk_hybrid *h)
{
    pk_dem_pairs_free(&h->c2);
    work_free(&h->w);
}

pk_hybrid_plan pk_hybrid_plan_of(const pk_hybrid *h)
{
    pk_hybrid_plan plan = {STALL_FACTORS, FIRE_AFTER,
                           HANDOVER * h->f0 > h->target ? HANDOVER * h->f0 : 0, CRAWL};
    return plan;
}

int pk_hybrid_step(pk_hybrid *h, double *x, pk_dr_stats *st, pk_newton_stats *ns)
{
    const newton_run *sy = &h->sy;
    pk_dem_pairs *c = sy->s.c;
    const size_t np = sy->s.np;
    const double f0 = h->f0, target = h->target;
    double phi = h->phi0, fn = f0;
    memcpy(h->w.x0, x, 3 * np * sizeof *x);
    int rc = pk_hybrid_newton_phase(sy, &h->w, x, &phi, &fn, target, STALL_FACTORS, 0, &h->budget,
                                    ns, st);
    if (rc == 1) { /* cancelled */
        st->f0 = f0;
        st->f = fn;
        return 0;
    }
    if (rc != 0)
        return rc;
    if (ns->exit == PK_NEWTON_CONVERGED) {
        st->f0 = f0;
        st->f = fn;
        st->stop = fn <= sy->prm->tol * f0 ? PK_DR_CONVERGED : PK_DR_CONVERGED_ABS;
        return 0;
    }
    /* Newton left its region: the step crosses instabilities (contacts
     * open and close, grains rearrange — a plastic event).  DR takes the
     * step from its start point, as if Newton had not been asked, through
     * the rearrangement (the path is set by the fast modes); at residuals
     * HANDOVER·|f⁰|, HANDOVER_STEP× that, … Newton tries to finish the slow
     * tail near the new minimum from a copy of DR's point.  After FIRE_AFTER
     * failed attempts FIRE (homog_fire.h) goes on from DR's point, with the
     * further attempts from its points: in that tail DR spends most of its
     * iterations and FIRE needs far fewer (docs/perf/homog.md). */
    memcpy(x, h->w.x0, 3 * np * sizeof *x);
    attempt_ctx a = {*sy, &h->w, target, &h->budget, ns, st, FIRE_AFTER, 0};
    a.sy.s.c = &h->c2;
    pk_dr_hook hook = {.fn = newton_attempt,
                       .ctx = &a,
                       .at = HANDOVER * f0 > target ? HANDOVER * f0 : 0,
                       .crawl = CRAWL};
    pk_dr_stats st_dr;
    int in_fire = 0;
    rc = pk_hybrid_relax_then_fire(sy, x, target, &hook, &a.fire_after, &in_fire, st, &st_dr, ns);
    /* an attempt's point may be beyond DR's candidate list: the caller evaluates c at x */
    if (rc == 0 && pk_dem_pairs_stale(c, x, sy->s.g->dim))
        rc = pk_dem_pairs_build(c, sy->s.g, x, sy->s.r, np, sy->prm->skin);
    return rc;
}
