/* client_job.h — what the client commands do with one job: report a problem
 * document, follow the job's event stream with a progress line, download and
 * verify its result.  Functions return the command's exit status:
 *   0 done, 1 rejected (4xx), 2 transport/integrity/server error,
 *   3 the job failed or was dismissed. */
#ifndef PK_CLIENT_JOB_H
#define PK_CLIENT_JOB_H

#include <jansson.h>

#include "client_http.h"

/* A string member of a document, "" when absent. */
const char *pk_doc_str(const json_t *doc, const char *key);

/* Print an answer that is not a success to stderr (a problem document's
 * title, detail and each error's pointer and message; else the raw body)
 * and return its exit status: 2 for no answer or 5xx, 1 otherwise. */
int pk_client_report(const char *cmd, const pk_reply *r);

/* Follow /jobs/{id}/events until the job is final (progress line on stderr
 * unless quiet; falls back to polling /jobs/{id}).  Returns the final status
 * document (new reference) or NULL after reporting a transport error. */
json_t *pk_client_wait(const pk_client *c, const char *id, int quiet);

/* Download the job's result to out and verify its SHA-256 against the
 * results document and the X-Content-SHA256 header (a failed job's partial
 * file too, to "<out>.partial", then 3: out is written only on success), and its content hash against the summary's
 * result_digest when the server states one (api/results/result_digest.h).
 * On success *info (if given) gets {"output", "sha256", "size", "summary",
 * "result_digest"}. */
int pk_client_fetch(const pk_client *c, const char *id, const char *out, json_t **info);

#endif
