/* homog_stiffness.h — the sparse stiffness of the free DOFs (Meier 2009
 * (4.11)–(4.14)) for the tangent's static condensation and the Newton
 * solver: per contact H = ∂²φ/∂l∂l = E/|l| [R n⊗n − ε 1] = −k_ij enters
 * K_ii and K_jj with +H and K_ij with −H. */
#ifndef PK_HOMOG_STIFFNESS_H
#define PK_HOMOG_STIFFNESS_H

#include <stdint.h>

#include "core/dem/dem_contact.h"
#include "core/base/sparse.h"

/* H (3×3 row-major) of a contact with branch vector l, |l| = len, overlap eps. */
void pk_homog_pair_hessian(double E, double len, double eps, const double *l, double H[9]);

/* Add one contact's blocks; di/dj = first DOF of i/j or −1 if not a DOF. 0 / -1. */
int pk_homog_add_pair_K(pk_sparse_sym *K, int dim, int32_t di, int32_t dj, const double H[9]);

#endif
