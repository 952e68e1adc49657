/* rsa.h — random sequential addition (Titscher & Unger §4).
 *
 * Grains are placed largest first at uniformly drawn positions; a draw is
 * rejected if the grain comes closer than Δd to a placed grain (surface to
 * surface) or, on a walled axis, closer than Δd/2 to a wall (the draw range
 * is shrunk so this never needs a test: Titscher & Unger §4; `wall_gap` NONE
 * keeps Δd between grains only and lets grains touch the walls).  After
 * `max_failed_draws` consecutive rejections of one grain the run stops with
 * what it has placed (Titscher's N^F failure criterion).  When the draws come
 * from the voxels not yet covered (rsa_voxels.h) and none is left, the box is
 * provably full for the next grain: the run stops as PK_STOP_SATURATED.
 * Long runs of equal diameters (monodisperse jobs, discrete size classes) are
 * placed in batches of attempts (batch/rsa_batch.h, batch/README.md). */
#ifndef PK_RSA_H
#define PK_RSA_H

#include <stddef.h>
#include <stdint.h>

#include "core/space/box.h"
#include "core/space/particles.h"
#include "core/base/progress.h"
#include "core/base/stop_reason.h"

/* Where a draw comes from.  Both place each grain uniformly over the space
 * still open to it (the law of Titscher's draw-until-accepted loop); they
 * differ in how many draws a grain costs, hence in what a given N^F reaches,
 * and in the packing a seed gives. */
typedef enum pk_rsa_draws {
    PK_RSA_DRAWS_OPEN = 0, /* "open" (default): late in a run, draws come from the
                                    space not yet known to be excluded (rsa_voxels.h; runs
                                    of equal grains: batch/README.md); a run whose open
                                    space is used up stops as PK_STOP_SATURATED */
    PK_RSA_DRAWS_PLAIN     /* "plain": uniform over the whole draw range all along,
                                    Titscher's loop draw for draw (runs of equal grains
                                    are batched with the same outcome bit for bit) */
} pk_rsa_draws;

/* The clearance kept at walls. */
typedef enum pk_rsa_wall_gap {
    PK_RSA_WALL_GAP_HALF = 0, /* "half" (default): wall clearances >= Δd/2 (Titscher §6.3) */
    PK_RSA_WALL_GAP_NONE      /* "none": Δd between grains only, grains may touch the walls
                                 (Titscher §3/§6.3; EDMD's wall_gap none) */
} pk_rsa_wall_gap;

typedef struct pk_rsa_params {
    double delta_d;            /* minimum surface gap Δd (>= 0) */
    uint64_t max_failed_draws; /* N^F (e.g. 1e6) */
    uint64_t seed;             /* positions use stream 1 of this seed */
    pk_rsa_draws draws;
    pk_rsa_wall_gap wall_gap;
    struct {                     /* test and bench overrides; all 0 in jobs */
        int one_at_a_time;       /* 1: runs of equal grains are not batched either */
        uint32_t batch_attempts; /* attempts per batch; 0 = adaptive */
        uint32_t batch_min_run;  /* shortest run batched; 0 = PK_RSA_BATCH_MIN_RUN */
    } test;
} pk_rsa_params;

typedef struct pk_rsa_stats {
    pk_stop_reason reason;
    size_t placed, requested;
    uint64_t draws; /* all position draws */
    double seconds;
} pk_rsa_stats;

/* Place grains with the given diameters (sorted descending; species[i] is
 * carried through) into box b.  `out` must be initialised (pk_particles_init,
 * dim = b->dim); grains are appended in placement order.  Returns 0 when the
 * run ended cleanly (whatever the reason; see stats->reason), -1 on bad input
 * or allocation failure. */
int pk_rsa_place(const pk_box *b, const double *diameters, const int32_t *species, size_t n,
                 const pk_rsa_params *prm, pk_monitor *mon, pk_particles *out, pk_rsa_stats *stats);

#endif
