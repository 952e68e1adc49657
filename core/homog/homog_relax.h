/* homog_relax.h — dynamic relaxation of the free particles (Meier 2009 §4.4,
 * (4.37)–(4.49)): M(ẍ + γẋ) = f with M = 1, central differences (4.38)–(4.41),
 * optimal Δt and γ from the extreme eigenvalues of the jammed free stiffness
 * (4.47).  Convergence: |f| <= max(tol·|f⁰|, abs_floor) (4.42 with an
 * absolute floor, spec H5), capped at max_iter.  The eigenvalue estimates are
 * taken at the start (Gershgorin + Lanczos, homog_eigen.h) and refreshed
 * every `refresh` iterations (Gershgorin again, Rayleigh quotient of the
 * residual for λ_min; rattlers re-detected) — spec H4. */
#ifndef PK_HOMOG_RELAX_H
#define PK_HOMOG_RELAX_H

#include <stddef.h>
#include <stdint.h>

#include "core/dem/dem_friction.h"
#include "core/base/progress.h"
#include "homog_system.h"

typedef enum pk_dr_stop {
    PK_DR_CONVERGED = 0, /* relative tolerance met */
    PK_DR_CONVERGED_ABS, /* absolute floor met (incl. nothing to relax) */
    PK_DR_NOT_NEEDED,    /* no free particle (Taylor) */
    PK_DR_MAX_ITER,
    PK_DR_CANCELLED,
    PK_DR_WALL_TIME,
    PK_DR_HANDED_OVER /* a hook stopped the relaxation to go on otherwise (internal) */
} pk_dr_stop;

const char *pk_dr_stop_name(pk_dr_stop s);
/* 1 for the two converged reasons and not_needed */
int pk_dr_stop_ok(pk_dr_stop s);

typedef struct pk_dr_params {
    double tol;       /* relative, (4.42); thesis 1e-8 */
    double abs_floor; /* absolute force floor */
    size_t max_iter;
    int lanczos_steps;    /* for the initial λ_min (e.g. 40) */
    size_t refresh;       /* iterations between estimate refreshes (e.g. 200) */
    double skin;          /* Verlet skin (length) */
    int plain_lambda_min; /* 1: λ_min without the Rayleigh quotient of DR's own
                           * increments (homog_relax.c, estimate; tests, bench) */
} pk_dr_params;

typedef struct pk_dr_stats {
    pk_dr_stop stop;
    size_t iterations, rebuilds, refreshes;
    double f0, f;     /* |f⁰|, final |f| (free DOFs) */
    double dt, gamma; /* last parameters used */
    double lambda_min, lambda_max;
    int clamped;     /* λ_min <= 0 was clamped (indefinite or no jammed grain) */
    size_t rattlers; /* at the last refresh */
} pk_dr_stats;

/* Relax x (the entries of particles with s->is_free[i]) at fixed geometry
 * s->g.  The pair list s->c is (re)built here as needed.  Returns 0 (see
 * st->stop), -1 on allocation failure, -2 when a periodic box is too small
 * for F̄. */
int pk_homog_relax(const pk_dem_system *s, double *x, const pk_dr_params *prm, pk_monitor *mon,
                   pk_dr_stats *st);

/* A hook into a frictionless relaxation (the Newton/DR hybrid,
 * homog_newton.h): called after an iteration whose residual |f| is <= at,
 * with the current x and *fres = |f|.  It returns 0 to let DR go on (x
 * untouched, it sets the next threshold *at), 1 when it has solved the step
 * from x (x and *fres replaced: DR stops as converged), 2 to stop DR at x
 * (stop PK_DR_HANDED_OVER: the caller goes on from there), < 0 on an error
 * (DR returns it).  It must not touch the pair list DR works on. */
typedef struct pk_dr_hook {
    int (*fn)(void *ctx, double *x, double *fres, double *at);
    void *ctx;
    double at;
    /* crawl > 0: after a first call the hook is also called when `crawl`
     * iterations have passed since the last call with |f| neither reaching
     * `at` nor rising above its value at that call — the relaxation creeps
     * (no rearrangement under way, no progress either).  0: never. */
    size_t crawl;
    /* poll (may be NULL): asked after every iteration; nonzero stops the
     * relaxation at once (stop PK_DR_HANDED_OVER, x as it is) — the hook's
     * owner has solved the step elsewhere (homog_speculative.c: the
     * attempts on a second thread).  It must be cheap. */
    int (*poll)(void *ctx);
    /* the relaxation's book-keeping (zero at the start) */
    size_t last;                /* iteration of the last call (counted from 1; 0: not called yet) */
    double f_last;              /* |f| at the last call */
    double f_peak;              /* the largest |f| since */
    const pk_dr_stats *running; /* during a call: the relaxation's statistics so far */
} pk_dr_hook;

/* st of a relaxation whose hook solved the step with residual fres (the
 * hook returned 1): the residual and the stop it then ends with. */
void pk_relax_hook_solved(pk_dr_stats *st, const pk_dr_params *prm, double fres);

/* The start of a relaxation, shared by DR and FIRE: st cleared, the pair
 * list built at x (returns its rc), *nfree the number of free grains. */
int pk_relax_begin(const pk_dem_system *s, const double *x, const pk_dr_params *prm,
                   pk_dr_stats *st, size_t *nfree);

/* After the first residual st->f0, shared by DR and FIRE: *target = the
 * residual to reach (tol·|f⁰|, at least abs_floor); returns 1 with st->stop
 * set when there is nothing to do (nothing_moves: PK_DR_NOT_NEEDED; |f⁰| at
 * most abs_floor: PK_DR_CONVERGED_ABS), else 0. */
int pk_relax_settled(pk_dr_stats *st, const pk_dr_params *prm, int nothing_moves, double *target);

/* The move of one relaxation iteration, shared by DR (4.39)–(4.41) and
 * FIRE's mixing step: v ← cv·v + cf·f, x ← x + Δt·v on the free grains.
 * Returns 1 when a grain moved beyond half the pair list's skin since it was
 * built (the list must be rebuilt), else 0. */
typedef struct pk_relax_coef {
    double dt, cv, cf;
} pk_relax_coef;
int pk_relax_move(double *x, double *v, const double *f, const uint8_t *is_free, size_t np, int dim,
                  pk_relax_coef cf, const pk_dem_pairs *c);
/* The same move, and acc[0] += v·v, acc[1] += v·f with the new v (each
 * axis summed apart, then the axes in order: the same bits in the SSE2 and
 * the generic loop); acc NULL: pk_relax_move. */
int pk_relax_move_acc(double *x, double *v, const double *f, const uint8_t *is_free, size_t np,
                      int dim, pk_relax_coef cf, const pk_dem_pairs *c, double acc[2]);
/* 1: pk_relax_move takes its generic loop in 2D too (tests: the SSE2 move
 * must give the same bits). */
extern int pk_relax_scalar_move;

/* The pair geometry of a relaxation whose iterations evaluate the forces
 * alone (pk_dem_eval_forces, after which fresh = 0): pk_relax_geom_refresh
 * puts the geometry (l, |l|, ε) of x back when fresh = 0 (pk_dem_eval
 * without outputs: the same bits as if it had been stored) — before its
 * readers (rattlers, Gershgorin, Lanczos, the caller's stress and
 * stiffness), before a hook (the pair data are then those of DR's last
 * evaluation, whatever x the hook returns) and on return. */
typedef struct pk_relax_geom {
    const pk_dem_system *s;
    int fresh;
} pk_relax_geom;
void pk_relax_geom_refresh(pk_relax_geom *gm, const double *x);

/* The end of one relaxation iteration, shared by DR and FIRE (homog_fire.h),
 * with st->f the residual after it: converged at target, the hook (if any;
 * the pair geometry gm refreshed at x before it, gm may be NULL), the
 * iteration cap, and every 64th iteration (k & 63 == 63) the monitor.
 * Returns 0 to go on, 1 to stop (st->stop set, x maybe replaced by the
 * hook's), < 0 the hook's error. */
int pk_relax_iteration_end(pk_dr_stats *st, const pk_dr_params *prm, double target, size_t k,
                           double *x, pk_dr_hook *hook, pk_monitor *mon, pk_progress *pr,
                           pk_relax_geom *gm);

/* pk_homog_relax with a hook (hook->at: the first threshold). */
int pk_homog_relax_hooked(const pk_dem_system *s, double *x, const pk_dr_params *prm,
                          pk_dr_hook *hook, pk_monitor *mon, pk_dr_stats *st);

/* The same with inter-particle friction (2D, dem_friction.h): relaxes the
 * free centres and EVERY rotation u_i = r_i θ_i (Remark 7.3: all grains
 * rotate freely, Taylor included), starting from and reading only the
 * committed state in fc.  u [np] in/out.  The residual is the norm of the
 * free forces and all couples m_i/r_i (7.24).  λ_max adds the tangential
 * row sums; λ_min is the smaller of the normal Lanczos estimate and a
 * finite-difference Rayleigh quotient of the residual through the full
 * (frictional) force.  An inactive law (tan ρ = h = 0) carries no tangential
 * force and leaves the frictionless iteration unchanged.  tot (may be NULL)
 * gets the tangential totals at the final state. */
int pk_homog_relax_fric(const pk_dem_system *s, double *x, const pk_dr_params *prm, pk_fric_ctx *fc,
                        double *u, pk_monitor *mon, pk_dr_stats *st, pk_fric_totals *tot);

#endif
