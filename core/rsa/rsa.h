/* rsa.h — random sequential addition (Titscher & Unger §4; spec §2).
 *
 * Grains are placed largest first at uniformly drawn positions; a draw is
 * rejected if the grain comes closer than Δd to a placed grain (surface to
 * surface) or, on a walled axis, closer than Δd/2 to a wall (the draw range
 * is shrunk so this never needs a test: spec §2.1 step 2).  After
 * `max_failed_draws` consecutive rejections of one grain the run stops with
 * what it has placed (Titscher's N^F failure criterion).  When the draws come
 * from the voxels not yet covered (rsa_voxels.h) and none is left, the box is
 * provably full for the next grain: the run stops as PK_STOP_SATURATED.
 * Long runs of equal diameters (monodisperse jobs, discrete size classes) are
 * placed in batches of attempts (rsa_batch.h) with cache-friendly tests; late
 * in such a run the draws come from the space not yet known to be excluded
 * (rsa_region.h). */
#ifndef PK_RSA_H
#define PK_RSA_H

#include <stddef.h>
#include <stdint.h>

#include "core/space/box.h"
#include "core/space/particles.h"
#include "core/base/progress.h"

typedef enum pk_stop_reason {
    PK_STOP_COMPLETE = 0,        /* every grain placed / target reached */
    PK_STOP_MAX_FAILED_DRAWS,    /* N^F consecutive failures for one grain */
    PK_STOP_NO_ROOM,             /* a grain does not fit into the box at all */
    PK_STOP_CANCELLED,           /* cancel flag or callback */
    PK_STOP_WALL_TIME,           /* wall-clock limit */
    PK_STOP_JAMMED,              /* (EDMD) jamming criterion met */
    PK_STOP_STALLED,             /* (EDMD) no progress */
    PK_STOP_ERROR,               /* out of memory or invalid input */
    PK_STOP_SATURATED            /* no free space is left for the next grain */
} pk_stop_reason;

/* Stable machine name ("complete", "max_failed_draws", ...). */
const char *pk_stop_reason_name(pk_stop_reason r);

typedef struct pk_rsa_params {
    double delta_d;              /* minimum surface gap Δd (>= 0) */
    uint64_t max_failed_draws;   /* N^F (e.g. 1e6) */
    uint64_t seed;               /* positions use stream 1 of this seed */
    int plain_draws;             /* 1: uniform draws over the whole range only (the
                                    reference path of the tests); 0: draws from the
                                    voxels not yet covered where that pays (same
                                    statistics, see rsa_voxels.h) */
    int no_batch;                /* 1: runs of equal diameters also go one grain at a
                                    time; 0 (default, with plain_draws = 0): runs of at
                                    least batch_min_run equal grains take the batched
                                    path (rsa_batch.h), bit-identical to plain draws */
    int batch_plain_draws;       /* 1: the batched path draws as plain_draws does all
                                    along (bit-identical to it: the tests' reference);
                                    0 (default): once most draws fail, it draws from the
                                    space not yet known excluded (rsa_region.h; same
                                    statistics, fewer draws, another packing per seed) */
    uint32_t batch_attempts;     /* attempts per batch; 0 = adaptive (tests fix it) */
    uint32_t batch_min_run;      /* 0 = PK_RSA_BATCH_MIN_RUN */
} pk_rsa_params;

typedef struct pk_rsa_stats {
    pk_stop_reason reason;
    size_t placed, requested;
    uint64_t draws;              /* all position draws */
    double seconds;
} pk_rsa_stats;

/* Place grains with the given diameters (sorted descending; species[i] is
 * carried through) into box b.  `out` must be initialised (pk_particles_init,
 * dim = b->dim); grains are appended in placement order.  Returns 0 when the
 * run ended cleanly (whatever the reason; see stats->reason), -1 on bad input
 * or allocation failure. */
int pk_rsa_place(const pk_box *b, const double *diameters, const int32_t *species, size_t n,
                 const pk_rsa_params *prm, pk_monitor *mon, pk_particles *out,
                 pk_rsa_stats *stats);

#endif
