/* homog_fire.h — FIRE relaxation of the free particles (Bitzek, Koskinen,
 * Gähler, Moseler, Gumbsch, PRL 97, 170201 (2006); with the semi-implicit
 * Euler step, the mixing after the velocity update and the half step back
 * on P <= 0 of FIRE 2.0, Guénolé et al., Comput. Mater. Sci. 175, 109584
 * (2020)).  Not in the thesis: the inner relaxation of the Newton hybrid
 * (homog_newton.h) between its Newton attempts — the thesis's DR
 * (homog_relax.h) is unchanged and remains the `dr` solver.
 * M = 1; Δt_max = dt_scale · 2/√λ_max (λ_max: the Gershgorin bound over the
 * free DOFs that DR's Δt (4.47) is dominated by; λ_min/λ_max ~ 1e-5 at 10⁴
 * grains does not change it): the stability bound of the stiffest mode.
 * Bitzek's Δt_max ~ 10 Δt_MD assumes an MD step well below that bound; DR's
 * is already at it (dt_scale 1.4 and 2: 5–20× more iterations, blow-ups and
 * restarts).  Δt starts at Δt_max/2.  Same contract
 * as pk_homog_relax_hooked: convergence |f| <= max(tol·|f⁰|, abs_floor),
 * cap max_iter, the hook called when |f| <= hook->at (results 0, 1, 2 and
 * errors as there).  In st: dt the last Δt, γ = 0, λ_max, refreshes = the
 * restarts (uphill steps: v = 0, Δt × f_dec, α = α_start). */
#ifndef PK_HOMOG_FIRE_H
#define PK_HOMOG_FIRE_H

#include "homog_relax.h"

typedef struct pk_fire_params {
    size_t n_min;    /* uphill-free steps before Δt grows (5) */
    double f_inc;    /* Δt growth (1.1) */
    double f_dec;    /* Δt cut on an uphill step (0.5) */
    double alpha0;   /* mixing at (re)start (0.1) */
    double f_alpha;  /* mixing decay (0.99) */
    double dt_scale; /* Δt_max / (2/√λ_max) */
} pk_fire_params;

/* The standard parameters of Bitzek et al. and the measured dt_scale. */
pk_fire_params pk_fire_params_default(void);

int pk_homog_fire_hooked(const pk_dem_system *s, double *x, const pk_dr_params *prm,
                         const pk_fire_params *fp, pk_dr_hook *hook, pk_monitor *mon,
                         pk_dr_stats *st);

#endif
