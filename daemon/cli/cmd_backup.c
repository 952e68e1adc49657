/* cmd_backup.c — `packd backup FILE [--data DIR | --config F]`: an online
 * copy of the service's queue database (jobs, events, counters, tokens) with
 * SQLite's backup API, safe while the daemon runs: the copy is one read
 * transaction (WAL: the daemon keeps writing meanwhile, the copy is the
 * snapshot at its start), written to FILE.tmp, checked with
 * PRAGMA integrity_check and renamed to FILE.  Result files (DATA/jobs/) are
 * plain files: copy them with any file tool (docs/operations.md). */
#include <sqlite3.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

#include "cli.h"
#include "daemon/config.h"
#include "daemon/store/migrations.h"

void cmd_backup_help(const char *name, FILE *f)
{
    (void)name;
    fprintf(
        f,
        "usage: packd backup FILE [--data DIR | --config F]\n"
        "Copy the service's database (DIR/queue.db; DIR from --data, else the config file's\n"
        "`data`, else $PACKD_DATA, else ./var) to FILE while the service runs, check the copy\n"
        "(PRAGMA integrity_check) and print {\"backup\", \"pages\", \"bytes\", \"jobs\", ...}.\n"
        "Restore: stop the service, copy FILE to DIR/queue.db, remove DIR/queue.db-wal and\n"
        "DIR/queue.db-shm, start the service.\n");
}

static long long scalar(sqlite3 *db, const char *sql)
{
    sqlite3_stmt *st;
    long long v = -1;
    if (sqlite3_prepare_v2(db, sql, -1, &st, NULL) == SQLITE_OK && sqlite3_step(st) == SQLITE_ROW)
        v = sqlite3_column_int64(st, 0);
    sqlite3_finalize(st);
    return v;
}

/* Copy src into dst in one step: a step restarts when another connection
 * writes between steps, one step reads a single snapshot.  A busy database
 * (a checkpoint, a recovery) is waited for and retried. */
static int copy(sqlite3 *src, sqlite3 *dst, int *pages, char *err, size_t errlen)
{
    sqlite3_backup *b = sqlite3_backup_init(dst, "main", src, "main");
    if (!b) {
        snprintf(err, errlen, "%s", sqlite3_errmsg(dst));
        return -1;
    }
    int rc, waits = 0;
    while ((rc = sqlite3_backup_step(b, -1)) == SQLITE_OK || rc == SQLITE_BUSY ||
           rc == SQLITE_LOCKED) {
        if (rc != SQLITE_OK) {
            if (++waits > 600) /* 30 s */
                break;
            sqlite3_sleep(50);
        }
    }
    *pages = sqlite3_backup_pagecount(b);
    sqlite3_backup_finish(b);
    if (rc != SQLITE_DONE) {
        snprintf(err, errlen, "backup step: %s", sqlite3_errstr(rc));
        return -1;
    }
    return 0;
}

int cmd_backup(int argc, char **argv)
{
    if (argc < 2 || argv[1][0] == '-') {
        fprintf(stderr, "usage: packd backup FILE [--data DIR | --config F]\n");
        return 64;
    }
    const char *out = argv[1];
    /* the remaining flags are the daemon's own (--data, --config, ...) */
    char *rest[64];
    int n = 0;
    rest[n++] = argv[0];
    for (int i = 2; i < argc && n < 63; i++)
        rest[n++] = argv[i];
    rest[n] = NULL;
    pk_config cfg;
    char err[1200];
    if (pk_config_from_args(&cfg, n, rest, err, sizeof err) != 0) {
        fprintf(stderr, "packd backup: %s\n", err);
        return 64;
    }
    char src_path[1100], tmp[4200];
    snprintf(src_path, sizeof src_path, "%s/queue.db", cfg.data);
    snprintf(tmp, sizeof tmp, "%s.tmp", out);
    sqlite3 *src = NULL, *dst = NULL;
    int rc = 2, pages = 0;
    /* read-write without create: a WAL database needs its -shm, and a
     * missing database is an error, not a new empty one */
    if (sqlite3_open_v2(src_path, &src, SQLITE_OPEN_READWRITE, NULL) != SQLITE_OK) {
        fprintf(stderr, "packd backup: %s: %s\n", src_path,
                src ? sqlite3_errmsg(src) : "cannot open");
        goto out;
    }
    sqlite3_busy_timeout(src, 5000);
    remove(tmp);
    /* the copy holds inputs, owners and token hashes: 0640 at most, as the database */
    if (pk_db_file_private(tmp) != 0 ||
        sqlite3_open_v2(tmp, &dst, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE, NULL) != SQLITE_OK) {
        fprintf(stderr, "packd backup: %s: %s\n", tmp, dst ? sqlite3_errmsg(dst) : "cannot open");
        goto out;
    }
    if (copy(src, dst, &pages, err, sizeof err) != 0) {
        fprintf(stderr, "packd backup: %s\n", err);
        goto out;
    }
    /* one self-contained file: the copy does not need a -wal beside it */
    sqlite3_exec(dst, "PRAGMA journal_mode=DELETE", NULL, NULL, NULL);
    sqlite3_stmt *st;
    char integrity[200] = "?";
    if (sqlite3_prepare_v2(dst, "PRAGMA integrity_check", -1, &st, NULL) == SQLITE_OK &&
        sqlite3_step(st) == SQLITE_ROW)
        snprintf(integrity, sizeof integrity, "%s", (const char *)sqlite3_column_text(st, 0));
    sqlite3_finalize(st);
    if (strcmp(integrity, "ok") != 0) {
        fprintf(stderr, "packd backup: the copy fails its integrity check: %s\n", integrity);
        goto out;
    }
    long long version = scalar(dst, "PRAGMA user_version"),
              jobs = scalar(dst, "SELECT count(*) FROM jobs");
    sqlite3_close(dst);
    dst = NULL;
    if (rename(tmp, out) != 0) {
        perror(out);
        goto out;
    }
    struct stat sb;
    stat(out, &sb);
    printf("{\"backup\": \"%s\", \"database\": \"%s\", \"pages\": %d, \"bytes\": %lld, "
           "\"schema_version\": %lld, \"jobs\": %lld, \"integrity\": \"ok\"}\n",
           out, src_path, pages, (long long)sb.st_size, version, jobs);
    rc = 0;
out:
    sqlite3_close(dst);
    sqlite3_close(src);
    if (rc)
        remove(tmp);
    return rc;
}
