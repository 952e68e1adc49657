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
