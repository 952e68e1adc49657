/* job_metrics.c — counters and the run-time histogram of ended jobs in the
 * queue database; contract in job_metrics.h. */
#include "job_metrics.h"

#include <math.h>
#include <stdio.h>

static int exec_bound(sqlite3 *db, const char *sql, const char *id, const char *status)
{
    sqlite3_stmt *st;
    if (sqlite3_prepare_v2(db, sql, -1, &st, NULL) != SQLITE_OK) {
        fprintf(stderr, "packd: sql error: %s in %s\n", sqlite3_errmsg(db), sql);
        return -1;
    }
    sqlite3_bind_text(st, 1, id, -1, SQLITE_TRANSIENT);
    if (status)
        sqlite3_bind_text(st, 2, status, -1, SQLITE_TRANSIENT);
    int rc = sqlite3_step(st);
    sqlite3_finalize(st);
    return rc == SQLITE_DONE ? 0 : -1;
}

int pk_metrics_job_ended(sqlite3 *db, const char *id, const char *status)
{
    int a = exec_bound(db,
                       "INSERT INTO job_counts(process, status, n) SELECT process, ?2, 1 FROM jobs"
                       " WHERE id=?1 ON CONFLICT(process, status) DO UPDATE SET n = n + 1",
                       id, status);
    int b = exec_bound(db,
                       "INSERT INTO job_durations(process, le, n, secs) SELECT process,"
                       " (SELECT min(le) FROM duration_buckets WHERE le >= finished - started), 1,"
                       " finished - started FROM jobs WHERE id=?1 AND started IS NOT NULL AND"
                       " finished IS NOT NULL ON CONFLICT(process, le) DO UPDATE SET n = n + 1,"
                       " secs = secs + excluded.secs",
                       id, NULL);
    return a || b ? -1 : 0;
}

static json_t *bound_json(double le) { return isinf(le) ? json_null() : json_real(le); }

json_t *pk_metrics_read(sqlite3 *db)
{
    json_t *finished = json_object(), *durations = json_object(), *bounds = json_array();
    sqlite3_stmt *st;
    if (sqlite3_prepare_v2(db, "SELECT le FROM duration_buckets ORDER BY le", -1, &st, NULL) ==
        SQLITE_OK)
        while (sqlite3_step(st) == SQLITE_ROW)
            json_array_append_new(bounds, bound_json(sqlite3_column_double(st, 0)));
    sqlite3_finalize(st);
    if (sqlite3_prepare_v2(db, "SELECT process, status, n FROM job_counts", -1, &st, NULL) ==
        SQLITE_OK)
        while (sqlite3_step(st) == SQLITE_ROW) {
            const char *p = (const char *)sqlite3_column_text(st, 0);
            json_t *o = json_object_get(finished, p);
            if (!o)
                json_object_set_new(finished, p, o = json_object());
            json_object_set_new(o, (const char *)sqlite3_column_text(st, 1),
                                json_integer(sqlite3_column_int64(st, 2)));
        }
    sqlite3_finalize(st);
    /* every bound of every process that has run, so each series is whole */
    if (sqlite3_prepare_v2(db,
                           "SELECT p.process, b.le, coalesce(d.n, 0), coalesce(d.secs, 0.0) FROM"
                           " (SELECT DISTINCT process FROM job_durations) p CROSS JOIN"
                           " duration_buckets b LEFT JOIN job_durations d ON d.process = p.process"
                           " AND d.le = b.le ORDER BY p.process, b.le",
                           -1, &st, NULL) == SQLITE_OK)
        while (sqlite3_step(st) == SQLITE_ROW) {
            const char *p = (const char *)sqlite3_column_text(st, 0);
            json_t *o = json_object_get(durations, p);
            if (!o)
                json_object_set_new(durations, p,
                                    o = json_pack("{s:[],s:i,s:f}", "n", "count", 0, "sum", 0.0));
            long long n = sqlite3_column_int64(st, 2);
            json_array_append_new(json_object_get(o, "n"), json_integer(n));
            json_object_set_new(o, "count",
                                json_integer(json_integer_value(json_object_get(o, "count")) + n));
            json_object_set_new(o, "sum",
                                json_real(json_real_value(json_object_get(o, "sum")) +
                                          sqlite3_column_double(st, 3)));
        }
    sqlite3_finalize(st);
    return json_pack("{s:o,s:o,s:o}", "finished", finished, "durations", durations, "bounds",
                     bounds);
}
