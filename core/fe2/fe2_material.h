/* fe2_material.h — the material law at the Gauss points of an FE² problem:
 * F̄ → P̄ and the consistent tangent Ā = dP̄/dF̄ (Meier 2009 (6.1)–(6.20)).
 *
 * Plane strain, per unit thickness: F̄, P̄ are 2×2, stored as 4-vectors in
 * the order (11, 12, 21, 22); Ā is 4×4 with A[I·4 + J] = ∂P̄_I/∂F̄_J in that
 * order (docs/result-format.md).  F̄₃₃ = 1.
 *
 * History (Remark 4.4): eval is a trial — it starts from the state committed
 * for Gauss point g and never changes it; commit(g) makes g's last trial the
 * committed state.  eval of distinct g may run concurrently on different
 * threads and must give the same bits whichever thread runs it. */
#ifndef PK_FE2_MATERIAL_H
#define PK_FE2_MATERIAL_H

#include <stddef.h>

/* What one Gauss-point evaluation reports (summaries, progress, the audit). */
typedef struct pk_fe2_gp_info {
    double energy;       /* Φ̄ (energy density of the RVE), 0 if n/a */
    double coordination; /* contacts per grain, 0 if n/a */
    size_t rattlers;
    size_t relax_iter; /* iterations of the micro relaxation (DR + Newton factorisations) */
    double seconds;    /* CPU/wall of this evaluation */
} pk_fe2_gp_info;

typedef struct pk_fe2_material {
    const char *name; /* "rve", "linear_elastic", ... */
    void *ctx;
    /* Trial at Gauss point g under F (det F > 0).  0: P and A filled;
     * non-zero: the evaluation failed (micro relaxation not converged,
     * singular RVE, ...), with a short reason in why[0..whylen) — the macro
     * solver then cuts the load step. */
    int (*eval)(void *ctx, size_t g, const double F[4], double P[4], double A[16],
                pk_fe2_gp_info *info, char *why, size_t whylen);
    /* g's last trial becomes its committed state.  0 / −1 (memory). */
    int (*commit)(void *ctx, size_t g);
} pk_fe2_material;

#endif
