/* worker_files.h — the job directory as the daemon and a worker share it,
 * whatever runs the worker (daemon/executor.h): the daemon writes job.json,
 * the worker writes progress lines, summary.json and result.h5, the daemon
 * reads them back into the queue. */
#ifndef PK_WORKER_FILES_H
#define PK_WORKER_FILES_H

#include <jansson.h>
#include <stddef.h>

/* Before a start: make DATA/jobs/<id>, remove an interrupted run's
 * temporary files and result, write job.json {process, inputs} of the job
 * row.  0, or -1 with why. */
int pk_worker_prepare(const char *dir, json_t *job, char *why, size_t n);

/* The job's /h5md/author for `packd run --author`: its owner when that names
 * a person (a token's name, the proxy's X-Packd-Owner), "" when the owner is
 * only the client's address (auth off): the file then says the author is
 * unknown rather than naming a machine. */
const char *pk_worker_author(json_t *job);

/* Remove *.tmp files in dir (an interrupted run's). */
void pk_worker_remove_tmp(const char *dir);

/* A worker progress object -> percent 0..99 (100 is for successful),
 * also stored in it as "progress". */
int pk_worker_percent(json_t *progress);

/* The end of a worker that exited with code 0 or 3 (docs/job-format.md,
 * "Status"): status "successful"/"failed", message, summary JSON text
 * (malloc'd, may be NULL) and the result's SHA-256 and size; a missing
 * result file fails the job. */
typedef struct pk_worker_outcome {
    const char *status;
    char message[1200];
    char *summary;
    char sha256[65];
    long long size;
} pk_worker_outcome;
void pk_worker_outcome_read(const char *dir, int code, pk_worker_outcome *o);

/* Last non-empty line of a text file (the worker's stderr), "" if none. */
void pk_worker_last_line(const char *path, char *out, size_t n);

#endif
