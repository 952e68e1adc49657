/* migrations.h — the queue database schema, versioned with PRAGMA user_version. */
#ifndef PK_MIGRATIONS_H
#define PK_MIGRATIONS_H

#include <sqlite3.h>
#include <stddef.h>

/* Bring the database to the newest schema version, one transaction per step.
 * Returns the version reached, or -1 with err (e.g. a database newer than
 * this binary). */
int pk_migrate(sqlite3 *db, char *err, size_t errlen);

/* The newest schema version this binary knows. */
int pk_schema_version(void);

/* The database file path, created if missing, 0640 at most (a looser one,
 * and its -wal and -shm, are tightened) whoever creates it first and
 * whatever the umask: SQLite gives the -wal and -shm it creates the
 * database's mode.  0, or -1 with errno. */
int pk_db_file_private(const char *path);

/* Open (create) the queue database with its pragmas and migrate it: every
 * connection to DATA/queue.db goes through here.  NULL with err. */
sqlite3 *pk_db_open(const char *path, char *err, size_t errlen);

/* A read-only connection (SQLITE_OPEN_READONLY) to a database pk_db_open
 * made: in WAL mode its reads see the last commit and never wait on the
 * writer's lock or fsync.  NULL with err. */
sqlite3 *pk_db_open_reader(const char *path, char *err, size_t errlen);

#endif
