/* job_end.c — a job's end kept until the queue records it.  Contract:
 * daemon/job_end.h. */
#include "job_end.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "log.h"

#define RETRY_S 1.0
#define RELOG_S 60.0 /* a pending end is logged again this often */

static char *dup_or_null(const char *s) { return s ? strdup(s) : NULL; }

void pk_job_end_drop(pk_job_end *e)
{
    free(e->message);
    free(e->summary);
    memset(e, 0, sizeof *e);
}

static const char *attempt(pk_job_end *e, pk_queue *q, double now)
{
    const char *ended = pk_queue_finish(q, e->id, e->status, e->message, e->summary,
                                        e->sha256[0] ? e->sha256 : NULL, e->size);
    if (ended) {
        if (e->pending)
            pk_log(PK_LOG_WARN, "job end recorded", "{s:s,s:s,s:f}", "job", e->id, "status", ended,
                   "late_s", now - e->since);
        pk_job_end_drop(e);
        return ended;
    }
    if (!e->pending) {
        e->pending = 1;
        e->since = now;
    }
    e->retry_at = now + RETRY_S;
    if (e->logged_at == 0 || now - e->logged_at >= RELOG_S) {
        char why[200] = "";
        pk_queue_writable(q, why, sizeof why);
        pk_log(PK_LOG_ERROR, "job end not recorded: retrying every second", "{s:s,s:s,s:s,s:s,s:f}",
               "job", e->id, "status", e->status, "message", e->message ? e->message : "", "error",
               why[0] ? why : "the queue refused the write", "pending_s", now - e->since);
        e->logged_at = now;
    }
    return NULL;
}

const char *pk_job_end_record(pk_job_end *e, pk_queue *q, const char *id, const char *status,
                              const char *message, const char *summary, const char *sha256,
                              long long size)
{
    pk_job_end_drop(e);
    snprintf(e->id, sizeof e->id, "%s", id);
    snprintf(e->status, sizeof e->status, "%s", status);
    snprintf(e->sha256, sizeof e->sha256, "%s", sha256 ? sha256 : "");
    e->message = dup_or_null(message);
    e->summary = dup_or_null(summary);
    e->size = size;
    return attempt(e, q, pk_queue_now());
}

const char *pk_job_end_retry(pk_job_end *e, pk_queue *q, double now)
{
    return e->pending && now >= e->retry_at ? attempt(e, q, now) : NULL;
}
