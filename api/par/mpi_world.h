/* mpi_world.h — the ranks of an MPI launch (`mpirun -np R packd run …`,
 * or `srun` with R tasks), beside the thread pool of core/base/par.h: one
 * process per rank, threads inside it.  The only file that includes
 * <mpi.h> is mpi_world.c, compiled with MPI when the build found Debian's
 * OpenMPI (PK_HAVE_MPI, Makefile); without it every packd is one process
 * and a launch of several ranks is refused (pk_mpi_init).
 *
 * The messages are byte blocks between rank 0 and one other rank.  Every
 * wait polls (a short sleep between tests, so an idle rank burns no core)
 * and ends on the caller's cancel flag or deadline: a lost rank never
 * hangs rank 0, and MPI errors return instead of aborting (MPI_ERRORS_RETURN). */
#ifndef PK_MPI_WORLD_H
#define PK_MPI_WORLD_H

#include <signal.h>
#include <stddef.h>

/* 1 when this packd was built with MPI. */
int pk_mpi_built(void);

/* The ranks the launcher started, from its environment (mpirun's
 * OMPI_COMM_WORLD_SIZE, srun's SLURM_STEP_NUM_TASKS, PMI-2's PMI_SIZE): 1
 * when not launched by one. */
int pk_mpi_launched_size(void);

/* Join the launch when pk_mpi_launched_size() > 1 (nothing otherwise):
 * MPI calls come from the main thread only, the pool's threads never make
 * any (MPI_THREAD_FUNNELED).  0; −1 with err when this build has no MPI,
 * MPI_Init failed, or MPI sees fewer ranks than were launched (srun with
 * no --mpi plugin: each task would run the whole job). */
int pk_mpi_init(char *err, size_t errlen);

/* This process's rank and the number of ranks (0 and 1 outside a launch). */
int pk_mpi_rank(void);
int pk_mpi_size(void);

/* Leave the launch: MPI_Finalize, or — after a wait was abandoned (a lost
 * rank, a cancel: the others cannot be met any more) — MPI_Abort with
 * status, which ends the other ranks too.  Nothing outside a launch. */
void pk_mpi_finish(int status);

/* A wait's outcome. */
enum { PK_MPI_OK = 0, PK_MPI_LOST = -1, PK_MPI_CANCELLED = 2 };

/* One transfer of a wait: n bytes to (send) or from (receive) rank peer;
 * done is set by the wait. */
typedef struct pk_mpi_msg {
    int peer, tag, send;
    void *buf;
    size_t n;
    int done;
} pk_mpi_msg;

/* Post the n transfers and wait until all are done: OK; LOST (an MPI error
 * or the deadline, pk_wall_seconds(), passed; 0 = none); CANCELLED when
 * *cancel was set while waiting.  Otherwise than OK, the transfers not done
 * name the ranks that did not answer (a killed rank is among them).  A wait
 * that did not end OK leaves transfers posted: pk_mpi_finish(≠ 0). */
int pk_mpi_exchange(pk_mpi_msg *m, size_t n, volatile sig_atomic_t *cancel, double deadline);

#endif
