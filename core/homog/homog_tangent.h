/* homog_tangent.h — the macroscopic tangent Ā = dP̄/dF̄ (Meier 2009 ch. 6) by
 * static condensation of the jammed stiffness onto F̄.
 *
 * With y_i = x_i for free grains and F̄X_i for prescribed ones, each contact
 * has l_c = x_j^free − x_i^free + F̄·G_c with a constant reference vector G_c
 * (the prescribed positions and, on a periodic RVE, the lattice shift of the
 * minimum image).  With H_c = ∂²φ/∂l∂l = −k_c (4.12):
 *   A_FF = Σ_c H_c ⊗̄ (G_c ⊗ G_c)            — (6.7) for Taylor
 *   B    = ∂²Φ/∂x_free∂F̄ (ndof × dim²)
 *   Ā    = (A_FF − Bᵀ K_II⁻¹ B) / V          — (6.18), (6.19)–(6.20)
 * where K_II is the stiffness of the jammed free grains (rattlers and their
 * contacts removed, (4.35)).  K_II is factorised by the injected sparse
 * solver; singular and indefinite blocks are reported, no tangent then.
 * Index order: Ā[(a·3+b)·9 + c·3+d] = ∂P̄_ab/∂F̄_cd (3D-embedded). */
#ifndef PK_HOMOG_TANGENT_H
#define PK_HOMOG_TANGENT_H

#include "homog_bc.h"
#include "core/base/sparse.h"

typedef struct pk_tangent_info {
    pk_sparse_info block; /* factorisation of K_II (status OK when no free DOF) */
    size_t free_dofs;     /* size of K_II */
    size_t jammed_contacts;
    double seconds;
} pk_tangent_info;

/* Tangent at the (relaxed) state s.  Returns 0 with A filled when the free
 * block is positive definite (or empty); 1 when it is singular or
 * indefinite (A untouched; see info->block); -1 memory / solver failure;
 * -2 periodic box too small for F̄; -3 friction is on (the frictional
 * tangent of the return mapping is not implemented: refused). */
int pk_homog_tangent(const pk_homog_rve *rve, const pk_homog_opts *o, const pk_homog_state *s,
                     const pk_sparse_solver *solver, double A[81], pk_tangent_info *info);

#endif
