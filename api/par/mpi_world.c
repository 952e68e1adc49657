/* mpi_world.c — the ranks of an MPI launch.  Contract: mpi_world.h. */
#include "mpi_world.h"

#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "core/base/progress.h"

int pk_mpi_launched_size(void)
{
    /* mpirun; srun's tasks of a step (whatever its --mpi plugin: pmix sets
     * no size); PMI-2 launchers.  Not SLURM_NTASKS: a batch script has it
     * and is one process. */
    static const char *const vars[] = {"OMPI_COMM_WORLD_SIZE", "SLURM_STEP_NUM_TASKS", "PMI_SIZE"};
    for (size_t i = 0; i < sizeof vars / sizeof vars[0]; i++) {
        const char *v = getenv(vars[i]);
        long n = v ? strtol(v, NULL, 10) : 0;
        if (n >= 1 && n <= INT_MAX)
            return (int)n;
    }
    return 1;
}

/* A poll's pause, the k-th of a wait: 50 µs doubling to 800 µs.  A short
 * wait (an answer already on its way) ends within 50 µs; a rank idle for a
 * whole round (the macro solve, the other blocks: 7–200 ms here) wakes
 * ~10 times less often than at a fixed 100 µs, its added latency ≤ 0.8 ms. */
static void pause_poll(unsigned k)
{
    struct timespec ts = {0, 50000L << (k < 4 ? k : 4)};
    nanosleep(&ts, NULL);
}

#ifdef PK_HAVE_MPI
#include <mpi.h>

static int world_rank, world_size = 1, joined, abandoned;

int pk_mpi_built(void) { return 1; }

int pk_mpi_init(char *err, size_t errlen)
{
    if (pk_mpi_launched_size() <= 1)
        return 0;
    int level;
    if (MPI_Init_thread(NULL, NULL, MPI_THREAD_FUNNELED, &level) != MPI_SUCCESS) {
        snprintf(err, errlen, "MPI_Init failed");
        return -1;
    }
    joined = 1;
    MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_RETURN);
    MPI_Comm_rank(MPI_COMM_WORLD, &world_rank);
    MPI_Comm_size(MPI_COMM_WORLD, &world_size);
    if (world_size != pk_mpi_launched_size()) {
        /* srun without an MPI plugin: every task is a rank 0 of its own */
        snprintf(err, errlen,
                 "launched as %d tasks, but MPI sees %d rank%s: the launcher gave MPI no "
                 "process manager (with srun: --mpi=pmix, or MpiDefault=pmix in slurm.conf)",
                 pk_mpi_launched_size(), world_size, world_size == 1 ? "" : "s");
        MPI_Finalize();
        joined = 0, world_rank = 0, world_size = 1;
        return -1;
    }
    return 0;
}

void pk_mpi_finish(int status)
{
    if (!joined)
        return;
    joined = 0;
    if (abandoned) {
        fflush(NULL); /* the abort ends this process too: its summary first */
        MPI_Abort(MPI_COMM_WORLD, status ? status : 1);
    } else
        MPI_Finalize();
}

int pk_mpi_exchange(pk_mpi_msg *m, size_t n, volatile sig_atomic_t *cancel, double deadline)
{
    MPI_Request *rq = calloc(n ? n : 1, sizeof *rq);
    int rc = PK_MPI_OK;
    for (size_t i = 0; i < n; i++)
        m[i].done = 0;
    if (!rq)
        return PK_MPI_LOST;
    for (size_t i = 0; i < n; i++) {
        int e = m[i].n > INT_MAX ? MPI_ERR_COUNT
            : m[i].send          ? MPI_Isend(m[i].buf, (int)m[i].n, MPI_BYTE, m[i].peer, m[i].tag,
                                             MPI_COMM_WORLD, &rq[i])
                                 : MPI_Irecv(m[i].buf, (int)m[i].n, MPI_BYTE, m[i].peer, m[i].tag,
                                             MPI_COMM_WORLD, &rq[i]);
        if (e != MPI_SUCCESS) {
            rc = PK_MPI_LOST;
            goto out;
        }
    }
    for (size_t left = n, k = 0; left > 0; k++) {
        left = 0;
        for (size_t i = 0; i < n; i++) {
            if (!m[i].done && MPI_Test(&rq[i], &m[i].done, MPI_STATUS_IGNORE) != MPI_SUCCESS) {
                m[i].done = 0;
                rc = PK_MPI_LOST;
                goto out;
            }
            left += !m[i].done;
        }
        if (!left)
            break;
        if (cancel && *cancel) {
            rc = PK_MPI_CANCELLED;
            goto out;
        }
        if (deadline > 0 && pk_wall_seconds() > deadline) {
            rc = PK_MPI_LOST;
            goto out;
        }
        pause_poll((unsigned)k);
    }
out:
    abandoned |= rc != PK_MPI_OK;
    free(rq);
    return rc;
}

#else

int pk_mpi_built(void) { return 0; }

int pk_mpi_init(char *err, size_t errlen)
{
    if (pk_mpi_launched_size() <= 1)
        return 0;
    snprintf(err, errlen,
             "launched as one of %d MPI ranks, but this packd was built without MPI "
             "(install libopenmpi-dev and run make again): every rank would run the whole job "
             "and write the same file",
             pk_mpi_launched_size());
    return -1;
}

void pk_mpi_finish(int status) { (void)status; }

int pk_mpi_exchange(pk_mpi_msg *m, size_t n, volatile sig_atomic_t *cancel, double deadline)
{
    (void)cancel, (void)deadline;
    for (size_t i = 0; i < n; i++)
        m[i].done = 0;
    (void)pause_poll;
    return n ? PK_MPI_LOST : PK_MPI_OK;
}

static const int world_rank = 0, world_size = 1;
#endif

int pk_mpi_rank(void) { return world_rank; }
int pk_mpi_size(void) { return world_size; }
