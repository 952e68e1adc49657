/* dem_friction.h — inter-particle friction of 2D disks (Meier 2009 ch. 7,
 * Table 7.1): total slip γ by the backward-Euler update (7.5),
 * elastic predictor f_t = E_t(γ − γ_plⁿ) and closed-form return map (7.16),
 * (7.17) on the Coulomb limit |f_t| ≤ f_n tan ρ + hα (7.11), with the erratum
 * of (7.12) (γ̇_pl = λ sgn, no E_t).  Forces and couples are the EXACT
 * derivatives of the incremental potential through γ (7.5):
 * f_i = −f_t [c_t t − (Δu_i + Δu_j)/(r_i + r_j) n]  ((7.19) plus the central
 * term from |l| in the rotation part, which (7.19) drops by holding s fixed),
 * c_t = |lⁿ|/|lⁿ⁺¹| tⁿ·tⁿ⁺¹ (7.20), and m_i = −f_t s r_i on both grains,
 * s = |l|/(r_i + r_j) ((7.21) with its s).  DEVIATION from the thesis'
 * algorithmic couple (7.23) m = −c_t f_t r_i: that couple makes the force
 * field non-conservative, and dynamic relaxation then locked into limit
 * cycles on our test RVEs; the exact derivative keeps the stick problem a
 * minimisation.  The two differ by O(ε/r) and O(load step).
 *
 * Rotations enter as the length-valued DOF u_i = r_i θ_i (counter-clockwise
 * positive, t = Ω n with Ω the +90° rotation); the generalized force
 * conjugate to u_i is m_i / r_i.
 *
 * History: every evaluation starts from the COMMITTED state (xⁿ, uⁿ, Fⁿ and
 * the per-contact γⁿ, γ_plⁿ, αⁿ keyed by the pair), so a trial F̄ never
 * overwrites it; pk_fric_hist_collect builds the trial history that
 * pk_homog_commit later makes the new one.  A contact that breaks loses γ and
 * γ_pl; α is kept for the pair (Table 7.1, step 3).  A new contact starts from
 * γⁿ = 0 with lⁿ from the committed positions (Table 7.1 as printed).
 * sgn(0) := +1.  2D only (the thesis' ch. 7 is 2D). */
#ifndef PK_DEM_FRICTION_H
#define PK_DEM_FRICTION_H

#include <stddef.h>
#include <stdint.h>

#include "dem_contact.h"

typedef struct pk_fric_law {
    double E_t;     /* tangential stiffness (> 0), thesis E_t = ϑ E_n */
    double tan_rho; /* friction coefficient tan ρ (>= 0) */
    double h;       /* hardening modulus of the friction limit (>= 0) */
} pk_fric_law;

/* 1 when the law can carry a tangential force (tan ρ > 0 or h > 0). */
int pk_fric_law_active(const pk_fric_law *law);

/* Table 7.1 for one contact: in γ (from 7.5), γ_plⁿ, αⁿ, f_n; out the
 * corrected γ_pl, α, the signed f_t = E_t γ_el, Δλ >= 0; returns 1 on slip. */
typedef struct pk_fric_point {
    double gamma_pl, alpha, ft, dlambda;
} pk_fric_point;
int pk_fric_return_map(const pk_fric_law *law, double fn, double gamma, double gamma_pl_n,
                       double alpha_n, pk_fric_point *out);

/* Per-contact history, sorted by key (i << 32 | j, i < j). */
typedef struct pk_fric_hist {
    size_t n, cap;
    uint64_t *key;
    double *gamma, *gamma_pl, *alpha;
} pk_fric_hist;

void pk_fric_hist_free(pk_fric_hist *h);
int pk_fric_hist_copy(pk_fric_hist *dst, const pk_fric_hist *src);
/* index of key or -1 */
long pk_fric_hist_find(const pk_fric_hist *h, uint64_t key);

/* Per-pair results of the last pk_dem_fric_eval (indexed like the pairs). */
typedef struct pk_fric_pairs {
    size_t cap;
    double *gamma, *gamma_pl, *alpha, *ft, *dlambda, *keff, *ct;
} pk_fric_pairs;
void pk_fric_pairs_free(pk_fric_pairs *w);

typedef struct pk_fric_ctx {
    const pk_fric_law *law;
    pk_dem_geom g_n;            /* geometry at the committed F̄ⁿ */
    const double *x_n, *u_n;    /* committed centres, committed r_i θ_i */
    const pk_fric_hist *hist_n; /* committed history */
    pk_fric_pairs w;            /* per-pair scratch / results */
} pk_fric_ctx;

typedef struct pk_fric_totals {
    double energy;      /* Φ_t (7.6) summed over contacts */
    double dissipation; /* Σ Δλ f_n tan ρ (7.13, one step) */
    size_t sliding;     /* contacts on the yield surface */
} pk_fric_totals;

/* Tangential part at (x, u).  Call after pk_dem_eval on the same c and x
 * (it reads c->l, len, eps).  Adds to f (may be NULL) the forces (7.19),
 * overwrites gu (may be NULL, [np]) with the couples m_i / r_i (7.23), adds
 * Σ f_t ⊗ l to S (may be NULL).  -1 on allocation failure. */
int pk_dem_fric_eval(const pk_dem_pairs *c, pk_fric_ctx *fc, const double *x, const double *u,
                     const double *r, size_t np, double E_n, double *f, double *gu, double S[9],
                     pk_fric_totals *tot);

/* Gershgorin-type bound of the tangential stiffness' row sums (translations
 * of free grains and all rotations), from the last pk_dem_fric_eval. */
double pk_dem_fric_gershgorin(const pk_dem_pairs *c, const pk_fric_ctx *fc, size_t np);

/* The trial history after pk_dem_fric_eval: contacts with their γ, γ_pl, α;
 * pairs of the committed history that are no longer in contact keep α only
 * (when α > 0).  -1 on allocation failure. */
int pk_fric_hist_collect(const pk_dem_pairs *c, const pk_fric_ctx *fc, pk_fric_hist *out);

#endif
