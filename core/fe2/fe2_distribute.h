/* fe2_distribute.h — an evaluation round shared with other evaluators (the
 * ranks of an MPI job, api/fe2/fe2_mpi.c); core/ never knows how they are
 * reached.
 *
 * The process that runs the macro Newton evaluates the block [lo, hi) of
 * the Gauss points itself (over its pool); every other evaluator holds the
 * committed micro state of its own contiguous block only and evaluates that
 * block when a round starts.  Their results are copied into the caller's
 * slots, and f_int and K are summed in element order as ever: the result is
 * the same bits as one process with one thread (fe2_material.h: an
 * evaluation gives the same bits wherever it runs). */
#ifndef PK_FE2_DISTRIBUTE_H
#define PK_FE2_DISTRIBUTE_H

#include <signal.h>
#include <stddef.h>
#include <stdint.h>

#include "fe2_material.h"

/* The longest reason a Gauss point reports (with its terminating NUL). */
#define PK_FE2_WHY 160

/* One Gauss point's evaluation, as an evaluator sends it back. */
typedef struct pk_fe2_gp_result {
    double P[4], A[16];
    pk_fe2_gp_info info;
    int32_t rc; /* 0 evaluated, 1 failed (why), 2 cancelled */
    char why[PK_FE2_WHY];
} pk_fe2_gp_result;

/* What the distributor's calls return. */
enum { PK_FE2_DIST_OK = 0, PK_FE2_DIST_LOST = -1, PK_FE2_DIST_CANCELLED = 2 };

typedef struct pk_fe2_distributor {
    void *ctx;
    size_t lo, hi; /* the Gauss points this process evaluates */
    /* A round at the displacements u [ndof] starts: the others begin their
     * blocks (before this process evaluates its own).  OK, or LOST with why. */
    int (*round_start)(void *ctx, const double *u, size_t ndof, char *why, size_t whylen);
    /* The others' results into res[g] for every g outside [lo, hi) (res has
     * a slot per Gauss point).  OK; LOST (an evaluator gone: why names it);
     * CANCELLED (the caller's cancel flag or wall time while waiting). */
    int (*round_finish)(void *ctx, pk_fe2_gp_result *res, char *why, size_t whylen);
    /* After a converged part: the others commit their blocks' last trials.
     * OK, or LOST with why (an evaluator out of memory counts as lost). */
    int (*commit)(void *ctx, char *why, size_t whylen);
} pk_fe2_distributor;

#endif
