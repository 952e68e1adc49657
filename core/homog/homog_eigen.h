/* homog_eigen.h — extreme-eigenvalue estimates of the jammed free stiffness
 * for the optimal dynamic-relaxation parameters (4.47).  The thesis leaves
 * the estimator open (§4.4.2): λ_max from a Gershgorin bound (an upper
 * bound: under-estimating λ_max is the unstable error), λ_min from a short
 * Lanczos run (its smallest Ritz value), later lowered by Rayleigh quotients
 * of the DR residual (pk_homog_rayleigh), which is dominated by the slowest
 * modes once the fast ones have decayed. */
#ifndef PK_HOMOG_EIGEN_H
#define PK_HOMOG_EIGEN_H

#include <stddef.h>
#include <stdint.h>

#include "core/dem/dem_contact.h"

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

/* u·v over the particles with mask[i] != 0 (stride-3 vectors, dim axes). */
double pk_homog_dot_mask(const double *u, const double *v, const uint8_t *mask, size_t np, int dim);

/* pk_homog_dot_mask(u, v, ...) bit for bit, and *uw = u·w from the same pass. */
double pk_homog_dot2_mask(const double *u, const double *v, const double *w, const uint8_t *mask,
                          size_t np, int dim, double *uw);

#endif
