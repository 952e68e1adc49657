/* job_verdict.h — what a finished job says of itself (docs/job-format.md,
 * "Status").  One contract for every process:
 *
 *   successful, complete: true    the job did what it was asked;
 *   successful, complete: false   it stopped short for a reason the user chose
 *                                 (e.g. a target φ above what the algorithm
 *                                 reaches); "warnings" says what and by how much;
 *   failed                        wall time, divergence, a failed audit,
 *                                 non-finite numbers: "failure" says why, and
 *                                 the partial result file is kept and says so.
 *
 * The verdict lives in the summary object a process's run returns, and in
 * the result file under /observables/verdict/. */
#ifndef PK_JOB_VERDICT_H
#define PK_JOB_VERDICT_H

#include <jansson.h>

#include "api/results/h5_result.h"

/* Append a sentence to summary's "warnings" array. */
void pk_verdict_warn(json_t *summary, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

/* Mark the job failed: sets "failure" (the first reason given wins) and
 * "complete": false. */
void pk_verdict_fail(json_t *summary, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

/* 1 when summary carries a failure. */
int pk_verdict_failed(const json_t *summary);

/* "successful" or "failed". */
const char *pk_verdict_status(const json_t *summary);

/* /observables/verdict/{status, complete, failure, warnings, warning_count}:
 * warnings as one string, one sentence per line.  0 on success. */
int pk_verdict_write_h5(pk_h5 *h, const json_t *summary);

/* The last step of every result file: unless an earlier write failed
 * (failed != 0), write the verdict and commit h under its name; otherwise
 * abort h (nothing appears at out_path) with "writing … failed" in err.
 * 0 / −1. */
int pk_verdict_close_h5(pk_h5 *h, int failed, const json_t *summary, const char *out_path,
                        char *err, size_t errlen);

#endif
