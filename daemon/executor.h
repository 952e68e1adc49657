/* executor.h — where the daemon's jobs run.  Two back ends behind one
 * interface, chosen by the config key `executor`:
 *   local  forked workers on this host (executor_local.c, the default)
 *   slurm  one sbatch job per packd job on a Slurm cluster (executor_slurm.c);
 *          jobs whose limits.wall_time_s is at most slurm_local_below_s run
 *          on a local back end beside it.
 * Every back end claims accepted jobs from the queue and records their ends
 * there: SQLite stays the one source of truth and only the daemon writes it. */
#ifndef PK_EXECUTOR_H
#define PK_EXECUTOR_H

#include <stddef.h>

#include "config.h"
#include "daemon/store/queue.h"

typedef struct pk_executor pk_executor;

typedef struct pk_executor_ops {
    const char *name;
    void (*configure)(pk_executor *e, const pk_config *c);
    void (*wake)(pk_executor *e);
    int (*busy)(pk_executor *e);
    int (*capacity)(pk_executor *e);
    int (*healthy)(pk_executor *e, char *why, size_t n);
    void (*stop)(pk_executor *e, double grace_s);
    void (*destroy)(pk_executor *e);
    /* poll cycles run and their seconds in all (NULL: the back end does not poll) */
    void (*poll_stats)(pk_executor *e, long long *cycles, double *seconds);
    /* job ends the queue could not record yet (NULL: the back end has none) */
    int (*unrecorded)(pk_executor *e);
} pk_executor_ops;

struct pk_executor {
    const pk_executor_ops *ops;
};

/* The back end c->executor names, started (its thread claims jobs now).
 * exe: path of the packd binary.  Before starting, jobs a dead daemon left
 * running are recovered as the back end needs (local: re-queued; slurm:
 * adopted by name).  NULL with err on failure. */
pk_executor *pk_executor_start(pk_queue *q, const char *exe, const pk_config *c, char *err,
                               size_t errlen);

/* SIGHUP: new limits take effect for the next claims. */
void pk_executor_configure(pk_executor *e, const pk_config *c);

/* Look at the queue now (a job was submitted or dismissed). */
void pk_executor_wake(pk_executor *e);

/* Jobs running now, and how many may run at once. */
int pk_executor_busy(pk_executor *e);
int pk_executor_capacity(pk_executor *e);

/* 1 when the back end can run jobs; 0 with why (e.g. "slurm controller
 * unreachable: ...") while it cannot: jobs then stay accepted. */
int pk_executor_healthy(pk_executor *e, char *why, size_t n);
const char *pk_executor_name(const pk_executor *e);

/* 1 with the poll cycles run so far and their wall seconds in all, for a
 * back end that polls (slurm); 0 otherwise. */
int pk_executor_poll_stats(pk_executor *e, long long *cycles, double *seconds);

/* Job ends waiting for the database (a full disk, an I/O error): retried
 * every second; the service is not ready while there are any. */
int pk_executor_unrecorded(pk_executor *e);

/* Stop claiming; give running jobs grace_s to finish (local) or leave them
 * to the cluster (slurm), join the thread.  busy/capacity/wake stay harmless
 * until pk_executor_free. */
void pk_executor_stop(pk_executor *e, double grace_s);
void pk_executor_free(pk_executor *e);

/* The local back end (executor_local.c).  It claims only jobs for which
 * short_only picks them: 0 = every accepted job; 1 = jobs whose
 * limits.wall_time_s is at most c->slurm_local_below_s (beside slurm). */
pk_executor *pk_executor_local_start(pk_queue *q, const char *exe, const pk_config *c,
                                     int short_only);
pk_executor *pk_executor_slurm_start(pk_queue *q, const char *exe, const pk_config *c, char *err,
                                     size_t errlen);

#endif
