/* homog_newton.h — Newton–Raphson equilibrium of the free particles with the
 * stiffness the tangent needs anyway (issue 6; not in the thesis, which uses
 * dynamic relaxation only).  Per iteration: rattlers detected, the free
 * stiffness K assembled (exact (4.11)–(4.14) between jammed grains,
 * Gauss–Newton E n⊗n on rattler contacts plus a tiny shift, so rattlers are
 * solved in the same system) and factorised by the injected sparse solver,
 * then a dogleg trust-region step on the potential Φ_n (the contact set may
 * change inside a step).  An indefinite exact block switches to Gauss–Newton;
 * a collapsed trust region, a stalled residual or the iteration cap hand the
 * rest to dynamic relaxation with the same convergence target. */
#ifndef PK_HOMOG_NEWTON_H
#define PK_HOMOG_NEWTON_H

#include "homog_relax.h"
#include "sparse.h"

typedef enum pk_newton_exit {
    PK_NEWTON_CONVERGED = 0,     /* no DR needed */
    PK_NEWTON_BLOCK_NOT_PD,      /* even the Gauss–Newton block is not positive definite → DR */
    PK_NEWTON_TRUST_REGION,      /* trust region collapsed without an acceptable step → DR */
    PK_NEWTON_CAP,               /* iteration cap → DR */
    PK_NEWTON_STALLED            /* residual not halved in 8 steps (contact chatter) → DR */
} pk_newton_exit;

const char *pk_newton_exit_name(pk_newton_exit e);

typedef struct pk_newton_stats {
    size_t iterations, cuts;     /* Newton steps, rejected trust-region trials */
    pk_newton_exit exit;
} pk_newton_stats;

/* Same contract as pk_homog_relax (st describes the DR part, if any, with
 * st->f0 the initial residual of the whole solve). */
int pk_homog_newton(pk_dem_pairs *c, const pk_dem_geom *g, double *x, const double *r, size_t np,
                    double E, const uint8_t *is_free, const pk_dr_params *prm,
                    const pk_sparse_solver *solver, size_t max_newton, pk_monitor *mon,
                    pk_dr_stats *st, pk_newton_stats *ns);

#endif
