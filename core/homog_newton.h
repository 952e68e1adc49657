/* homog_newton.h — Newton–Raphson equilibrium of the free particles with the
 * stiffness the tangent needs anyway (issue 6; not in the thesis, which uses
 * dynamic relaxation only).  Per iteration: rattlers detected, the jammed free
 * stiffness K (4.11)–(4.14) factorised by the injected sparse solver, step
 * Δx = K⁻¹f, backtracking line search on the potential Φ_n (Armijo) with the
 * contact set re-evaluated at every trial point.  Falls back to dynamic
 * relaxation (same convergence target) when the block is singular or
 * indefinite, the line search fails, the residual stalls (contacts switching
 * on and off make the problem non-smooth) or the cap is reached, and polishes the
 * rattlers (which carry no stiffness) by DR. */
#ifndef PK_HOMOG_NEWTON_H
#define PK_HOMOG_NEWTON_H

#include "homog_relax.h"
#include "sparse.h"

typedef enum pk_newton_exit {
    PK_NEWTON_CONVERGED = 0,     /* no DR needed */
    PK_NEWTON_RATTLER_POLISH,    /* jammed set converged, DR finished the rattlers */
    PK_NEWTON_BLOCK_NOT_PD,      /* singular / indefinite block → DR */
    PK_NEWTON_LINE_SEARCH,       /* no descent → DR */
    PK_NEWTON_CAP,               /* iteration cap → DR */
    PK_NEWTON_STALLED            /* residual not halved in 4 steps (contact chatter) → DR */
} pk_newton_exit;

const char *pk_newton_exit_name(pk_newton_exit e);

typedef struct pk_newton_stats {
    size_t iterations, cuts;     /* Newton steps, line-search halvings */
    pk_newton_exit exit;
} pk_newton_stats;

/* Same contract as pk_homog_relax (st describes the DR part, if any, with
 * st->f0 the initial residual of the whole solve). */
int pk_homog_newton(pk_dem_pairs *c, const pk_dem_geom *g, double *x, const double *r, size_t np,
                    double E, const uint8_t *is_free, const pk_dr_params *prm,
                    const pk_sparse_solver *solver, size_t max_newton, pk_monitor *mon,
                    pk_dr_stats *st, pk_newton_stats *ns);

#endif
