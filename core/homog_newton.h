/* homog_newton.h — equilibrium of the free particles with the stiffness the
 * tangent needs anyway (issue 6; not in the thesis, which uses dynamic
 * relaxation only): a Newton method made robust for contact networks.
 * Per factorisation: rattlers detected, K assembled over every free grain
 * (exact (4.11)–(4.14) between jammed grains, Gauss–Newton E n⊗n on rattler
 * contacts plus a small shift) and factorised by the injected sparse solver
 * (a Levenberg–Marquardt shift when the exact block is indefinite).  With
 * that factor as H₀, L-BFGS steps with an Armijo line search on Φ_n follow:
 * the first is Newton's step, the later ones absorb contacts opening and
 * closing without a new factorisation, which is refreshed when the residual
 * stops halving.  A failed line search on a fresh Newton direction, a
 * residual that does not halve over several factorisations (the step crosses
 * instabilities: near jamming) or the cap hand the step to dynamic
 * relaxation, restarted from the step's start point. */
#ifndef PK_HOMOG_NEWTON_H
#define PK_HOMOG_NEWTON_H

#include "homog_relax.h"
#include "sparse.h"

typedef enum pk_newton_exit {
    PK_NEWTON_CONVERGED = 0,     /* no DR needed */
    PK_NEWTON_BLOCK_NOT_PD,      /* even the Gauss–Newton block is not positive definite → DR */
    PK_NEWTON_LINE_SEARCH,       /* no descent along a fresh Newton direction → DR */
    PK_NEWTON_CAP,               /* iteration cap → DR */
    PK_NEWTON_STALLED            /* residual not halved in 6 factorisations (instabilities) → DR */
} pk_newton_exit;

const char *pk_newton_exit_name(pk_newton_exit e);

typedef struct pk_newton_stats {
    size_t iterations;           /* factorisations of the stiffness */
    size_t steps, cuts;          /* quasi-Newton steps, line-search halvings */
    pk_newton_exit exit;
} pk_newton_stats;

/* Same contract as pk_homog_relax (st describes the DR part, if any, with
 * st->f0 the initial residual of the whole solve). */
int pk_homog_newton(pk_dem_pairs *c, const pk_dem_geom *g, double *x, const double *r, size_t np,
                    double E, const uint8_t *is_free, const pk_dr_params *prm,
                    const pk_sparse_solver *solver, size_t max_newton, pk_monitor *mon,
                    pk_dr_stats *st, pk_newton_stats *ns);

#endif
