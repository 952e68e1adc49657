/* job_end.h — a job's end as the queue must record it, kept until it is.
 *
 * A worker that ends while the queue database takes no writes (database or
 * disk full, I/O error) would leave its job `running` with no worker and its
 * reason lost.  Its end (status, message, summary, result digest) is kept
 * with its slot instead and written again every second until it commits;
 * the first failure, and one a minute after it, is logged with the
 * database's error.  Used by the local executor's thread only. */
#ifndef PK_JOB_END_H
#define PK_JOB_END_H

#include "daemon/store/queue.h"

typedef struct pk_job_end {
    int pending; /* an end not recorded yet */
    char id[37], status[12], sha256[65];
    char *message, *summary; /* owned copies */
    long long size;
    double since, retry_at, logged_at;
} pk_job_end;

/* Record the end of job id (arguments as pk_queue_finish; sha256 and summary
 * may be NULL).  Returns the status the job ended with, as pk_queue_finish,
 * or NULL when it is pending: e keeps a copy for pk_job_end_retry. */
const char *pk_job_end_record(pk_job_end *e, pk_queue *q, const char *id, const char *status,
                              const char *message, const char *summary, const char *sha256,
                              long long size);

/* A pending end whose second has come is tried again: the status it ended
 * with once recorded (e is then free), else NULL. */
const char *pk_job_end_retry(pk_job_end *e, pk_queue *q, double now);

/* Forget a pending end (the daemon stops: the job is re-queued at the next
 * start, pk_queue_recover). */
void pk_job_end_drop(pk_job_end *e);

#endif
