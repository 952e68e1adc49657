/* supervisor.h — the worker processes of the daemon.
 *
 * One thread claims accepted jobs from the queue while fewer than `workers`
 * run, and starts each as a child process: fork/exec of this same binary,
 *   packd run DATA/jobs/<id>/job.json -o DATA/jobs/<id>/result.h5 --progress-fd 3 --threads T
 * with stdout -> summary.json, stderr -> worker.log.  The child
 *   - dies with the daemon (PR_SET_PDEATHSIG = SIGKILL, checked against a race),
 *   - holds an exclusive flock on DATA/jobs/<id>/worker.lock for its whole life,
 *     so a second worker of the same job (e.g. after a daemon restart while the
 *     old child is still being killed) waits until the first is gone.
 * The thread relays progress lines to the queue (-> SSE), reaps children
 * (a crash fails only that job, with the signal in `message`), hashes the
 * result (SHA-256) and sends SIGTERM to workers of dismissed jobs — which
 * the worker turns into the core's cancel flag — within 0.2 s of the request. */
#ifndef PK_SUPERVISOR_H
#define PK_SUPERVISOR_H

#include "daemon/store/queue.h"

typedef struct pk_supervisor pk_supervisor;

/* exe: path of the packd binary; data: data directory (jobs/ inside);
 * job_threads: threads of each worker's parallel sections (T above). */
pk_supervisor *pk_supervisor_start(pk_queue *q, const char *exe, const char *data, int workers,
                                   double max_wall_time_s, int job_threads);

/* SIGHUP: new limits take effect for the next claims. */
void pk_supervisor_configure(pk_supervisor *s, int workers, double max_wall_time_s,
                             int job_threads);

/* Look at the queue now (a job was submitted or dismissed). */
/* Wall seconds between a worker's checkpoints (default 30). */
void pk_supervisor_set_checkpoint_interval(pk_supervisor *s, double seconds);

void pk_supervisor_wake(pk_supervisor *s);

/* Workers running now, and the configured maximum. */
int pk_supervisor_busy(const pk_supervisor *s);
int pk_supervisor_capacity(const pk_supervisor *s);

/* Ended jobs whose end the queue could not record yet (daemon/job_end.h):
 * their slots stay taken and /healthz is not ready while any is left. */
int pk_supervisor_unrecorded(const pk_supervisor *s);

/* Stop claiming; give running jobs grace_s to finish, then kill their workers
 * and re-queue the jobs; join the thread.  The object stays readable (busy,
 * capacity, wake are harmless) until pk_supervisor_free. */
void pk_supervisor_stop(pk_supervisor *s, double grace_s);
void pk_supervisor_free(pk_supervisor *s);

#endif
