/* edmd_checkpoint.h — an EDMD run's state as plain arrays, so a long run can
 * be saved periodically and continued after an interruption (daemon restart,
 * killed worker).  Core only copies the state out and back in; the file I/O
 * is api/'s (api/pack/edmd_checkpoint_h5.c).
 *
 * A snapshot is taken at the end of a pressure window right after a re-base
 * (t = 0): every grain's flight (p, a, v, g), the shell, the absolute time,
 * the engine's grain order, the run's counters and φ(t) history.  Neighbour
 * lists and events are not saved: a resumed run rebuilds and re-predicts
 * them from the exact positions and velocities, so it is a valid
 * continuation of the same trajectory (not bit-identical to an uninterrupted
 * run: the stall window and pressure window restart). */
#ifndef PK_EDMD_CHECKPOINT_H
#define PK_EDMD_CHECKPOINT_H

#include <stddef.h>
#include <stdint.h>

#include "edmd.h"

/* scal[] members */
enum {
    PK_EDMD_SNAP_T_BASE,
    PK_EDMD_SNAP_H0,
    PK_EDMD_SNAP_H1,
    PK_EDMD_SNAP_K0,
    PK_EDMD_SNAP_PRESSURE,
    PK_EDMD_SNAP_SKIN_SCALE,
    PK_EDMD_SNAP_MAX_OVERLAP,
    PK_EDMD_SNAP_FRACTION,
    PK_EDMD_SNAP_GROWTH_RATE,
    PK_EDMD_SNAP_NSCAL
};
/* cnt[] members */
enum {
    PK_EDMD_SNAP_EVENTS,
    PK_EDMD_SNAP_PAIR,
    PK_EDMD_SNAP_WALL,
    PK_EDMD_SNAP_NLIST,
    PK_EDMD_SNAP_INVALID,
    PK_EDMD_SNAP_RESCALES,
    PK_EDMD_SNAP_REBASES,
    PK_EDMD_SNAP_OVERLAPS,
    PK_EDMD_SNAP_RESORTS,
    PK_EDMD_SNAP_SECOND,
    PK_EDMD_SNAP_HIST_STRIDE,
    PK_EDMD_SNAP_HIST_COUNT,
    PK_EDMD_SNAP_SLOWED,
    PK_EDMD_SNAP_GROWTH_CHANGES,
    PK_EDMD_SNAP_NCNT
};
#define PK_EDMD_SNAP_KIN 8 /* p[3], a, v[3], g per grain */

typedef struct pk_edmd_snapshot {
    size_t n;
    int dim;
    double *kin;   /* [n][PK_EDMD_SNAP_KIN] in engine order */
    int64_t *perm; /* [n] engine index -> the caller's grain */
    double scal[PK_EDMD_SNAP_NSCAL];
    int64_t cnt[PK_EDMD_SNAP_NCNT];
    size_t nhist;
    double hist[4][PK_EDMD_HIST_MAX]; /* events, time, φ, reduced pressure */
} pk_edmd_snapshot;

/* What a run does with snapshots (pk_edmd_params.checkpoint; NULL = none). */
typedef struct pk_edmd_checkpoint {
    double interval_s; /* wall seconds between snapshots (<= 0: none) */
    /* Called with each snapshot; its return value is only counted (a full
     * disk must not stop the run). */
    int (*save)(const pk_edmd_snapshot *snap, void *ctx);
    void *ctx;
    const pk_edmd_snapshot *resume; /* continue from here (NULL: from the start) */
    /* out */
    int resumed;             /* 1: the run continued from resume */
    uint64_t resumed_events; /* events done before the resume */
    double resumed_time;     /* simulated time reached before it */
    unsigned saved, save_failures;
    /* private */
    double last_s;
} pk_edmd_checkpoint;

int pk_edmd_snapshot_alloc(pk_edmd_snapshot *s, size_t n, int dim); /* 0 or -1 */
void pk_edmd_snapshot_free(pk_edmd_snapshot *s);

/* --- hooks of core/edmd/edmd.c --- */
struct edmd_state;

/* The run's own bookkeeping beside the engine state. */
typedef struct edmd_ckpt_loop {
    double t_base, K0, pressure, fraction;
    uint64_t hist_stride, hist_count;
    double growth_rate; /* the run's current γ (slowed near jamming) */
    int slowed;         /* 1: the jamming slowdown applied; 2: and lifted (jam_full_rate_p) */
} edmd_ckpt_loop;

/* 1 when a snapshot is due (its interval has passed since the last one or
 * the run's start). */
int edmd_checkpoint_due(pk_edmd_checkpoint *c);
/* Copy the state (at t = 0, just re-based) out and hand it to c->save. */
void edmd_checkpoint_take(const struct edmd_state *s, const size_t *perm, const pk_edmd_stats *st,
                          const edmd_ckpt_loop *l, pk_edmd_checkpoint *c);
/* Engine order of the snapshot into perm (a permutation of 0..n-1 is
 * checked): 0, or -1 when it does not fit this run. */
int edmd_checkpoint_perm(const pk_edmd_snapshot *r, size_t n, int dim, size_t *perm);
/* Flights, shell, counters, history and bookkeeping back (after setup). */
void edmd_checkpoint_restore(struct edmd_state *s, pk_edmd_stats *st, edmd_ckpt_loop *l,
                             pk_edmd_checkpoint *c);

#endif
