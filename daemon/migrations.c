/* migrations.c — every schema change of the queue database, in order.  Step i
 * takes user_version i to i+1; never edit a released step, append one. */
#include "migrations.h"

#include <stdio.h>

static const char *const steps[] = {
    /* 0 -> 1: jobs, their events (SSE resume), idempotency keys, uploads */
    "CREATE TABLE jobs ("
    "  seq INTEGER PRIMARY KEY AUTOINCREMENT,"      /* submission order */
    "  id TEXT NOT NULL UNIQUE,"
    "  process TEXT NOT NULL,"
    "  inputs TEXT NOT NULL,"                      /* JSON, as validated */
    "  owner TEXT NOT NULL,"
    "  status TEXT NOT NULL CHECK (status IN ('accepted','running','successful','failed','dismissed')),"
    "  progress INTEGER NOT NULL DEFAULT 0,"
    "  message TEXT NOT NULL DEFAULT '',"
    "  created REAL NOT NULL, started REAL, finished REAL, updated REAL NOT NULL,"
    "  attempts INTEGER NOT NULL DEFAULT 0,"       /* worker starts */
    "  cancel_requested INTEGER NOT NULL DEFAULT 0,"
    "  worker_pid INTEGER,"
    "  rev INTEGER NOT NULL DEFAULT 0,"            /* bumped on every change: ETag */
    "  summary TEXT,"                              /* worker's summary JSON */
    "  result_sha256 TEXT, result_size INTEGER);"
    "CREATE INDEX jobs_by_status ON jobs(status, seq);"
    "CREATE INDEX jobs_by_owner ON jobs(owner, status);"
    "CREATE TABLE events ("
    "  id INTEGER PRIMARY KEY AUTOINCREMENT,"      /* SSE id */
    "  job_id TEXT NOT NULL, kind TEXT NOT NULL, data TEXT NOT NULL, created REAL NOT NULL);"
    "CREATE INDEX events_by_job ON events(job_id, id);"
    "CREATE TABLE idempotency ("
    "  owner TEXT NOT NULL, key TEXT NOT NULL, request_sha256 TEXT NOT NULL,"
    "  job_id TEXT NOT NULL, created REAL NOT NULL, PRIMARY KEY (owner, key));"
    "CREATE TABLE files ("
    "  id TEXT PRIMARY KEY, sha256 TEXT NOT NULL, size INTEGER NOT NULL,"
    "  media_type TEXT NOT NULL, owner TEXT NOT NULL, created REAL NOT NULL);",
    /* job metrics that outlive the job rows (job_metrics.c): how many jobs
     * ended per process and final status, and a histogram of their run
     * times; both filled from the jobs already there.  duration_buckets
     * holds the histogram's upper bounds in seconds (9e999 is +Inf). */
    "CREATE TABLE job_counts ("
    "  process TEXT NOT NULL, status TEXT NOT NULL, n INTEGER NOT NULL,"
    "  PRIMARY KEY (process, status));"
    "CREATE TABLE duration_buckets (le REAL PRIMARY KEY);"
    "INSERT INTO duration_buckets VALUES (0.1), (0.5), (1), (2), (5), (10), (30), (60), (120),"
    "  (300), (600), (1800), (3600), (7200), (21600), (86400), (9e999);"
    "CREATE TABLE job_durations ("                 /* per bucket, not cumulative */
    "  process TEXT NOT NULL, le REAL NOT NULL, n INTEGER NOT NULL, secs REAL NOT NULL,"
    "  PRIMARY KEY (process, le));"
    "INSERT INTO job_counts(process, status, n) SELECT process, status, count(*) FROM jobs"
    "  WHERE status IN ('successful', 'failed', 'dismissed') GROUP BY process, status;"
    "INSERT INTO job_durations(process, le, n, secs)"
    "  SELECT process, (SELECT min(le) FROM duration_buckets WHERE le >= finished - started) AS b,"
    "  count(*), sum(finished - started) FROM jobs"
    "  WHERE started IS NOT NULL AND finished IS NOT NULL GROUP BY process, b;",
};

int pk_schema_version(void) { return (int)(sizeof steps / sizeof *steps); }

static int user_version(sqlite3 *db)
{
    sqlite3_stmt *st;
    int v = -1;
    if (sqlite3_prepare_v2(db, "PRAGMA user_version", -1, &st, NULL) == SQLITE_OK &&
        sqlite3_step(st) == SQLITE_ROW)
        v = sqlite3_column_int(st, 0);
    sqlite3_finalize(st);
    return v;
}

int pk_migrate(sqlite3 *db, char *err, size_t errlen)
{
    int v = user_version(db);
    if (v < 0) {
        snprintf(err, errlen, "cannot read user_version: %s", sqlite3_errmsg(db));
        return -1;
    }
    if (v > pk_schema_version()) {
        snprintf(err, errlen, "database schema version %d is newer than this packd (%d)", v,
                 pk_schema_version());
        return -1;
    }
    for (; v < pk_schema_version(); v++) {
        char *msg = NULL, sql[64];
        snprintf(sql, sizeof sql, "PRAGMA user_version = %d", v + 1);
        if (sqlite3_exec(db, "BEGIN IMMEDIATE", NULL, NULL, &msg) != SQLITE_OK ||
            sqlite3_exec(db, steps[v], NULL, NULL, &msg) != SQLITE_OK ||
            sqlite3_exec(db, sql, NULL, NULL, &msg) != SQLITE_OK ||
            sqlite3_exec(db, "COMMIT", NULL, NULL, &msg) != SQLITE_OK) {
            snprintf(err, errlen, "migration %d -> %d: %s", v, v + 1, msg ? msg : "?");
            sqlite3_free(msg);
            sqlite3_exec(db, "ROLLBACK", NULL, NULL, NULL);
            return -1;
        }
    }
    return v;
}
