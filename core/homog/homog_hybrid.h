/* homog_hybrid.h — the serial Newton/DR hybrid's step (homog_newton.c) in
 * parts, for the speculative runner that wraps it (homog_speculative.c): the
 * solve's problem and work arrays, its prologue and end, one Newton phase,
 * one attempt from a relaxation's point, and DR-then-FIRE.  Internal to
 * core/homog; homog_newton.c does not know the speculative runner. */
#ifndef PK_HOMOG_HYBRID_H
#define PK_HOMOG_HYBRID_H

#include <stdatomic.h>

#include "homog_newton.h"

/* L-BFGS memory (pairs). */
#define MEMORY 8

/* L-BFGS memory in DOF space: ring of (s, y, 1/s·y). */
typedef struct qn_memory {
    size_t nd, count, head;
    double *s, *y, rho[MEMORY], alpha[MEMORY];
} qn_memory;

typedef struct newton_work {
    double *x0, *f, *ft, *xt, *g, *gt, *d, *qv, *sv, *yv;
    qn_memory mem;
    uint8_t *rat;
    int32_t *dof;
    pk_sparse_sym K;
} newton_work;

/* One solve: the system (its pair list the one this solve's phases use)
 * and how it runs. */
typedef struct newton_run {
    pk_dem_system s;
    const pk_dr_params *prm;
    const pk_sparse_solver *solver;
    pk_sparse_ctx *sctx; /* the solver's context over the load path; NULL: none */
    pk_monitor *mon;
    const atomic_int *abort; /* nonzero: stop as if cancelled (speculative attempts); NULL: none */
} newton_run;

/* The Newton attempts DR (then FIRE) makes along its way (pk_dr_hook):
 * Newton runs on a copy of the relaxation's point with a pair list of its
 * own, so that a failed attempt leaves the point as it was; at the
 * fire_after-th attempt point that is not solved DR stops there (hook
 * result 2) for FIRE to go on. */
typedef struct attempt_ctx {
    newton_run sy; /* sy.s.c = the attempts' own pair list */
    newton_work *w;
    double target;
    size_t *budget;
    pk_newton_stats *ns;
    pk_dr_stats *st;   /* for newton_phase's stop on a cancel (restored) */
    size_t fire_after; /* unsolved attempt points after which DR stops and
                        * FIRE goes on from there; 0: never */
    size_t failed;
} attempt_ctx;

/* One Newton phase from x (w->f, *phi, *fn describe x on entry and on exit);
 * see homog_newton.c.  Returns 0, -1 (memory), -2 (box), 1 (cancelled). */
int pk_hybrid_newton_phase(const newton_run *sy, newton_work *w, double *x, double *phi, double *fn,
                           double target, size_t stall, int shift, size_t *budget,
                           pk_newton_stats *ns, pk_dr_stats *st);

/* The threshold of the next attempt after one at *at. */
void pk_hybrid_next_threshold(double *at, double target);

/* Newton from xn, a copy of a relaxation's point: 1 when it converged (xn
 * the solution, *fres its residual), 0 when not — or not tried, the budget
 * being spent —, < 0 on an error. */
int pk_hybrid_attempt_from(attempt_ctx *a, double *xn, double *fres);

/* The parameters FIRE runs with after DR, and st (DR's statistics) with
 * FIRE's fs after it added. */
pk_dr_params pk_hybrid_fire_params(const pk_dr_params *prm, double target, const pk_dr_stats *st);
void pk_hybrid_fire_merge(pk_dr_stats *st, const pk_dr_stats *fs, const pk_dr_params *prm,
                          pk_newton_stats *ns);

/* DR from x on sy->s with the hook, then FIRE from DR's point when the
 * hook stops DR (hook->fn returned 2; not when hook->poll did): *fire_after
 * = 0 and *in_fire = 1 as FIRE begins, *st_dr = DR's statistics at its end. */
int pk_hybrid_relax_then_fire(const newton_run *sy, double *x, double target, pk_dr_hook *hook,
                              size_t *fire_after, int *in_fire, pk_dr_stats *st, pk_dr_stats *st_dr,
                              pk_newton_stats *ns);

/* How the hybrid makes its attempts: the first phase's stall count, the
 * unsolved attempt points before FIRE, the first threshold, the creep. */
typedef struct pk_hybrid_plan {
    size_t stall_first, fire_after;
    double at;
    size_t crawl;
} pk_hybrid_plan;

/* One step of the hybrid: its problem, work, the attempts' own pair list,
 * and what the prologue found at the start point. */
typedef struct pk_hybrid {
    newton_run sy; /* sy.s.c: the caller's pair list */
    newton_work w;
    pk_dem_pairs c2;         /* the attempts' */
    double phi0, f0, target; /* at the start point (w.f: its forces) */
    size_t budget;           /* factorisations left */
} pk_hybrid;

/* The prologue: ns and st cleared, the pair list built and evaluated at x,
 * the work arrays, the DOF numbering, f⁰ and the target.  0, -1 (memory),
 * -2 (box); pk_hybrid_end is due in every case. */
int pk_hybrid_begin(pk_hybrid *h, const pk_dem_system *s, const double *x, const pk_dr_params *prm,
                    const pk_newton_opts *no, pk_monitor *mon, pk_dr_stats *st,
                    pk_newton_stats *ns);
/* The serial step after the prologue: the Newton phase from x, then DR (and
 * FIRE) with the attempts. */
int pk_hybrid_step(pk_hybrid *h, double *x, pk_dr_stats *st, pk_newton_stats *ns);
void pk_hybrid_end(pk_hybrid *h);
/* The serial step's plan (its constants, its first threshold). */
pk_hybrid_plan pk_hybrid_plan_of(const pk_hybrid *h);

#endif
