/* homog_newton.h — equilibrium of the free particles with the stiffness the
 * tangent needs anyway (not in the thesis, which uses dynamic relaxation
 * only): Newton's method where it is fast, dynamic relaxation through
 * plastic events.
 * Newton phase: per factorisation, rattlers detected, K assembled over every
 * free grain (exact (4.11)–(4.14) between jammed grains, Gauss–Newton E n⊗n
 * on rattler contacts plus a small shift) and factorised by the injected
 * sparse solver; with that factor as H₀, L-BFGS steps with an Armijo line
 * search on Φ_n follow (the first is Newton's step, the later ones absorb
 * contacts opening and closing), the factor being refreshed when the
 * residual stops halving.  The phase ends when the exact block is not
 * positive definite (an instability), a fresh Newton direction finds no
 * decrease, or the residual does not halve over one factorisation's steps
 * (over 6 factorisations in an attempt from DR's point, below).
 * Hybrid: after such an exit DR takes the step from its start point, as if
 * Newton had not been asked, and at residuals 1e-3·|f⁰|, 3e-4·|f⁰|, …
 * Newton tries to finish the slow tail near the new minimum from a copy of
 * DR's point (a failed attempt leaves DR untouched), and also when DR creeps
 * (1,000 iterations after a failed attempt without reaching the next
 * threshold nor rising: pk_dr_hook.crawl).  After two failed
 * attempts FIRE (homog_fire.h) relaxes on from DR's point — the slow tail,
 * where DR spends most of its iterations — with the further attempts from
 * FIRE's points (without a successful one the result is FIRE's, at the same
 * tolerance).  Newton only accepts steps that lower Φ_n and converges only
 * where the block it factorised last was positive definite: the end point is
 * a local minimum.  Which one, when the step crosses a plastic event, is
 * path dependent (docs/homogenization.md).
 * The hybrid's steps are pk_hybrid_begin/step/end (homog_hybrid.h);
 * pk_homog_newton_speculative (homog_speculative.h) wraps its step and, with
 * a pool of two threads or more, makes the attempts on a second thread: the
 * same result, bit for bit, as the serial step. */
#ifndef PK_HOMOG_NEWTON_H
#define PK_HOMOG_NEWTON_H

#include "core/base/sparse.h"
#include "homog_relax.h"

typedef enum pk_newton_exit {
    PK_NEWTON_CONVERGED = 0, /* the last Newton phase converged (after DR or not) */
    PK_NEWTON_BLOCK_NOT_PD,  /* exact block not positive definite (instability) → DR */
    PK_NEWTON_LINE_SEARCH,   /* no descent along a fresh Newton direction → DR */
    PK_NEWTON_CAP,           /* factorisation budget spent → DR to the end */
    PK_NEWTON_STALLED        /* residual not halved over the stall count → DR */
} pk_newton_exit;

const char *pk_newton_exit_name(pk_newton_exit e);

typedef struct pk_newton_stats {
    size_t iterations;      /* factorisations of the stiffness */
    size_t reused;          /* of them, those that reused the context's analysis */
    size_t steps, cuts;     /* quasi-Newton steps, line-search halvings */
    size_t attempts;        /* Newton attempts from DR's points */
    size_t shifts;          /* Levenberg–Marquardt shift raises in those attempts */
    size_t fire_iterations; /* of the relaxation's iterations, those FIRE made */
    pk_newton_exit exit;    /* of the last Newton phase */
} pk_newton_stats;

/* The sparse solver a solve factorises with. */
typedef struct pk_newton_opts {
    const pk_sparse_solver *solver;
    /* the solver's context (solver->ctx_new) kept by the caller over the
     * steps of a load path, so that a contact pattern seen before reuses its
     * analysis; NULL: every factorisation analysed afresh (the same numbers) */
    pk_sparse_ctx *sctx;
    size_t max_iter; /* factorisations over all Newton phases */
} pk_newton_opts;

#endif
