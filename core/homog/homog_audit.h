/* homog_audit.h — what every load step of a homogenization must satisfy
 * before its result may be called successful (docs/homogenization.md,
 * "Audit").  Per step:
 *   converged   the relaxation stopped converged (a step that ends at
 *               max_iter is not) with |f| <= its target max(tol·|f⁰|, floor);
 *   balance     the forces on the free grains, recomputed at the final state
 *               by the stress evaluation, within PK_AUDIT_BALANCE_SLACK × the
 *               target (the relaxation's residual is what it says);
 *   contained   every free grain's centre inside its cell: restricted Taylor
 *               — inside the box in the reference frame (F̄⁻¹x ∈ [0, L], the
 *               hull around it is prescribed); periodic — its fluctuation
 *               F̄⁻¹x − X shorter than a cell edge on every axis (a larger one
 *               is a grain flung through the images); Taylor — prescribed;
 *   finite      P̄, σ̄, energies, J̄ and every centre finite;
 *   overlap     max ε_ij / min(r_i, r_j) <= PK_AUDIT_OVERLAP_MAX: at 1 the
 *               centre of the smaller grain reaches the surface of the other;
 *               beyond it the contact normal and the linear law (ε ≪ r, spec
 *               H3) have no meaning. */
#ifndef PK_HOMOG_AUDIT_H
#define PK_HOMOG_AUDIT_H

#include <stddef.h>

#include "homog_bc.h"

#define PK_AUDIT_OVERLAP_MAX 1.0
#define PK_AUDIT_BALANCE_SLACK 2.0

enum {
    PK_AUDIT_NOT_CONVERGED = 1,
    PK_AUDIT_UNBALANCED = 2,
    PK_AUDIT_ESCAPED = 4,
    PK_AUDIT_NOT_FINITE = 8,
    PK_AUDIT_OVERLAP = 16
};

typedef struct pk_homog_audit {
    double target;         /* the relaxation's residual target */
    double residual_ratio; /* final |f| / target (0: nothing to relax) */
    double balance_ratio;  /* recomputed |f_free| / target */
    double escape;         /* largest excursion of a centre beyond its cell, / its radius */
    size_t outside;        /* grains beyond their cell */
    double overlap_ratio;  /* max ε / min(r_i, r_j) */
    unsigned failed;       /* PK_AUDIT_* bits; 0 = passed */
} pk_homog_audit;

/* Audit the step st whose relaxed state is s (its x and F).  Returns a->failed. */
unsigned pk_homog_audit_step(const pk_homog_rve *rve, const pk_homog_opts *o,
                             const pk_homog_state *s, const pk_homog_step *st, pk_homog_audit *a);

/* One sentence saying what failed in a (with its figures) into buf. */
void pk_homog_audit_describe(const pk_homog_audit *a, const pk_homog_step *st, char *buf,
                             size_t len);

#endif
