/* homog_bc.h — one macroscopic load step of the RVE under F̄ (Meier 2009
 * ch. 4–5): prescribe positions by the boundary condition (4.24)/(4.27)/
 * (4.33), relax the free particles (homog_relax.h), then homogenize.
 *
 * Stress: P̄ = (1/V) Σ_contacts f_ij ⊗ F̄⁻¹l_ij — the partial derivative
 * ∂Φ̄/∂F̄ at fixed fluctuations (5.3)–(5.4), which equals the BC formulas
 * (5.16) (Taylor, exactly), (5.19) (restricted Taylor) and (5.22) (periodic)
 * once the free particles are in equilibrium (the second sum of (5.6)
 * vanishes).  σ̄ = J̄⁻¹P̄F̄ᵗ = (1/v) Σ f_ij ⊗ l_ij (the symmetric full contact
 * sum: (5.20) as printed sums over 𝓑 only and gives half of it;
 * docs/homogenization.md "Stress and energy").  For Taylor and restricted Taylor the
 * reaction form (5.16)/(5.19), (1/V) Σ_{i prescribed} r_i ⊗ X_i, is computed
 * as well; its distance to P̄ measures the relaxation residual.
 *
 * History (Remark 4.4): pk_homog_eval reads the committed state
 * and writes a separate trial state; only pk_homog_commit makes a trial the
 * new history, so a macro Newton driver can evaluate trial F̄ freely. */
#ifndef PK_HOMOG_BC_H
#define PK_HOMOG_BC_H

#include <stddef.h>
#include <stdint.h>

#include "core/dem/dem_friction.h"
#include "homog_newton.h"
#include "homog_relax.h"
#include "homog_rve.h"
#include "core/base/progress.h"

typedef struct pk_homog_state {
    size_t n;
    double F[9]; /* F̄ of this state */
    double *x;   /* [n][3] spatial centres */
    size_t ncontact;
    uint64_t *keys;    /* sorted contact keys (i << 32 | j), i < j */
    double *u;         /* [n] rotations as r_i θ_i (friction; 0 otherwise) */
    pk_fric_hist hist; /* per-contact slip history (friction) */
} pk_homog_state;

typedef struct pk_homog_opts {
    double E_n; /* normal contact stiffness (4.3) */
    /* Pair-specific normal stiffness (E_n,ij of (4.3)) by species: an
     * n_species × n_species symmetric matrix of absolute stiffnesses, row
     * major; NULL = E_n for every pair.  Every RVE species must be < n_species. */
    const double *E_n_species;
    size_t n_species;
    int affine_predictor; /* 1: start free grains from x = F̄ⁿ⁺¹(F̄ⁿ)⁻¹xⁿ (Ξ fixed); 0: thesis */
    pk_dr_params dr;
    /* Equilibrium solver: NULL = dynamic relaxation (the thesis); a sparse
     * solver = Newton–Raphson with DR fallback (homog_newton.h). */
    const pk_sparse_solver *newton;
    pk_sparse_ctx *newton_ctx; /* newton's context over the load path (NULL: none) */
    size_t newton_max_iter;
    /* Inter-particle friction (ch. 7, 2D): NULL = frictionless.  With
     * friction the equilibrium solver is always DR (newton is ignored; the
     * job layer refuses the combination) and rotations are relaxed. */
    const pk_fric_law *friction;
    /* Threads for the parallel sections (core/base/par.h; NULL: serial).  The
     * results are the same bits for any pool: a deployment setting. */
    pk_par *par;
} pk_homog_opts;

/* Give a contact list the RVE's stiffness classes (uniform when
 * o->E_n_species is NULL) and the options' thread pool; call before its
 * first build. */
void pk_homog_pairs_setup(pk_dem_pairs *c, const pk_homog_rve *rve, const pk_homog_opts *o);

typedef struct pk_homog_step {
    double F[9], P[9], sigma[9], sigma_skew[9];
    double P_reaction[9];   /* (5.16)/(5.19); = P for periodic */
    double reaction_defect; /* |P_reaction − P| / max(|P|, tiny) */
    double J;
    double energy;            /* Φ_n (4.7) */
    double energy_density;    /* Φ̄ = Φ_n / V (5.1) */
    double energy_t;          /* Φ_t (7.6), friction */
    double dissipation;       /* Σ Δλ f_n tan ρ of this step (7.13), friction */
    size_t sliding;           /* contacts on the Coulomb limit, friction */
    double sum_force;         /* |Σ_i f_i| (global equilibrium) */
    double free_force;        /* |(f_i)_free| at the final state, recomputed (the audit) */
    double max_overlap_ratio; /* max ε_ij / min(r_i, r_j) (spec H3) */
    size_t contacts, formed, broken, rattlers;
    double coordination; /* 2·contacts / particles */
    pk_dr_stats dr;      /* DR part (all of it without Newton) */
    int used_newton;
    pk_newton_stats newton;
} pk_homog_step;

/* State at F̄ = 1 (x = X) with its contact set.  0 / -1 (memory). */
int pk_homog_state_init(const pk_homog_rve *rve, const pk_homog_opts *o, pk_homog_state *s);
void pk_homog_state_free(pk_homog_state *s);
/* dst := src (allocates as needed).  0 / -1. */
int pk_homog_state_copy(pk_homog_state *dst, const pk_homog_state *src);
/* The committed history becomes the trial state. */
int pk_homog_commit(pk_homog_state *committed, const pk_homog_state *trial);

/* Evaluate F̄ from the committed state into *trial (committed is not
 * touched).  Returns 0 (check out->dr.stop), -1 memory, -2 periodic box too
 * small for this F̄, -3 det F̄ <= 0 or not finite, -4 friction asked in 3D. */
int pk_homog_eval(const pk_homog_rve *rve, const pk_homog_opts *o, const pk_homog_state *committed,
                  const double F[9], pk_homog_state *trial, pk_homog_step *out, pk_monitor *mon);

#endif
