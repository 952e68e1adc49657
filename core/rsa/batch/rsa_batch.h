/* rsa_batch.h — batched space-time RSA for a run of equal grains (internal to core/rsa/rsa.c).
 *
 * RSA is a deterministic function of its attempt sequence: attempt t (a
 * uniform point of the draw range) is accepted iff it overlaps no grain
 * accepted before it.  For a run of grains of one size the attempts are taken
 * B at a time:
 *   1. draw the B points in attempt order from the same stream, with the same
 *      arithmetic, as the one-at-a-time loop of rsa.c (plain draws);
 *   2. test them against the grains accepted before the batch — a read-only
 *      dense cell store (rsa_cells.h) — in cell order, so neighbouring tests
 *      share cache lines, and per attempt the neighbour cells on the near side
 *      of its cell first; the order is free because the store does not change;
 *   3. walk the survivors of 2 in attempt order (a bitmap over the batch; the
 *      attempts in between are failures): a survivor is accepted iff no
 *      survivor accepted earlier in this batch (small hash of cells) and no
 *      grain placed before the run (pk_grid) is within contact; failures since
 *      the last acceptance count towards N^F exactly as one at a time; the
 *      walk stops at the acceptance that completes the run (or the N^F-th
 *      failure), and the rng is rewound to just after that attempt;
 *   4. add the batch's accepted grains to the store.
 * With pk_rsa_params.batch_plain_draws the outcome — positions, order, draw
 * count, rng state, stop reason except for cancellation timing — is bit for
 * bit that of plain draws one at a time (tests/unit/test_rsa_batch.c compares
 * them with memcmp).  By default, once a batch accepts fewer than a fifth of
 * its draws, step 1 draws from the space not yet known to be excluded
 * (rsa_region.h): attempts landing in a marked fine voxel fail at once and
 * never reach step 2, accepted grains mark their exclusion balls in step 4.
 * Same law of the packing (uniform over the open space at every acceptance;
 * tests/unit/test_rsa_region.c checks it statistically), far fewer draws,
 * but another packing per seed than plain draws; the same seed still gives
 * the same packing, and the rng is not rewound after such a batch. */
#ifndef PK_RSA_BATCH_H
#define PK_RSA_BATCH_H

#include "core/space/grid.h"
#include "core/base/rng.h"
#include "core/rsa/rsa.h"

/* Runs of equal diameters at least this long take the batched path (unless
 * pk_rsa_params.batch_min_run says otherwise). */
#define PK_RSA_BATCH_MIN_RUN 512

/* 1 if the batched path can serve grains of radius r with this draw range
 * (lo, span per axis) for a run of m grains; decided without drawing. */
int pk_rsa_batch_usable(const pk_box *b, double r, double gap, const double *lo,
                        const double *span, size_t m);

/* Place up to m grains of radius r (species[0..m)) with draws over
 * [lo, lo + span] per axis; grains already in `out` and registered in `grid`
 * are obstacles (the run's grains are appended to `out`, not to the grid).
 * Adds to st->placed and st->draws; *solid grows by the grains' measure.
 * Returns PK_STOP_COMPLETE when all m are placed, else the reason to stop
 * (max_failed_draws, cancelled, wall_time, error). */
pk_stop_reason pk_rsa_batch_run(const pk_box *b, double r, const int32_t *species, size_t m,
                                const double *lo, const double *span, const pk_rsa_params *prm,
                                const pk_grid *grid, pk_rng *rng, pk_monitor *mon,
                                pk_progress *pg, double box_measure, double *solid,
                                pk_particles *out, pk_rsa_stats *st);

#endif
