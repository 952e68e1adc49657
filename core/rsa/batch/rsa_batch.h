/* rsa_batch.h — batched RSA for a run of equal grains: the one entry point of
 * core/rsa/batch/, called from core/rsa/rsa.c.  How it works and why it places
 * exactly as one draw at a time would: core/rsa/batch/README.md. */
#ifndef PK_RSA_BATCH_H
#define PK_RSA_BATCH_H

#include "core/base/rng.h"
#include "core/rsa/rsa.h"
#include "core/space/grid.h"

/* Runs of equal diameters at least this long take the batched path (unless
 * pk_rsa_params.test.batch_min_run says otherwise). */
#define PK_RSA_BATCH_MIN_RUN 512

/* The state of rsa.c's placement loop that a batched run works on. */
typedef struct pk_rsa_batch_env {
    const pk_box *b;
    const pk_rsa_params *prm; /* Δd, N^F, draws, test overrides */
    const pk_grid *grid;      /* the grains placed before the run */
    pk_rng *rng;              /* the position stream, left just after the run's last draw */
    pk_monitor *mon;
    pk_progress *pg;
    double box_measure;
    double *solid;     /* grows by the run's grains' measure */
    pk_particles *out; /* the run's grains are appended (not added to grid) */
    pk_rsa_stats *st;  /* adds to placed and draws */
    /* Called once the run is known to take the batched path, before its first
     * draw: the caller makes grid hold every grain placed so far.  0 or -1. */
    int (*enter)(void *ctx);
    void *ctx;
} pk_rsa_batch_env;

/* Place the run of m grains of radius r (species[0..m)) with draws over
 * [lo, lo + span] per axis.  Returns 0 when the batched path does not serve
 * the run (shorter than the minimum run, or a cell store that would not pay
 * or cannot serve the box): nothing drawn, nothing changed.  Otherwise 1 with
 * *why = PK_STOP_COMPLETE when all m are placed, else the reason to stop
 * (max_failed_draws, saturated, cancelled, wall_time, error). */
int pk_rsa_batch_place(const pk_rsa_batch_env *e, double r, const int32_t *species, size_t m,
                       const double *lo, const double *span, pk_stop_reason *why);

#endif
