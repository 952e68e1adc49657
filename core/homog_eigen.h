/* homog_eigen.h — extreme-eigenvalue estimates of the jammed free stiffness
 * for the optimal dynamic-relaxation parameters (4.47).  The thesis leaves
 * the estimator open (spec §2.7.2): λ_max from a Gershgorin bound (an upper
 * bound: under-estimating λ_max is the unstable error), λ_min from a short
 * Lanczos run (its smallest Ritz value), later lowered by Rayleigh quotients
 * of the DR residual (pk_homog_rayleigh), which is dominated by the slowest
 * modes once the fast ones have decayed. */
#ifndef PK_HOMOG_EIGEN_H
#define PK_HOMOG_EIGEN_H

#include <stddef.h>
#include <stdint.h>

#include "dem_contact.h"

/* Smallest Ritz value of K on mask after `steps` Lanczos steps (a
 * deterministic start vector).  Returns NAN on allocation failure, 0 when
 * mask selects nothing. */
double pk_homog_lanczos_min(const pk_dem_pairs *c, int dim, size_t np, double E,
                            const uint8_t *mask, int steps);

/* v·Kv / v·v on mask (NAN if v vanishes there); work: 3·np doubles. */
double pk_homog_rayleigh(const pk_dem_pairs *c, int dim, size_t np, double E, const uint8_t *mask,
                         const double *v, double *work);

/* Smallest eigenvalue of the symmetric tridiagonal (a[0..m), b[0..m-1))
 * by Sturm bisection. */
double pk_tridiag_min_eig(const double *a, const double *b, int m);

/* The Rayleigh quotient of DR's increments Δx = Δt·v (adaptive DR,
 * Underwood 1983; Papadrakakis 1981): K Δx ≈ −(f(x + Δx) − f(x)), summed
 * over a window of increments, λ ≈ Σ −Δx·Δf / Σ Δx·Δx — the stiffness along
 * the modes DR moves in, from three dot products of the update pass.  Late in
 * a relaxation the velocity is made of the slowest modes (the fast ones are
 * damped out): an estimate of λ_min that a short Lanczos run misses by
 * orders of magnitude near jamming (40 steps: 4e-3 where the block's λ_min is
 * ~1e-5 at 10⁴ grains), and one that exists when no grain is jammed. */
typedef struct pk_increment_rq {
    double num, den;                  /* Σ −Δx·Δf, Σ Δx·Δx of the window */
    double pend_vf, pend_vv, pend_dt; /* the last move: v·f before it, v·v, Δt (0: none) */
} pk_increment_rq;

/* After the update of step k (x += Δt·v_new, v_old → v_new at force f_k):
 * d[0] = v_old·f_k, d[1] = v_new·f_k, d[2] = v_new·v_new.  Books step k−1
 * (d[0] is its v·f after the move) and leaves step k pending. */
void pk_increment_rq_add(pk_increment_rq *q, const double d[3], double dt);

/* The quotient of the window (0 when empty), and a fresh window. */
double pk_increment_rq_take(pk_increment_rq *q);

/* u·v over the particles with mask[i] != 0 (stride-3 vectors, dim axes). */
double pk_homog_dot_mask(const double *u, const double *v, const uint8_t *mask, size_t np, int dim);

#endif
