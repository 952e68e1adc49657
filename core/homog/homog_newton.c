#include "homog_newton.h"
#include "homog_hybrid.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/dem/dem_rattler.h"
#include "homog_eigen.h"
#include "homog_fire.h"
#include "homog_stiffness.h"
#include "core/base/par.h"

/* Where a near-jamming 10⁴ step goes (round 9, bench seed 6, HEAD 5f20cc2,
 * 2.36 s CPU: 12 factorisations, 571 DR + 5,651 FIRE iterations): force
 * evaluations 0.87 s (6,554 × 0.133 ms), CHOLMOD factorisations 0.48 s
 * (40 ms each: rattlers 1.4 ms, assembly 1 ms, the rest analyse + factor in
 * api/solver/sparse_cholmod.c), FIRE's vector passes 0.19 s + ~0.2 s of dot
 * products (fused since), L-BFGS solves 0.20 s (98 × 2.1 ms), pair-list
 * builds 0.19 s (47 × 4.0 ms, 88 % of it pk_grid's scan) — 39 of the 47 in
 * the line search: a full step moves its largest grain MAX_MOVE = skin/2,
 * so most first trials are stale (seed 8: 53 of 61).  Fewer or cheaper
 * builds move the list's order and with it the rounding (see
 * pk_dem_pairs_build). */
/* Stiffness added on rattler DOFs (× E): a rattler without contacts has no
 * stiffness at all, and its force is zero, so any small shift gives the
 * right step (zero) without spoiling the conditioning of the jammed part. */
#define RATTLER_SHIFT 1e-6
/* Armijo: accept a step achieving this share of the linear decrease. */
#define ARMIJO 1e-4
/* Below this relative size the energy difference is round-off: judge the
 * step by the residual instead (near convergence f·Δx ~ |f|²/λ is ~1e-18 Φ). */
#define ENERGY_ROUNDOFF 1e-11
/* Factorisations without halving the residual before Newton, from the step's
 * start, hands the step to DR — and before an attempt from one of DR's
 * points is given up.  An attempt gets more: near the end of a plastic
 * event Newton may first slide on along a soft mode (the residual rises,
 * Φ_n falls) before it converges (measured at 10⁴ grains: 5 factorisations,
 * where DR needs ~3,000 more iterations to the next attempt; with 3 also
 * from FIRE's points, 10 attempts instead of 3 on the near-jamming bench RVE).
 * From the step's start one factorisation whose L-BFGS steps do not halve
 * the residual is enough (was 3): DR starts from
 * the step's start, not from where Newton stopped, so the result only
 * changes where Newton would have converged after a factorisation that did
 * not halve the residual — none measured (40 plastic and elastic steps of
 * 200–400 grains; the 10⁴ bench steps and relaxations at F̄ = 1, where the
 * 2nd or 3rd factorisation was indefinite: 1–2 factorisations and their
 * L-BFGS window, ~0.1–0.25 s, saved per step, same DR path). */
#define STALL_FACTORS 1
#define ATTEMPT_STALL 6
/* Rises of the residual from one factorisation's point to the next after
 * which an attempt is given up.  A converging attempt rises at most once
 * (the slide along the soft mode) and then falls at every factorisation;
 * the failed attempts measured rise again within 1–2 factorisations and then
 * creep on (Φ_n −1e-5 relative) until ATTEMPT_STALL: near-jamming 10⁴ bench
 * RVE 19 → 11 factorisations, dense 10⁴ and test_homog_newton's cases the
 * same attempts succeed, same minima. */
#define ATTEMPT_RISES 2
/* Residuals (× |f⁰|) of DR's (then FIRE's) points from which Newton tries
 * to finish a step it could not take from the start: HANDOVER,
 * × HANDOVER_STEP, … (see pk_homog_newton).  With failed attempts cheap
 * (ATTEMPT_RISES) denser attempts pay: near-jamming 10⁴ bench RVE, step 0.3 /
 * 0.4 / 0.5 / 0.6 / 0.7: 6,073 / 4,711 / 4,066 / 3,786 / 3,587 DR+FIRE
 * iterations, 11 / 13 / 7 / 7 / 9 factorisations; every value from 0.3 to
 * 0.7 ends in DR's minimum on it and on test_homog_newton's cases. */
/* Sixth session, with DR's increments in its λ_min (homog_relax.c): the
 * failed attempts of the cached near-jamming 10⁴ steps all end with
 * block_not_positive_definite — seed 7's two at their first factorisation,
 * seed 6's four and seed 8's three at their second or third, after the residual
 * climbed ×3–×60 from DR's point — and cost seed 6 8 of its 12
 * factorisations and most of its 95 L-BFGS steps (estimated from their
 * unit costs, ~45 ms a factorisation and ~6 ms a step: ~0.8 of ~2.1 s).
 * Dropped: no attempt while the Rayleigh quotient of DR's increments since
 * the last estimate is negative (DR inside a rearrangement) — it never was
 * at an attempt (seeds 6–8: the same attempts, the same path).  Dropped
 * too: an attempt's factor refreshed as soon as its residual climbed above
 * 2× / 4× that at the factorisation (instead of REFRESH_WINDOW steps on):
 * the refreshed blocks were positive definite, the attempts went on and
 * failed later — seeds 5–9, 7 / 12 / 7 / 11 / 5 → 17 / 24 / 7 / 13 / 7
 * factorisations (2×), seed 6 2.3 → 4.0 s.  And the next threshold halved
 * once more after a failed attempt (×0.25): seed 6 12 → 8 factorisations but
 * 2.06 → 2.21 s (DR runs longer before FIRE), seed 7 1.96 → 3.19 s (13,602
 * creeping DR iterations), seeds 5/8/9 1.24/2.01/0.86 → 1.07/1.52/1.26 s. */
/* Seventh session, measured and not kept: FIRE's thresholds ×0.25 apart
 * instead of ×0.5 (one failing attempt fewer on seed 6: 1.71 → 1.60 s, the
 * same minimum; seeds 5, 7–9 ±0.07 s); ×0.125 and ×0.05 slower (seed 6:
 * 5,681 → 11,809 FIRE iterations) — a gain on one RVE is no rule. */
#define HANDOVER 1e-3
#define HANDOVER_STEP 0.5
/* DR iterations after a failed attempt in which the residual neither
 * reached the next threshold nor rose above the attempt's (pk_dr_hook.crawl)
 * after which the next attempt is made anyway: DR creeps along a mode far
 * softer than its λ_min estimate (Lanczos, 40 steps: 4e-3, where the block's
 * λ_min is ~1e-5 at 10⁴ grains near jamming) — measured 8,750 iterations
 * from 1.05e-4 to 5.3e-5 on one RVE; the attempt fails there too, so FIRE
 * (FIRE_AFTER) takes the creep over.  Between DR's attempts the residual
 * halves within 200–550 iterations on the other bench RVEs and never creeps
 * 1,000 iterations in test_homog_newton's cases (500 changes one 10⁴ path). */
#define CRAWL 1000
/* Failed attempts from DR's points after which FIRE replaces DR.  1 is 2x
 * faster on the 10⁴ bench RVEs, but two of the three plastic cases of
 * test_homog_newton then end in another minimum of HIGHER energy (ΔΦ/Φ up to
 * +3e-3; all three with the first attempt at 3e-3): FIRE from rest at DR's
 * point leaves DR's path while the rearrangement still goes on (even where
 * the block is positive definite there: the 400-grain case).  After 2, every
 * case measured ends in DR's minimum (FIRE then starts at HANDOVER ×
 * HANDOVER_STEP = 5e-4·|f⁰| at the earliest). */
#define FIRE_AFTER 2
/* Quasi-Newton steps per factorisation: at most, and the window within which
 * the residual must halve before the preconditioner is refreshed. */
#define MAX_INNER 60
#define REFRESH_WINDOW 12
/* Line-search cuts before the direction is given up.  A cut takes the
 * minimiser of the quadratic through Φ(0), Φ'(0) and Φ(s) (Nocedal & Wright
 * §3.5), kept within [CUT_MIN, CUT_MAX]·s; halving when the energy change is
 * round-off.  Near jamming the first trials overshoot by far (contacts close
 * along a soft mode): halving took 7 evaluations per accepted step,
 * the interpolation 2.5–3.5 (near-jamming 10⁴ bench RVEs: 433 → 319 and
 * 644 → 279 evaluations in the Newton attempts, 12 → 10 factorisations on
 * the second, the same minima). */
#define MAX_CUTS 12
#define CUT_MIN 0.1
#define CUT_MAX 0.5
/* Largest displacement of a grain per step, × the Verlet skin.  Measured
 * (seventh session, cached 10⁴ bench steps, alternating pairs, CPU s): 0.3
 * cuts the pair-list builds 3–5× (a full first trial no longer leaves the
 * list's reach), the same DR/FIRE paths and minima (Φ to 1e-14), seeds 5, 7,
 * 8, 9 10–27 % faster — but seed 6 1.82–1.86 → 1.99–2.14 s (14 instead of
 * 12 factorisations, 138 instead of 95 steps in its failing attempts) and
 * the dense RVE 0.49–0.53 → 0.58 s; 0.2 and 0.4 alike.  Kept at 0.5. */
#define MAX_MOVE 0.5
/* Levenberg–Marquardt shifts (× E) of an attempt from DR's point: the first,
 * the largest, and the one below which the shift is dropped; at most
 * SHIFT_RAISES raises per attempt (a converging attempt needed 2 at 10⁴
 * grains; attempts that need more creep along a valley DR is faster down:
 * measured 7 raises and 13–17 factorisations in the relaxation of random
 * overlaps).  No shift once the attempt's residual has risen above its value
 * at DR's point: Newton then slid along a soft mode into another instability.
 * Measured (round 7): such shifted continuations converged in 0 of 10
 * attempts on the 10⁴ bench steps (near jamming seeds 5–9, dense 5–6) — each
 * cost 2–8 factorisations: step factorisations 9/24/7/21/5 → 7/14/7/12/5,
 * dense 7 → 6, same DR/FIRE path, same minima — and in 2 of 8 on 40 steps of
 * 200–400 grains (there the hybrid then needs 600–1,200 more relaxation
 * iterations, same minima).  With the rule no shift was made at all in those
 * 40 and 216 more 200–800-grain steps (φ 0.85–0.88, 0.5–2 %): the shift is
 * kept for a block that turns indefinite while the residual falls. */
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
static pk_sparse_factor *factor_block(const newton_sys *sy, newton_work *w, double mu,
                                      size_t *budget, pk_newton_stats *ns, pk_sparse_info *info)
{
    const int dim = sy->g->dim;
    info->status = PK_SPARSE_FAILED;
    if (pk_dem_rattlers(sy->c, dim, sy->np, sy->is_free, w->rat) == (size_t)-1)
        return NULL;
    w->K.nnz = 0;
    w->K.n = w->mem.nd;
    if (assemble(sy->c, dim, sy->E, w->dof, w->rat, mu, sy->np, &w->K) != 0)
        return NULL;
    if (*budget > 0) /* the check of a shifted end point may come with the budget spent */
        (*budget)--;
    ns->iterations++;
    /* Newton asks "PD?" only; an unchanged contact pattern reuses the
     * previous analysis, same numbers (measured round 10: it never repeats
     * within one relaxation of the bench RVEs or test cases, but in 12 of 25
     * factorisations over 20 elastic 0.01 % steps of a dense 10³ RVE: the
     * context spans the load path, api/homog/homog_run.c) */
    pk_sparse_factor *F = sy->sctx ? sy->solver->factor_pd_ctx(sy->sctx, &w->K, info)
                                   : sy->solver->factor_pd(&w->K, info);
    ns->reused += info->reused_analysis != 0;
    return F;
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
 * lower μ was just found indefinite; measured: one indefinite factorisation
 * less on both dense 10⁴ bench RVEs, one more on the 400-grain case of
 * test_homog_newton), 0 below SHIFT_MIN·E — but only while the residual is
 * at most its value at the entry point (above: the phase ends).  A point
 * reached with μ > 0 counts as converged only if the unshifted block is
 * positive definite there (a minimum, not a saddle).
 * *budget factorisations at most (decremented).
 * Returns 0, -1 (memory), -2 (box), 1 (cancelled: st->stop set). */
int pk_hybrid_newton_phase(const newton_sys *sy, newton_work *w, double *x, double *phi, double *fn,
                        double target, size_t stall, int shift, size_t *budget,
                        pk_newton_stats *ns, pk_dr_stats *st)
{
    pk_dem_pairs *c = sy->c;
    const pk_dem_geom *g = sy->g;
    const int dim = g->dim;
    const size_t np = sy->np, nd = w->mem.nd;
    const double E = sy->E;
    double best = *fn, mu = 0, mu_used = 0;
    const double f_entry = *fn; /* no shift once the residual rose above it */
    size_t since_best = 0;
    int stable_start = 0; /* the block was positive definite at the entry point */
    int raises = 0, hold = 0; /* hold: keep μ at the next positive definite factorisation */
    int rises = 0;            /* of the residual between factorisation points (attempts) */
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
        pk_sparse_factor *fac = factor_block(sy, w, mu, budget, ns, &info);
        if (info.status == PK_SPARSE_FAILED) {
            sy->solver->release(fac);
            return -1;
        }
        if (info.status != PK_SPARSE_OK) {
            sy->solver->release(fac);
            if (shift && stable_start && raises < SHIFT_RAISES && mu < SHIFT_MAX * E &&
                *fn <= f_entry) {
                mu = mu > 0 ? 10 * mu : SHIFT_FIRST * E;
                ns->shifts++;
                raises++;
                hold = 1;
                continue;
            }
            ns->exit = PK_NEWTON_BLOCK_NOT_PD;
            return 0;
        }
        mu_used = mu;
        if (hold)
            hold = 0;
        else
            mu = mu > 10 * SHIFT_MIN * E ? 0.1 * mu : 0;
        stable_start = 1;
        /* Quasi-Newton steps preconditioned by this factor: exact Newton first,
         * then L-BFGS corrections as contacts open and close, until the
         * residual stops halving within the window (refresh the factor). */
        w->mem.count = w->mem.head = 0;
        gather_gradient(w->f, w->dof, np, dim, w->g);
        const double f_factor = *fn;
        double f_window = *fn;
        size_t window_start = 0;
        int failed_first = 0, rc = 0;
        for (size_t inner = 0; inner < MAX_INNER && *fn > target; inner++) {
            if (qn_direction(&w->mem, sy->solver, fac, w->g, w->qv, w->d) != 0) {
                rc = -1;
                break;
            }
            double gd = dot(w->g, w->d, nd);
            if (!(gd < 0)) { /* memory spoilt the direction: plain preconditioned step */
                w->mem.count = w->mem.head = 0;
                if (qn_direction(&w->mem, sy->solver, fac, w->g, w->qv, w->d) != 0) {
                    rc = -1;
                    break;
                }
                gd = dot(w->g, w->d, nd);
                if (!(gd < 0))
                    break;
            }
            /* Trust region in the max norm: no grain moves more than half the
             * Verlet skin per step — along a soft mode the step is cut to the
             * region where contacts are known (trial points keep their
             * candidate list, no rebuild per line-search cut). */
            double dmax2 = 0;
            for (size_t e = 0; e < nd; e += (size_t)dim) {
                double q = 0;
                for (int a = 0; a < dim; a++)
                    q += w->d[e + a] * w->d[e + a];
                dmax2 = fmax(dmax2, q);
            }
            double reach = MAX_MOVE * sy->prm->skin;
            if (dmax2 > reach * reach) {
                double shrink = reach / sqrt(dmax2);
                for (size_t e = 0; e < nd; e++)
                    w->d[e] *= shrink;
                gd *= shrink;
            }
            double s = 1, phit = *phi, ftn = *fn, cut_by = CUT_MAX;
            int ok = 0;
            for (int cut = 0; cut < MAX_CUTS; cut++, s *= cut_by) {
                memcpy(w->xt, x, 3 * np * sizeof *x);
                for (size_t i = 0; i < np; i++)
                    if (w->dof[i] >= 0)
                        for (int a = 0; a < dim; a++)
                            w->xt[3 * i + a] += s * w->d[w->dof[i] + a];
                rc = eval_at(c, g, w->xt, sy->r, np, E, sy->prm, w->ft, &phit);
                if (rc != 0)
                    break;
                ftn = sqrt(pk_homog_dot_mask(w->ft, w->ft, sy->is_free, np, dim));
                double lin = -s * gd; /* predicted decrease to first order */
                if (lin <= ENERGY_ROUNDOFF * fabs(*phi))
                    ok = ftn < *fn; /* energy change lost in round-off */
                else
                    ok = phit <= *phi - ARMIJO * lin;
                if (ok)
                    break;
                ns->cuts++;
                /* Φ(t) ≈ Φ + t·gd + c t² through Φ(s): its minimiser over s */
                cut_by = lin > ENERGY_ROUNDOFF * fabs(*phi)
                             ? fmax(CUT_MIN, fmin(CUT_MAX, 0.5 * lin / (phit - *phi + lin)))
                             : CUT_MAX;
            }
            if (rc != 0)
                break;
            if (!ok) {
                failed_first = inner == 0;
                break;
            }
            gather_gradient(w->ft, w->dof, np, dim, w->gt);
            for (size_t e = 0; e < nd; e++) {
                w->sv[e] = s * w->d[e];
                w->yv[e] = w->gt[e] - w->g[e];
            }
            qn_push(&w->mem, w->sv, w->yv);
            memcpy(w->g, w->gt, nd * sizeof *w->g);
            memcpy(x, w->xt, 3 * np * sizeof *x);
            memcpy(w->f, w->ft, 3 * np * sizeof *w->f);
            *phi = phit;
            *fn = ftn;
            ns->steps++;
            if (*fn < 0.5 * f_window) {
                f_window = *fn;
                window_start = inner;
            } else if (inner >= window_start + REFRESH_WINDOW) {
                break;
            }
            if (sy->abort && atomic_load(sy->abort)) {
                rc = 1;
                break;
            }
            if (sy->mon) {
                pk_progress pr = {.stage = "newton", .fraction = -1, .phi = -1, .eta_s = -1,
                                  .done = ns->steps};
                int t = pk_monitor_tick(sy->mon, &pr, 0);
                if (t) {
                    st->stop = t == 1 ? PK_DR_CANCELLED : PK_DR_WALL_TIME;
                    rc = 1;
                    break;
                }
            }
        }
        sy->solver->release(fac);
        if (rc != 0)
            return rc;
        rc = eval_at(c, g, x, sy->r, np, E, sy->prm, w->f, phi); /* contacts of the current point */
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
    if (mu_used > 0) { /* converged on a shifted model: a minimum only if K itself is PD */
        pk_sparse_info info;
        pk_sparse_factor *fac = factor_block(sy, w, 0, budget, ns, &info);
        sy->solver->release(fac);
        if (info.status == PK_SPARSE_FAILED)
            return -1;
        if (info.status != PK_SPARSE_OK) {
            ns->exit = PK_NEWTON_BLOCK_NOT_PD;
            return 0;
        }
    }
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
    const int dim = a->sy.g->dim;
    const size_t np = a->sy.np;
    if (*a->budget == 0)
        return 0;
    int rc = pk_dem_pairs_build(a->sy.c, a->sy.g, xn, a->sy.r, np, a->sy.prm->skin);
    if (rc != 0)
        return rc;
    double phi;
    pk_dem_eval(a->sy.c, a->sy.g, xn, a->sy.r, np, a->sy.E, w->f, &phi, NULL);
    double fn = sqrt(pk_homog_dot_mask(w->f, w->f, a->sy.is_free, np, dim));
    a->ns->attempts++;
    pk_dr_stop keep = a->st->stop;
    rc = pk_hybrid_newton_phase(&a->sy, w, xn, &phi, &fn, a->target, ATTEMPT_STALL, 1, a->budget, a->ns,
                      a->st);
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
    memcpy(xn, x, 3 * a->sy.np * sizeof *x);
    int rc = pk_hybrid_attempt_from(a, xn, fres);
    if (rc < 0)
        return rc;
    if (rc == 1) {
        memcpy(x, xn, 3 * a->sy.np * sizeof *x);
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
    st->stop = !pk_dr_stop_ok(fs->stop)       ? fs->stop
               : fs->f <= prm->tol * st->f0 ? PK_DR_CONVERGED
                                             : PK_DR_CONVERGED_ABS;
}

/* FIRE from DR's point after a failed attempt (the attempts go on from
 * FIRE's points through the same hook) to the step's target; st (DR's
 * statistics so far) gets FIRE's iterations added and its end.
 * Measured and dropped (round 10, cached bench RVEs near-jamming 10⁴ seeds 6
 * and 8, HEAD 1.9–2.4 / 1.75–2.0 s CPU): instead of FIRE, L-BFGS
 * preconditioned by the Gauss–Newton stiffness Σ E n⊗n + μ·1 (always
 * positive definite; exact K whenever it is PD; Packwood et al., JCP 144,
 * 164109 (2016)): same minima (ΔΦ/Φ ≤ 1e-15), but 682 / 283 steps, 34 / 16
 * factorisations, 4.6 / 3.1 s (μ = 1e-4·E; 1e-3·E and 1e-5·E no better;
 * refreshing every 12 steps: 17 factorisations and then FIRE anyway).  The
 * tail is FIRE rolling out of a flat region into the next rearrangement
 * (seed 6: |f| rising ×10 over 3,500 iterations, the block positive definite
 * at FIRE's points): cutting the iterations 8× does not pay a solve
 * (~2 ms ≈ 15 force evaluations) per step.  An earlier first attempt
 * (HANDOVER 2e-3 / 3e-3, seed 7's 3,000 crawling DR iterations): same minima
 * on all six cached RVEs, total CPU of the six steps 9.0 s → 11.8 / 10.0 s.
 * Dropped too (seventh session): FIRE's Δt_max and DR's Δt from a λ_max
 * below Gershgorin's bound (which is 1.65× the power iteration's on these
 * blocks; scaled by 0.65): DR 15–20 % fewer iterations, but FIRE slower and
 * on seed 8 unstable (53,458 instead of 1,296 iterations). */
static int fire_on(pk_dem_pairs *c, const pk_dem_geom *g, double *x, const double *r, size_t np,
                   double E, const uint8_t *is_free, const pk_dr_params *prm, double target,
                   pk_dr_hook *hook, pk_monitor *mon, pk_dr_stats *st, pk_newton_stats *ns)
{
    pk_fire_params fp = pk_fire_params_default();
    pk_dr_params p = pk_hybrid_fire_params(prm, target, st);
    pk_dr_stats fs;
    int rc = pk_homog_fire_hooked(c, g, x, r, np, E, is_free, &p, &fp, hook, mon, &fs);
    pk_hybrid_fire_merge(st, &fs, prm, ns);
    return rc;
}

/* DR from x with the hook, then FIRE from DR's point when the hook stops DR
 * (hook->fn returned 2; not when hook->poll stopped it: *handed_over = 0).
 * The path both hybrids share. */
int pk_hybrid_relax_then_fire(pk_dem_pairs *c, const pk_dem_geom *g, double *x, const double *r,
                           size_t np, double E, const uint8_t *is_free, const pk_dr_params *prm,
                           double target, pk_dr_hook *hook, size_t *fire_after, int *in_fire,
                           pk_monitor *mon, pk_dr_stats *st, pk_dr_stats *st_dr,
                           pk_newton_stats *ns)
{
    int rc = pk_homog_relax_hooked(c, g, x, r, np, E, is_free, prm, hook, mon, st);
    *st_dr = *st;
    if (rc == 0 && st->stop == PK_DR_HANDED_OVER && !(hook->poll && hook->poll(hook->ctx))) {
        *fire_after = 0;
        *in_fire = 1;
        hook->crawl = 0; /* FIRE does not creep: a slow FIRE climbs out of a saddle */
        rc = fire_on(c, g, x, r, np, E, is_free, prm, target, hook, mon, st, ns);
    }
    return rc;
}


int pk_homog_newton(pk_dem_pairs *c, const pk_dem_geom *g, double *x, const double *r, size_t np,
                    double E, const uint8_t *is_free, const pk_dr_params *prm,
                    const pk_sparse_solver *solver, pk_sparse_ctx *sctx, size_t max_newton,
                    pk_monitor *mon, pk_dr_stats *st, pk_newton_stats *ns)
{
    const int dim = g->dim;
    memset(ns, 0, sizeof *ns);
    memset(st, 0, sizeof *st);
    int rc = pk_dem_pairs_build(c, g, x, r, np, prm->skin);
    if (rc != 0)
        return rc;
    newton_work w;
    pk_dem_pairs c2 = {0};
    pk_dem_pairs_stiffness(&c2, c->kclass, c->kmat, c->nclass, c->kref);
    c2.par = c->par;
    if (work_alloc(&w, np, dim) != 0) {
        rc = -1;
        goto out;
    }
    newton_sys sy = {c, g, r, np, E, is_free, prm, solver, sctx, mon, NULL};
    double phi;
    pk_dem_eval(c, g, x, r, np, E, w.f, &phi, NULL);
    double f0 = sqrt(pk_homog_dot_mask(w.f, w.f, is_free, np, dim)), fn = f0;
    double target = fmax(prm->tol * f0, prm->abs_floor);
    size_t nd = 0;
    for (size_t i = 0; i < np; i++)
        w.dof[i] = is_free[i] ? (int32_t)(dim * nd++) : -1;
    w.mem.nd = nd * (size_t)dim;
    size_t budget = max_newton;
#if !defined(__STDC_NO_THREADS__)
    if (pk_par_threads(c->par) >= 2 && fn > target) {
        pk_hybrid_plan plan = {STALL_FACTORS, FIRE_AFTER, HANDOVER * f0 > target ? HANDOVER * f0 : 0,
                               CRAWL};
        rc = pk_hybrid_speculative(&sy, &w, &c2, x, phi, f0, target, &budget, &plan, st, ns);
        goto out;
    }
#endif
    memcpy(w.x0, x, 3 * np * sizeof *x);
    rc = pk_hybrid_newton_phase(&sy, &w, x, &phi, &fn, target, STALL_FACTORS, 0, &budget, ns, st);
    if (rc == 1) { /* cancelled */
        st->f0 = f0;
        st->f = fn;
        rc = 0;
        goto out;
    }
    if (rc != 0)
        goto out;
    if (ns->exit == PK_NEWTON_CONVERGED) {
        st->f0 = f0;
        st->f = fn;
        st->stop = fn <= prm->tol * f0 ? PK_DR_CONVERGED : PK_DR_CONVERGED_ABS;
        goto out;
    }
    /* Newton left its region: the step crosses instabilities (contacts
     * open and close, grains rearrange — a plastic event).  DR takes the
     * step from its start point, as if Newton had not been asked, through
     * the rearrangement (the path is set by the fast modes); at residuals
     * HANDOVER·|f⁰|, HANDOVER_STEP× that, … Newton tries to finish the slow
     * tail near the new minimum from a copy of DR's point.  After FIRE_AFTER
     * failed attempts FIRE (homog_fire.h) goes on from DR's point, with the
     * further attempts from its points: in that tail DR spends most of its
     * iterations (near-jamming 10⁴ RVE: 23,000 of 27,500) and FIRE needs
     * ~15x fewer.  FIRE from the start is faster still, but on the dense 10⁴
     * RVE it lands in another minimum of HIGHER energy (ΔΦ/Φ = +4e-5). */
    memcpy(x, w.x0, 3 * np * sizeof *x);
    attempt_ctx a = {sy, &w, target, &budget, ns, st, FIRE_AFTER, 0};
    a.sy.c = &c2;
    pk_dr_hook hook = {.fn = newton_attempt, .ctx = &a,
                       .at = HANDOVER * f0 > target ? HANDOVER * f0 : 0, .crawl = CRAWL};
    pk_dr_stats st_dr;
    int in_fire = 0;
    rc = pk_hybrid_relax_then_fire(c, g, x, r, np, E, is_free, prm, target, &hook, &a.fire_after, &in_fire,
                         mon, st, &st_dr, ns);
    /* an attempt's point may be beyond DR's candidate list: the caller evaluates c at x */
    if (rc == 0 && pk_dem_pairs_stale(c, x, dim))
        rc = pk_dem_pairs_build(c, g, x, r, np, prm->skin);
out:
    pk_dem_pairs_free(&c2);
    work_free(&w);
    return rc;
}
