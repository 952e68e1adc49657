/* http_status_info.h — OGC API – Processes statusInfo and results documents
 * from a job row of the queue (a JSON object with the queue's column names:
 * id, process, status, progress, message, created, started, finished,
 * updated, summary, result_sha256, result_size). */
#ifndef PK_HTTP_STATUS_INFO_H
#define PK_HTTP_STATUS_INFO_H

#include <jansson.h>

/* statusInfo: jobID, processID, type, status, message, progress, created,
 * started, finished, updated, links (self, monitor (SSE), results or the
 * partial result of a failed job), and the verdict's complete, warnings and
 * failure when the job has finished. */
json_t *pk_status_info(json_t *row);

/* Results document of a successful job: {"summary": {"value": {...}},
 * "result": {"href", "type", "size", "sha256"}}. */
json_t *pk_results_document(json_t *row);

/* 1 when the job failed but kept a partial result file (job_verdict.h). */
int pk_has_partial_result(json_t *row);

/* The problem document (status 422) that the results of a failed job
 * answer: the failure reason, the summary, and the partial file if any. */
json_t *pk_failed_results_problem(json_t *row);

/* Media type of the one file output "result". */
#define PK_RESULT_MEDIA_TYPE "application/x-hdf5"

#endif
