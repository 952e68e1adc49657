/* result_cache.h — a successful job's result answering a later equal
 * request (config result_cache_max_age_s): what makes two requests equal,
 * and the new job's directory made from the old one's.  The queue finds
 * and records the jobs (pk_queue_find_reusable, pk_queue_submit_reused). */
#ifndef PK_RESULT_CACHE_H
#define PK_RESULT_CACHE_H

#include <jansson.h>

/* The key of a request for process with these validated inputs (caps
 * applied, links resolved): SHA-256 over the digest of this packd binary
 * (another build may compute another result), the process and the inputs
 * with sorted keys.  -1 when the inputs name a file: its bytes may change
 * under the same name, so such a job is never reused. */
int pk_result_cache_key(const char *process, json_t *inputs, char key[65]);

/* The result files of job src (its inputs, result, XDMF and summary) as
 * hard links in the job directory of dst under data (made if need be):
 * either job's dismissal leaves the other's files.  0, or -1 with none of
 * them left in dst. */
int pk_result_cache_link(const char *data, const char *src, const char *dst);

/* Remove those links from dst again (its other files stay). */
void pk_result_cache_unlink(const char *data, const char *dst);

#endif
