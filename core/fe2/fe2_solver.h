/* fe2_solver.h — the macroscopic boundary value problem of FE² (Meier 2009
 * ch. 6): quasi-static equilibrium R(u) = f_int(u) − f_ext = 0 on a 2D
 * plane-strain mesh (fe2_mesh.h) whose Gauss points carry a material
 * (fe2_material.h), solved by Newton–Raphson with the consistent tangent
 *   K = ∫ ∇N ⋅ Ā ⋅ ∇N dV,   f_int = ∫ P̄ ⋅ ∇N dV   (reference configuration)
 * and a line search, load step by load step, cutting a step when a Gauss
 * point fails or the iteration does not converge.
 *
 * Loads are dead loads in the reference configuration: f_ext is a nodal
 * vector the caller assembles (pk_fe2_edge_traction, pk_fe2_body_force);
 * prescribed displacements are values of listed degrees of freedom.  A load
 * step moves both linearly from the last converged values to the step's
 * targets; a cut step does the same in smaller parts.  The material is
 * committed (Remark 4.4) only when a (part of a) step converged.
 *
 * K is assembled from (Ā + Āᵀ)/2 at each Gauss point: the frictionless RVE
 * tangent has major symmetry (Meier (2.13); test_homog_tangent: defect
 * < 1e-12), so this only removes round-off, and the LDLᵀ solver stores one
 * triangle. */
#ifndef PK_FE2_SOLVER_H
#define PK_FE2_SOLVER_H

#include <stddef.h>
#include <stdint.h>

#include "core/base/par.h"
#include "core/base/progress.h"
#include "core/base/sparse.h"
#include "fe2_distribute.h"
#include "fe2_material.h"
#include "fe2_mesh.h"

/* Nodal forces of a traction t (force per reference length, per unit
 * thickness) on the straight edge from node a to node b, added into f
 * [2·nnode].  A pressure p is t = −p·n with n the outward normal. */
void pk_fe2_edge_traction(const pk_fe2_mesh *m, int32_t a, int32_t b, const double t[2], double *f);

/* Nodal forces of a body force b (force per reference volume) added into f. */
void pk_fe2_body_force(const pk_fe2_mesh *m, const double b[2], double *f);

typedef struct pk_fe2_problem {
    const pk_fe2_mesh *mesh;
    const pk_fe2_material *mat;
    size_t nfix;
    const int32_t *fix_dof;         /* [nfix] prescribed degrees of freedom, distinct */
    const pk_sparse_solver *solver; /* factorises K over the free dofs (LDLᵀ) */
    pk_par *par;                    /* Gauss points in parallel (NULL: serial) */
    /* Gauss points shared with other evaluators (NULL: all evaluated here) */
    const pk_fe2_distributor *dist;
} pk_fe2_problem;

typedef struct pk_fe2_newton_opts {
    double rtol;     /* |R_free| / |R_free of iteration 1| below which a step converged */
    double atol;     /* |R_free| below which a step converged regardless */
    int max_iter;    /* Newton iterations per (part of a) step */
    int line_search; /* 1: line search on R·Δu (FEAP's rule) */
    int max_cuts;    /* halvings of a step before the job fails */
} pk_fe2_newton_opts;

/* The converged macro state: displacements, the prescribed values and
 * f_ext reached, and the Gauss-point fields of the last converged state. */
typedef struct pk_fe2_state {
    size_t ndof, ngp;
    double *u;          /* [ndof] */
    double *fext;       /* [ndof] */
    double *fint;       /* [ndof] internal forces; the reactions of a set of
                       prescribed dofs are Σ (fint − fext) over it */
    double *F, *P;      /* [ngp][4] */
    double *A;          /* [ngp][16] */
    pk_fe2_gp_info *gp; /* [ngp] */
    int evaluated;      /* fint, F, P, A, gp belong to u (set by pk_fe2_step; 0
                           after init: the first step evaluates the material at
                           u once, without commit, for its tangent) */
} pk_fe2_state;

/* u = fext = 0, F = 1, not evaluated.  0 / −1. */
int pk_fe2_state_init(pk_fe2_state *s, const pk_fe2_mesh *m);
void pk_fe2_state_free(pk_fe2_state *s);

/* One Newton solve (one converged part of a load step). */
typedef struct pk_fe2_iterations {
    double t0, t1;     /* the part of the step, as fractions of it */
    int n;             /* residual norms recorded (the thesis tables' "iter"
                             column): n − 1 Newton corrections */
    double res[64];    /* relative residual norms |R_free| / abs_res0, res[0] = 1 */
    double abs_res0;   /* |R_free| of iteration 1 */
    double ls_eta[64]; /* line-search factor of the correction after res[k]
                          (1 = full step; ls_eta[0] = 1, the predictor) */
    int converged;
} pk_fe2_iterations;

typedef struct pk_fe2_step_report {
    int converged; /* the whole step */
    int cuts;      /* halvings used */
    size_t nparts; /* parts tried (converged or not), ≤ cap */
    pk_fe2_iterations parts[32];
    double reaction[2]; /* Σ (f_int − f_ext) over the prescribed dofs, by component
                             (the internal forces when no load acts on them) */
    size_t rounds;      /* evaluation rounds (every Gauss point once), line searches included */
    char why[256];      /* the reason a step failed */
} pk_fe2_step_report;

/* Each part starts with the tangent predictor (the last converged state's
 * K and f_int, the prescribed increments Δu_D moved to the right-hand side:
 * K_ff Δu_f = −(f_int − f_ext(t1) + K_fD Δu_D)), so the material's first
 * trial of a part is already near equilibrium; then Newton iterations
 * evaluate the material until the residual converges.
 *
 * Move from the state *s to the targets uD_target [nfix] (values of
 * problem->fix_dof) and fext_target [ndof].  On success *s holds the new
 * converged state and the material is committed; on failure *s and the
 * material keep the last converged part (the report says how far it got).
 * 0 converged, 1 not converged (after max_cuts), 2 cancelled or out of
 * time (mon), −1 memory or solver failure. */
int pk_fe2_step(const pk_fe2_problem *pb, const pk_fe2_newton_opts *o, pk_fe2_state *s,
                const double *uD_target, const double *fext_target, pk_fe2_step_report *rep,
                pk_monitor *mon);

/* The global residual R(u) = f_int(u) − f_ext and, with K non-NULL, the
 * stiffness over all dofs (upper triangle) at the displacement u, from trial
 * evaluations of the material (nothing committed): the macro tangent test
 * compares K with finite differences of R.  K->n is set to 2·nnode and its
 * triplets replaced (K->nnz reset, storage reused).  fext may be NULL
 * (R = f_int).  0, 1 when a Gauss point failed (why says which), −1 memory. */
int pk_fe2_residual(const pk_fe2_problem *pb, const double *u, const double *fext, double *R,
                    pk_sparse_sym *K, char *why, size_t whylen);

/* The evaluator's side of a distributed round (fe2_distribute.h): Gauss
 * points [lo, hi) at u, trials from their committed states, over pb->par
 * (pb->dist unused) into res[0 .. hi − lo).  0, −1 memory. */
int pk_fe2_eval_block(const pk_fe2_problem *pb, const double *u, size_t lo, size_t hi,
                      pk_fe2_gp_result *res, volatile sig_atomic_t *cancel);

/* Commit the last trials of Gauss points [lo, hi).  0, −1 memory. */
int pk_fe2_commit_block(const pk_fe2_problem *pb, size_t lo, size_t hi);

#endif
