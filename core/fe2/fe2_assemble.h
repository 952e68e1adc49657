/* fe2_assemble.h — the parts of the macro solver shared by the residual
 * (fe2_assemble.c) and the Newton step (fe2_newton.c); private to core/fe2.
 *
 * One evaluation round: F̄ = 1 + ∇₀u at every Gauss point, the material's
 * trial eval there (in parallel over pb->par, each point writing only its
 * own slot), then f_int and K assembled serially in element order from the
 * slots — so the sums run in one order whatever the pool size. */
#ifndef PK_FE2_ASSEMBLE_H
#define PK_FE2_ASSEMBLE_H

#include <signal.h>

#include "fe2_solver.h"

#define FE2_WHY PK_FE2_WHY

/* Per-Gauss-point geometry (constant) and the slots of the last round. */
typedef struct fe2_gp_buf {
    size_t ngp;
    size_t *elem;          /* [ngp] element of g */
    double *dN, *w;        /* [ngp][8] ∂N_a/∂X_J, [ngp] weight·det J */
    double *F, *P, *A;     /* [ngp][4], [ngp][4], [ngp][16] */
    pk_fe2_gp_info *info;  /* [ngp] */
    int *rc;               /* [ngp] the eval's return (0 ok) */
    char (*why)[FE2_WHY];  /* [ngp] its reason */
    pk_fe2_gp_result *res; /* [ngp] the other evaluators' results (pb->dist only) */
} fe2_gp_buf;

int fe2_gp_buf_init(fe2_gp_buf *b, const pk_fe2_mesh *m); /* 0 / −1 */
void fe2_gp_buf_free(fe2_gp_buf *b);

/* The round's outcome. */
enum { FE2_ROUND_OK = 0, FE2_ROUND_FAILED = 1, FE2_ROUND_CANCELLED = 2, FE2_ROUND_LOST = 3 };

/* Evaluate every Gauss point at u (pb->dist: this process's block, the
 * others' results fetched).  FAILED names the first failing point (lowest
 * g) and its reason in why; CANCELLED when *cancel was set; LOST when an
 * evaluator of pb->dist was lost (why says which). */
int fe2_eval_round(const pk_fe2_problem *pb, const double *u, fe2_gp_buf *b,
                   volatile sig_atomic_t *cancel, char *why, size_t whylen);

/* f_int = ∫ P̄·∇₀N dV from the round's P̄ into fint [2·nnode]. */
void fe2_internal_force(const pk_fe2_problem *pb, const fe2_gp_buf *b, double *fint);

/* K = ∫ ∇₀N·Ā·∇₀N dV from the round's Ā (symmetrised, see fe2_solver.h)
 * into K (upper triangle; K->nnz reset), rows mapped by map[dof] (−1:
 * dropped; NULL: every dof, n = 2·nnode).  0 / −1 (memory). */
int fe2_stiffness(const pk_fe2_problem *pb, const fe2_gp_buf *b, const int32_t *map, size_t n,
                  pk_sparse_sym *K);

#endif
