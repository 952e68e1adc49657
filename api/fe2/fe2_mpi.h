/* fe2_mpi.h — an fe2 run over the ranks of an MPI launch (api/par/mpi_world.h):
 * the Gauss points in contiguous blocks, one per rank (pk_par_range); each
 * rank holds the committed RVE states of its block only and evaluates it
 * over its own thread pool; rank 0 also runs the macro Newton, assembles in
 * element order and alone writes files (core/fe2/fe2_distribute.h: the
 * result is the same bits as one process with one thread).
 *
 * Rank 0 drives, the others serve (pk_fe2_mpi_serve) until it says stop.
 * A rank that is lost — killed, its node gone — ends the run: rank 0's wait
 * for it ends on an MPI error, on the signal the launcher sends when a rank
 * dies (the cancel flag of packd run) or on the job's wall time, and the job
 * fails naming the ranks it was waiting for, its converged steps kept.
 * The other ranks, signalled too, wait for rank 0 to write that and end the
 * launch (at most 30 s) rather than end it first. */
#ifndef PK_FE2_MPI_H
#define PK_FE2_MPI_H

#include <signal.h>
#include <stddef.h>

#include "core/fe2/fe2_rve.h"
#include "core/fe2/fe2_solver.h"
#include "core/space/box.h"
#include "core/space/particles.h"

typedef struct pk_fe2_mpi {
    int rank, size;
    size_t ngp, ndof, ngrain;
    size_t lo, hi;                 /* this rank's block */
    pk_fe2_distributor dist;       /* rank 0: the others' blocks (pb->dist) */
    volatile sig_atomic_t *cancel; /* the run's cancel flag */
    double deadline;               /* the job's wall time (pk_wall_seconds), 0 none */
    const pk_fe2_rve *mr;          /* this rank's RVE states (pk_fe2_mpi_attach) */
    double *cmd;                   /* [2 + ndof] a command: op, argument, u */
    void *scratch;                 /* results or centres of one rank */
    size_t bytes_in, bytes_out;    /* moved so far (rank 0: the figures of docs/perf/fe2-mpi.md) */
    int broken;                    /* a wait was abandoned: the ranks cannot meet again */
} pk_fe2_mpi;

/* The blocks of ngp Gauss points over this launch's ranks, for a mesh of
 * ndof dofs and RVEs of ngrain grains; mon's cancel flag and wall time end
 * every wait.  0 / −1 (memory). */
int pk_fe2_mpi_init(pk_fe2_mpi *d, size_t ngp, size_t ndof, const pk_monitor *mon);

/* Rank 0 hands its RVE (box, grains) to the others, or ok = 0: the run
 * ended before (they stop).  Others: receive it into box, p (0), or learn
 * that the run ended (1), or lose rank 0 (−1, err).  Rank 0: 0, −1 (err). */
int pk_fe2_mpi_share_rve(pk_fe2_mpi *d, int ok, pk_box *box, pk_particles *p, char *err,
                         size_t errlen);

/* This rank's RVE states, of ngrain grains each (after pk_fe2_rve_init_block
 * on [d->lo, d->hi)). */
void pk_fe2_mpi_attach(pk_fe2_mpi *d, const pk_fe2_rve *mr, size_t ngrain);

/* Ranks other than 0: serve rounds, commits and centres for rank 0 until it
 * says stop (0) or is lost (−1, err). */
int pk_fe2_mpi_serve(pk_fe2_mpi *d, const pk_fe2_problem *pb, char *err, size_t errlen);

/* Rank 0: the committed centres ([ngrain][3]) of Gauss point g into x, from
 * the rank holding it.  0 / −1 (err). */
int pk_fe2_mpi_centres(pk_fe2_mpi *d, size_t g, double *x, char *err, size_t errlen);

/* Rank 0: the others stop serving (nothing when a wait was abandoned). */
void pk_fe2_mpi_stop(pk_fe2_mpi *d);

void pk_fe2_mpi_free(pk_fe2_mpi *d);

#endif
