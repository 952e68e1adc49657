/* fe2_rve.h — the granular RVE as the material of FE² (Meier 2009 ch. 6):
 * at every Gauss point a DEM RVE (core/homog) under the point's F̄.
 *
 * F̄ (2×2) is embedded in 3D with F̄₃₃ = 1 (plane strain); eval relaxes the
 * RVE from the Gauss point's committed state into its trial state
 * (pk_homog_eval), audits the result (pk_homog_audit_step), computes the
 * tangent by static condensation (pk_homog_tangent, the injected sparse
 * solver) and returns P̄ and Ā in the (11, 12, 21, 22) order of
 * fe2_material.h; commit makes the trial the history (pk_homog_commit,
 * Remark 4.4).  A relaxation that fails its audit (not converged, escaped
 * grains, ...), a singular or indefinite jammed block, or an F̄ the RVE
 * cannot take are failures with a reason: the macro solver cuts the step.
 *
 * Several RVEs (e.g. packings of different seeds) may be given: Gauss point
 * g uses RVE g mod nrve.  Every Gauss point of one RVE starts from the same
 * state: the RVE relaxed at F̄ = 1 (computed once at init and copied), so a
 * radius-inflated, jammed RVE starts prestressed and with a stiffness.
 *
 * The RVEs are shared read-only; each Gauss point's own relaxation runs
 * serially (opts.par and opts.newton_ctx are cleared), so distinct Gauss
 * points may be evaluated on different threads with the same bits.  Their
 * calls into the sparse solvers (the tangent's, and opts.newton's if set)
 * are serialised by the adapter's lock: CHOLMOD with Debian's serial
 * OpenBLAS is not reentrant. */
#ifndef PK_FE2_RVE_H
#define PK_FE2_RVE_H

#include "core/base/sparse.h"
#include "core/homog/homog_bc.h"
#include "fe2_material.h"

typedef struct pk_fe2_rve {
    size_t nrve, ngp;
    size_t lo, hi;           /* the Gauss points whose states this process holds */
    const pk_homog_rve *rve; /* [nrve], borrowed */
    pk_homog_opts o;         /* the options of every evaluation (serial) */
    const pk_sparse_solver *solver;
    pk_homog_state *committed, *trial; /* [ngp] */
    pk_homog_step *start;              /* [nrve] the relaxation at F̄ = 1 */
    double *P0;                        /* [nrve][4] P̄ of the start state (prestress) */
    void *lock; /* serialises the evaluations' calls into the sparse solvers (fe2_rve.c) */
} pk_fe2_rve;

/* Set up ngp Gauss points over the nrve RVEs rve[] with the options o (its
 * par, if any, runs the start relaxations; the Gauss points' evaluations
 * are serial) and the solver of the tangent.  0, or −1 with err (memory, a
 * start relaxation that fails its audit, cancelled through mon). */
int pk_fe2_rve_init(pk_fe2_rve *m, const pk_homog_rve *rve, size_t nrve, const pk_homog_opts *o,
                    const pk_sparse_solver *solver, size_t ngp, pk_monitor *mon, char *err,
                    size_t errlen);

/* The same holding the states of Gauss points [lo, hi) only (an evaluator
 * of a distributed round, fe2_distribute.h): the others are neither
 * allocated nor evaluated here (eval and commit refuse them). */
int pk_fe2_rve_init_block(pk_fe2_rve *m, const pk_homog_rve *rve, size_t nrve,
                          const pk_homog_opts *o, const pk_sparse_solver *solver, size_t ngp,
                          size_t lo, size_t hi, pk_monitor *mon, char *err, size_t errlen);

void pk_fe2_rve_free(pk_fe2_rve *m);

/* The RVE of Gauss point g (g mod nrve). */
size_t pk_fe2_rve_index(const pk_fe2_rve *m, size_t g);

/* The material over m (borrowed; it must outlive the material). */
pk_fe2_material pk_fe2_rve_material(pk_fe2_rve *m);

#endif
