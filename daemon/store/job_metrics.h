/* job_metrics.h — counters of ended jobs that never go down: kept in their
 * own tables of the queue database (migrations.c), so neither a dismissed
 * (deleted) job nor a restart takes anything away.  Prometheus then reads
 * true counters and a histogram (route_metrics.c). */
#ifndef PK_JOB_METRICS_H
#define PK_JOB_METRICS_H

#include <jansson.h>
#include <sqlite3.h>

/* Count job `id` as ended with `status` (successful, failed, dismissed) and,
 * if it ran (started and finished set), its run time.  Call inside the
 * transaction that ends the job, once per job.  0, or -1 on an SQL error. */
int pk_metrics_job_ended(sqlite3 *db, const char *id, const char *status);

/* {"finished": {process: {status: n}},
 *  "durations": {process: {"le": [bounds...], "n": [per bucket...], "sum": s, "count": c}},
 *  "bounds": [upper bounds in seconds, the last +Inf as null]} */
json_t *pk_metrics_read(sqlite3 *db);

#endif
