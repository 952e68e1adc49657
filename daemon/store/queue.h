/* queue.h — the durable job queue: one SQLite file (WAL, busy timeout,
 * migrations.c) is the source of truth for jobs, inputs, states, progress,
 * idempotency keys, uploads and the events SSE listeners resume from.
 *
 * One writer connection per pk_queue, serialised by a mutex, and a few
 * read-only connections (SQLITE_OPEN_READONLY) for the lookups (get, list,
 * events, files, stats) and pk_queue_writable, so a read never waits on a
 * commit's fsync: every function is one short transaction and safe to call
 * from any thread.  Job rows come back as
 * JSON objects with the column names as keys (inputs/summary parsed). */
#ifndef PK_QUEUE_H
#define PK_QUEUE_H

#include <jansson.h>
#include <stddef.h>

typedef struct pk_queue pk_queue;

enum {
    PK_Q_OK = 0,            /* new job created */
    PK_Q_EXISTING = 1,      /* idempotency key seen with the same request: same job */
    PK_Q_FULL = -2,         /* max_queued waiting jobs */
    PK_Q_OWNER_FULL = -3,   /* max_queued_per_owner waiting jobs of this owner */
    PK_Q_KEY_CONFLICT = -4, /* idempotency key reused with another request */
    PK_Q_UNWRITABLE = -5,   /* the database takes no writes now (disk full, I/O error) */
    PK_Q_GONE = -6,         /* the job to reuse is no longer successful (dismissed meanwhile) */
    PK_Q_ERROR = -1,
};

pk_queue *pk_queue_open(const char *path, char *err, size_t errlen);
void pk_queue_close(pk_queue *q);

/* Current time in seconds since the epoch (what the queue stores). */
double pk_queue_now(void);

typedef struct pk_submit {
    const char *id; /* the new job's id (pk_uuid4), or NULL: one is made */
    const char *process, *inputs_json, *owner;
    const char *idempotency_key; /* may be NULL */
    const char *request_sha256;  /* fingerprint of the request (with a key) */
    const char *cache_key;       /* its result may answer a later equal request; NULL: never */
    int max_queued, max_queued_per_owner;
} pk_submit;

/* Submit a job; fills id (37 bytes). Returns a PK_Q_* code. */
int pk_queue_submit(pk_queue *q, const pk_submit *s, char id[37]);

/* A successful job of owner whose cache_key is key, finished at or after
 * not_before, whose summary does not say complete: false (a run that
 * stopped short may go further when run again): its id in src (37 bytes),
 * the newest such; 0 when there is none. */
int pk_queue_find_reusable(pk_queue *q, const char *key, const char *owner, double not_before,
                           char src[37]);

/* Record s as a job already successful with src's result (its files are in
 * place under the id the caller chose, in id): its summary, digest and
 * size, message saying where it came from.  The idempotency key is honoured
 * as by pk_queue_submit (PK_Q_EXISTING fills id with the earlier job);
 * PK_Q_GONE when src is no longer successful. */
int pk_queue_submit_reused(pk_queue *q, const pk_submit *s, const char *src, char id[37]);

/* The job row, or NULL if unknown. */
json_t *pk_queue_get(pk_queue *q, const char *id);

/* Which jobs GET /jobs lists (OGC job-list); an absent filter matches all. */
typedef struct pk_job_filter {
    const char *status_json;             /* JSON array of statuses (any of them), or NULL */
    const char *process_json;            /* JSON array of process ids (any of them), or NULL */
    const char *owner;                   /* NULL: every owner's */
    double created_from, created_before; /* created in [from, before); NAN: open */
    /* started..finished, or ..now while running; a job without both (never
     * started, or re-queued) has no duration and fails either bound */
    double min_duration, max_duration; /* seconds; NAN: none */
} pk_job_filter;

/* Newest first: at most limit rows after offset; *total all that match. */
json_t *pk_queue_list(pk_queue *q, const pk_job_filter *f, int limit, int offset, int *total);

/* Move the oldest accepted job to running (attempts + 1).  Returns the job
 * row (new ref) or NULL when none waits.  A job a back end holds
 * (executor_ref set, e.g. queued on Slurm) is never claimed. */
json_t *pk_queue_claim(pk_queue *q);
/* The same among jobs whose inputs' limits.wall_time_s is at most bound_s
 * (SHORT) or is not (LONG: larger or absent); ANY ignores bound_s. */
typedef enum { PK_CLAIM_ANY, PK_CLAIM_SHORT, PK_CLAIM_LONG } pk_claim;
json_t *pk_queue_claim_by_wall(pk_queue *q, pk_claim which, double bound_s);
void pk_queue_set_worker(pk_queue *q, const char *id, int pid);

/* A running job's progress (0..100) and the worker's progress object. */
void pk_queue_progress(pk_queue *q, const char *id, int percent, json_t *data);

/* End a running job: status "successful" or "failed".  A job already
 * dismissed (cancelled) keeps its status; its final event notes the stop.
 * Progress events of the job but the last are dropped (SSE history of a
 * finished job: its status events and final progress).
 * Returns the status the job ends with (static string), "unchanged" when
 * the job was not running (already final: nothing is touched), or NULL when
 * the end could not be recorded (database or disk full, I/O error: nothing
 * changed; the caller tries again). */
const char *pk_queue_finish(pk_queue *q, const char *id, const char *status, const char *message,
                            const char *summary_json, const char *sha256, long long size);

/* DELETE /jobs/{id}: accepted/running -> dismissed (running ones get
 * cancel_requested, the executor stops their worker); finished ->
 * dismissed.  *was receives the previous status.  Returns 0, -1 if unknown. */
int pk_queue_dismiss(pk_queue *q, const char *id, char was[16]);

/* Running jobs whose worker must be stopped (cancel_requested). */
json_t *pk_queue_cancel_requests(pk_queue *q);

/* Daemon start: jobs left running by a dead daemon go back to accepted, or
 * fail after max_attempts starts.  Returns how many were re-queued. */
int pk_queue_recover(pk_queue *q, int max_attempts, int *failed);

/* SIGTERM past the grace period: give the start back and re-queue. */
void pk_queue_requeue(pk_queue *q, const char *id, const char *why);

/* The status events of every job after event id `after` (at most limit):
 * [{id, job_id, data}]; with after < 0, {id} of the last event of all. */
json_t *pk_queue_status_events(pk_queue *q, long long after, int limit);

/* Events of a job after event id `after` (oldest first, at most limit):
 * [{"id", "kind", "data"}]. */
json_t *pk_queue_events(pk_queue *q, const char *id, long long after, int limit);

/* Block until an event newer than `seen` (from pk_queue_event_seq) may exist
 * or timeout_ms passes; returns the current sequence. */
long long pk_queue_event_seq(pk_queue *q);
long long pk_queue_wait_event(pk_queue *q, long long seen, int timeout_ms);
/* Wake every waiter (shutdown). */
void pk_queue_wake_all(pk_queue *q);

/* Metrics: {"jobs": {status: n} (rows now), "ok": whether the database
 * answered, and the monotonic "finished", "durations", "bounds" of
 * pk_metrics_read (job_metrics.h)}. */
json_t *pk_queue_stats(pk_queue *q);

/* Transactions the writer committed since the queue was opened. */
long long pk_queue_transactions(pk_queue *q);

/* 1 when the last write committed; 0 while writes fail (why: the error and
 * how long).  Meanwhile a probe as large as a job's end is written at most
 * once a second (skipped while the writer is busy: it reports its own
 * outcome), so the state clears by itself once space returns.  Never waits
 * on a write in progress. */
int pk_queue_writable(pk_queue *q, char *why, size_t n);

/* For a back end that runs jobs outside this process (daemon/executor.h):
 * the jobs it holds, executor_ref 'backend:<ref>' not yet ended, oldest
 * first: [{id, status, attempts, progress, message, owner, inputs,
 * executor_ref}]. */
json_t *pk_queue_held_jobs(pk_queue *q, const char *backend);

/* Apply a poll cycle's changes in ONE transaction, events only for what
 * changed.  Each change is {"id", "op", ...}, and any op may carry "ref"
 * (the new executor_ref):
 *   "hold"     only set the ref
 *   "queued"   accepted/running -> accepted, "message"; "attempts" if > 0
 *   "running"  accepted/running -> running, "message", "attempts" if > 0,
 *              "progress": a worker progress object with "progress" 0..99
 *   "finish"   as pk_queue_finish: "status", "message", "summary" (JSON
 *              text), "sha256", "size" (an accepted job passes by running)
 *   "requeue"  a claimed job not yet held goes back to accepted, its start
 *              given back, "message" says why
 * Returns 0 when committed. */
int pk_queue_sync(pk_queue *q, json_t *changes);

/* Uploaded files: one row per (id, owner) — the bytes are stored once, each
 * owner who sent them owns the upload.  get_file with owner NULL: any owner's. */
int pk_queue_add_file(pk_queue *q, const char *id, const char *sha256, long long size,
                      const char *media_type, const char *owner);
json_t *pk_queue_get_file(pk_queue *q, const char *id, const char *owner);

#endif
