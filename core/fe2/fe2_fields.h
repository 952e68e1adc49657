/* fe2_fields.h — derived fields of a converged FE² state (Meier 2009 §6.4):
 * the Cauchy stress, its von Mises norm and the deformed volume behind the
 * dilatancy Δ = (v/V − 1)·100 %.
 *
 * Plane strain with a 2D RVE: the RVE gives the in-plane stresses only
 * (σ̄₃₃ is not computed), so the von Mises stress is that of the 2×2 Cauchy
 * stress, σ_dev = σ̄ − ½ tr σ̄ 1, σ_mises = √(3/2 σ_dev:σ_dev) — the
 * thesis's formula with the 2×2 deviator (the thesis leaves
 * the choice open). */
#ifndef PK_FE2_FIELDS_H
#define PK_FE2_FIELDS_H

#include "fe2_mesh.h"

/* σ̄ = J̄⁻¹ P̄ F̄ᵀ (2.5), all in the (11, 12, 21, 22) order. */
void pk_fe2_cauchy(const double F[4], const double P[4], double sigma[4]);

/* √(3/2 σ_dev:σ_dev) with the 2×2 deviator (the file's comment); the
 * symmetric part of σ̄ is used. */
double pk_fe2_von_mises(const double sigma[4]);

/* The deformed area Σ_g w_g det J_g det F̄_g of the mesh (per unit
 * thickness), F [ngp][4] the Gauss points' F̄: exact, since det F̄·det J =
 * det ∂x/∂ξ is linear in ξ, η on a Q1 and constant on a triangle. */
double pk_fe2_deformed_volume(const pk_fe2_mesh *m, const double *F);

#endif
