/* migrations.c — every schema change of the queue database, in order.  Step i
 * takes user_version i to i+1; never edit a released step, append one. */
#include "migrations.h"

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static const char *const steps[] = {
    /* 0 -> 1: jobs, their events (SSE resume), idempotency keys, uploads */
    "CREATE TABLE jobs ("
    "  seq INTEGER PRIMARY KEY AUTOINCREMENT," /* submission order */
    "  id TEXT NOT NULL UNIQUE,"
    "  process TEXT NOT NULL,"
    "  inputs TEXT NOT NULL," /* JSON, as validated */
    "  owner TEXT NOT NULL,"
    "  status TEXT NOT NULL CHECK (status IN "
    "('accepted','running','successful','failed','dismissed')),"
    "  progress INTEGER NOT NULL DEFAULT 0,"
    "  message TEXT NOT NULL DEFAULT '',"
    "  created REAL NOT NULL, started REAL, finished REAL, updated REAL NOT NULL,"
    "  attempts INTEGER NOT NULL DEFAULT 0," /* worker starts */
    "  cancel_requested INTEGER NOT NULL DEFAULT 0,"
    "  worker_pid INTEGER,"
    "  rev INTEGER NOT NULL DEFAULT 0," /* bumped on every change: ETag */
    "  summary TEXT,"                   /* worker's summary JSON */
    "  result_sha256 TEXT, result_size INTEGER);"
    "CREATE INDEX jobs_by_status ON jobs(status, seq);"
    "CREATE INDEX jobs_by_owner ON jobs(owner, status);"
    "CREATE TABLE events ("
    "  id INTEGER PRIMARY KEY AUTOINCREMENT," /* SSE id */
    "  job_id TEXT NOT NULL, kind TEXT NOT NULL, data TEXT NOT NULL, created REAL NOT NULL);"
    "CREATE INDEX events_by_job ON events(job_id, id);"
    "CREATE TABLE idempotency ("
    "  owner TEXT NOT NULL, key TEXT NOT NULL, request_sha256 TEXT NOT NULL,"
    "  job_id TEXT NOT NULL, created REAL NOT NULL, PRIMARY KEY (owner, key));"
    "CREATE TABLE files ("
    "  id TEXT PRIMARY KEY, sha256 TEXT NOT NULL, size INTEGER NOT NULL,"
    "  media_type TEXT NOT NULL, owner TEXT NOT NULL, created REAL NOT NULL);",
    /* 1 -> 2: bearer tokens (only their SHA-256 is stored, daemon/store/tokens.c);
     * an upload belongs to each owner who sent its bytes: one row per (id, owner) */
    "CREATE TABLE tokens ("
    "  name TEXT PRIMARY KEY, sha256 TEXT NOT NULL UNIQUE, admin INTEGER NOT NULL DEFAULT 0,"
    "  created REAL NOT NULL, last_used REAL);"
    "CREATE TABLE files_owned ("
    "  id TEXT NOT NULL, sha256 TEXT NOT NULL, size INTEGER NOT NULL,"
    "  media_type TEXT NOT NULL, owner TEXT NOT NULL, created REAL NOT NULL,"
    "  PRIMARY KEY (id, owner));"
    "INSERT INTO files_owned SELECT id, sha256, size, media_type, owner, created FROM files;"
    "DROP TABLE files;"
    "ALTER TABLE files_owned RENAME TO files;",
    /* 2 -> 3: job metrics that outlive the job rows (job_metrics.c): how many jobs
     * ended per process and final status, and a histogram of their run
     * times; both filled from the jobs already there.  duration_buckets
     * holds the histogram's upper bounds in seconds (9e999 is +Inf). */
    "CREATE TABLE job_counts ("
    "  process TEXT NOT NULL, status TEXT NOT NULL, n INTEGER NOT NULL,"
    "  PRIMARY KEY (process, status));"
    "CREATE TABLE duration_buckets (le REAL PRIMARY KEY);"
    "INSERT INTO duration_buckets VALUES (0.1), (0.5), (1), (2), (5), (10), (30), (60), (120),"
    "  (300), (600), (1800), (3600), (7200), (21600), (86400), (9e999);"
    "CREATE TABLE job_durations (" /* per bucket, not cumulative */
    "  process TEXT NOT NULL, le REAL NOT NULL, n INTEGER NOT NULL, secs REAL NOT NULL,"
    "  PRIMARY KEY (process, le));"
    "INSERT INTO job_counts(process, status, n) SELECT process, status, count(*) FROM jobs"
    "  WHERE status IN ('successful', 'failed', 'dismissed') GROUP BY process, status;"
    "INSERT INTO job_durations(process, le, n, secs)"
    "  SELECT process, (SELECT min(le) FROM duration_buckets WHERE le >= finished - started) AS b,"
    "  count(*), sum(finished - started) FROM jobs"
    "  WHERE started IS NOT NULL AND finished IS NOT NULL GROUP BY process, b;",
    /* 3 -> 4: the back end that holds a job outside this process
     * (daemon/executor.h): 'slurm:<job id>' while Slurm has it,
     * 'slurm:<job id>:ended' once its end is recorded; NULL for local jobs. */
    "ALTER TABLE jobs ADD COLUMN executor_ref TEXT;",
    /* 4 -> 5: the key under which a job's result may answer a later equal
     * request (daemon/result_cache.h); NULL for a job never to be reused. */
    ("ALTER TABLE jobs ADD COLUMN cache_key TEXT;"
     "CREATE INDEX jobs_by_cache_key ON jobs(cache_key, owner) WHERE cache_key IS NOT NULL;"),
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
        int ok = sqlite3_exec(db, "BEGIN IMMEDIATE", NULL, NULL, &msg) == SQLITE_OK;
        /* Another connection (the daemon, `packd token`) may have migrated meanwhile. */
        int now = ok ? user_version(db) : v;
        if (now > v && now <= pk_schema_version()) {
            sqlite3_exec(db, "COMMIT", NULL, NULL, NULL);
            v = now - 1;
            continue;
        }
        if (!ok || now != v || sqlite3_exec(db, steps[v], NULL, NULL, &msg) != SQLITE_OK ||
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

/* Drop the group-write and every other-account bit of an open file. */
static int tighten(int fd)
{
    struct stat st;
    if (fstat(fd, &st) != 0)
        return -1;
    return (st.st_mode & 0137) ? fchmod(fd, st.st_mode & 0640) : 0;
}

int pk_db_file_private(const char *path)
{
    int fd = open(path, O_RDWR | O_CREAT | O_CLOEXEC | O_NOFOLLOW, 0640);
    if (fd < 0)
        return -1;
    int rc = tighten(fd);
    close(fd);
    for (const char *const *sfx = (const char *const[]){"-wal", "-shm", NULL}; *sfx; sfx++) {
        char side[4200];
        snprintf(side, sizeof side, "%s%s", path, *sfx);
        int sf = open(side, O_RDWR | O_CLOEXEC | O_NOFOLLOW);
        if (sf >= 0) {
            tighten(sf);
            close(sf);
        }
    }
    return rc;
}

sqlite3 *pk_db_open(const char *path, char *err, size_t errlen)
{
    sqlite3 *db = NULL;
    if (pk_db_file_private(path) != 0) {
        snprintf(err, errlen, "%s: %s", path, strerror(errno));
        return NULL;
    }
    if (sqlite3_open_v2(path, &db, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE | SQLITE_OPEN_NOMUTEX,
                        NULL) != SQLITE_OK) {
        snprintf(err, errlen, "%s: %s", path, db ? sqlite3_errmsg(db) : "cannot open");
        sqlite3_close(db);
        return NULL;
    }
    /* WAL: readers never block the writer; FULL: a committed job survives a
     * power loss too; the busy timeout covers the other connections (the
     * daemon's queue and token store, `packd token`, the sqlite3 CLI, backups). */
    sqlite3_busy_timeout(db, 5000);
    char *msg = NULL;
    if (sqlite3_exec(db,
                     "PRAGMA journal_mode=WAL; PRAGMA synchronous=FULL; PRAGMA foreign_keys=ON;",
                     NULL, NULL, &msg) != SQLITE_OK ||
        pk_migrate(db, err, errlen) < 0) {
        if (msg)
            snprintf(err, errlen, "%s: %s", path, msg);
        sqlite3_free(msg);
        sqlite3_close(db);
        return NULL;
    }
    return db;
}

sqlite3 *pk_db_open_reader(const char *path, char *err, size_t errlen)
{
    sqlite3 *db = NULL;
    if (sqlite3_open_v2(path, &db, SQLITE_OPEN_READONLY | SQLITE_OPEN_NOMUTEX, NULL) != SQLITE_OK) {
        snprintf(err, errlen, "%s: reader: %s", path, db ? sqlite3_errmsg(db) : "cannot open");
        sqlite3_close(db);
        return NULL;
    }
    sqlite3_busy_timeout(db, 5000); /* only a WAL recovery or restart makes a reader wait */
    return db;
}
