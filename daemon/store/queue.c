/* queue.c — the durable job queue over one SQLite file: submit, claim,
 * progress, finish, events, uploads; contract in queue.h. */
#include "queue.h"

#include <errno.h>
#include <math.h>
#include <pthread.h>
#include <sqlite3.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "job_metrics.h"
#include "migrations.h"
#include "uuid.h"

/* Read-only connections (SQLITE_OPEN_READONLY), one per HTTP event-loop
 * thread at most: in WAL mode a read never waits on the writer's fsync, so
 * status polls stay fast while workers report progress. */
#define READERS 8

typedef struct reader {
    sqlite3 *db;
    pthread_mutex_t mu;
} reader;

struct pk_queue {
    sqlite3 *db;        /* the one writer */
    pthread_mutex_t mu; /* the writer's: held across a commit and its fsync */
    reader rd[READERS];
    unsigned rd_next;
    pthread_mutex_t ev_mu;
    pthread_cond_t ev_cond;
    long long ev_seq; /* bumped on every inserted event / state change */
    /* The last failed write (disk or database full, I/O error) until a
     * commit succeeds again: /healthz is not ready meanwhile.  Under
     * state_mu, never held across a write: /healthz never waits on one. */
    pthread_mutex_t state_mu;
    double write_failed_at, probed_at;
    char write_error[160];
    long long commits; /* transactions the writer committed (atomic) */
};

double pk_queue_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    return (double)ts.tv_sec + ts.tv_nsec * 1e-9;
}

/* Prepare on db and bind: types "s" text (NULL ok), "i" int, "I" long long,
 * "d" double. */
static sqlite3_stmt *vprep(sqlite3 *db, const char *sql, const char *types, va_list ap)
{
    sqlite3_stmt *st = NULL;
    if (sqlite3_prepare_v2(db, sql, -1, &st, NULL) != SQLITE_OK) {
        fprintf(stderr, "packd: sql error: %s in %s\n", sqlite3_errmsg(db), sql);
        return NULL;
    }
    for (int i = 0; types && types[i]; i++) {
        switch (types[i]) {
        case 's': {
            const char *s = va_arg(ap, const char *);
            if (s)
                sqlite3_bind_text(st, i + 1, s, -1, SQLITE_TRANSIENT);
            else
                sqlite3_bind_null(st, i + 1);
            break;
        }
        case 'i': sqlite3_bind_int(st, i + 1, va_arg(ap, int)); break;
        case 'I': sqlite3_bind_int64(st, i + 1, va_arg(ap, long long)); break;
        case 'd': sqlite3_bind_double(st, i + 1, va_arg(ap, double)); break;
        }
    }
    return st;
}

/* A statement on the writer connection (under q->mu). */
static sqlite3_stmt *prep(pk_queue *q, const char *sql, const char *types, ...)
{
    va_list ap;
    va_start(ap, types);
    sqlite3_stmt *st = vprep(q->db, sql, types, ap);
    va_end(ap);
    return st;
}

/* A statement on a reader connection (held by the caller). */
static sqlite3_stmt *rprep(reader *rd, const char *sql, const char *types, ...)
{
    va_list ap;
    va_start(ap, types);
    sqlite3_stmt *st = vprep(rd->db, sql, types, ap);
    va_end(ap);
    return st;
}

/* A free reader, or the next one in turn when all are busy. */
static reader *reader_take(pk_queue *q)
{
    unsigned start = __atomic_fetch_add(&q->rd_next, 1, __ATOMIC_RELAXED);
    for (unsigned i = 0; i < READERS; i++) {
        reader *rd = &q->rd[(start + i) % READERS];
        if (pthread_mutex_trylock(&rd->mu) == 0)
            return rd;
    }
    reader *rd = &q->rd[start % READERS];
    pthread_mutex_lock(&rd->mu);
    return rd;
}

static void reader_give(reader *rd) { pthread_mutex_unlock(&rd->mu); }

static void note_write(pk_queue *q, int ok);

/* Run a statement to completion; returns sqlite3_changes or -1. */
static int run(pk_queue *q, sqlite3_stmt *st)
{
    if (!st)
        return -1;
    int rc;
    while ((rc = sqlite3_step(st)) == SQLITE_ROW)
        ;
    sqlite3_finalize(st);
    if (rc != SQLITE_DONE) {
        fprintf(stderr, "packd: sql step: %s\n", sqlite3_errmsg(q->db));
        if ((rc & 0xff) == SQLITE_FULL || (rc & 0xff) == SQLITE_IOERR)
            note_write(q, 0);
        return -1;
    }
    return sqlite3_changes(q->db);
}

static long long scalar(pk_queue *q, sqlite3_stmt *st)
{
    long long v = -1;
    if (st && sqlite3_step(st) == SQLITE_ROW)
        v = sqlite3_column_int64(st, 0);
    sqlite3_finalize(st);
    return v;
}

/* One row as a JSON object; columns named inputs/summary/data are parsed JSON. */
static json_t *row_json(sqlite3_stmt *st)
{
    json_t *o = json_object();
    for (int c = 0; c < sqlite3_column_count(st); c++) {
        const char *name = sqlite3_column_name(st, c);
        json_t *v;
        switch (sqlite3_column_type(st, c)) {
        case SQLITE_INTEGER: v = json_integer(sqlite3_column_int64(st, c)); break;
        case SQLITE_FLOAT: v = json_real(sqlite3_column_double(st, c)); break;
        case SQLITE_NULL: v = json_null(); break;
        default: {
            const char *t = (const char *)sqlite3_column_text(st, c);
            if (!strcmp(name, "inputs") || !strcmp(name, "summary") || !strcmp(name, "data")) {
                v = json_loads(t, JSON_DECODE_ANY, NULL);
                if (!v)
                    v = json_string(t);
            } else {
                v = json_string(t);
            }
        }
        }
        json_object_set_new(o, name, v ? v : json_null());
    }
    return o;
}

static json_t *rows(sqlite3_stmt *st)
{
    json_t *a = json_array();
    while (st && sqlite3_step(st) == SQLITE_ROW)
        json_array_append_new(a, row_json(st));
    sqlite3_finalize(st);
    return a;
}

static json_t *one_row(sqlite3_stmt *st)
{
    json_t *a = rows(st), *r = json_array_size(a) ? json_incref(json_array_get(a, 0)) : NULL;
    json_decref(a);
    return r;
}

static void notify(pk_queue *q)
{
    pthread_mutex_lock(&q->ev_mu);
    q->ev_seq++;
    pthread_cond_broadcast(&q->ev_cond);
    pthread_mutex_unlock(&q->ev_mu);
}

static void add_event(pk_queue *q, const char *id, const char *kind, json_t *data)
{
    char *text = json_dumps(data, JSON_COMPACT);
    run(q,
        prep(q, "INSERT INTO events(job_id, kind, data, created) VALUES (?,?,?,?)", "sssd", id,
             kind, text ? text : "{}", pk_queue_now()));
    free(text);
}

/* The "status" event of a job, from its row (after a change). */
static void add_status_event(pk_queue *q, const char *id)
{
    json_t *d = one_row(
        prep(q, "SELECT status, progress, message, attempts FROM jobs WHERE id=?", "s", id));
    if (d) {
        add_event(q, id, "status", d);
        json_decref(d);
    }
}

static int begin(pk_queue *q) { return sqlite3_exec(q->db, "BEGIN IMMEDIATE", NULL, NULL, NULL); }

/* Remember whether the database takes writes (under q->mu). */
static void note_write(pk_queue *q, int ok)
{
    pthread_mutex_lock(&q->state_mu);
    if (ok) {
        q->write_failed_at = 0;
    } else {
        snprintf(q->write_error, sizeof q->write_error, "%s", sqlite3_errmsg(q->db));
        q->write_failed_at = pk_queue_now();
    }
    pthread_mutex_unlock(&q->state_mu);
}

/* 0 when committed; -1 (rolled back, remembered) otherwise. */
static int commit(pk_queue *q)
{
    int ok = sqlite3_exec(q->db, "COMMIT", NULL, NULL, NULL) == SQLITE_OK;
    note_write(q, ok);
    if (!ok)
        sqlite3_exec(q->db, "ROLLBACK", NULL, NULL, NULL);
    return ok ? 0 : -1;
}
static void rollback(pk_queue *q) { sqlite3_exec(q->db, "ROLLBACK", NULL, NULL, NULL); }

/* Every commit of the writer, explicit or autocommit: /metrics shows what
 * a poll cycle or a progress line costs the database. */
static int count_commit(void *arg)
{
    __atomic_add_fetch(&((pk_queue *)arg)->commits, 1, __ATOMIC_RELAXED);
    return 0;
}

long long pk_queue_transactions(pk_queue *q)
{
    return __atomic_load_n(&q->commits, __ATOMIC_RELAXED);
}

pk_queue *pk_queue_open(const char *path, char *err, size_t errlen)
{
    pk_queue *q = calloc(1, sizeof *q);
    if (!q) {
        snprintf(err, errlen, "out of memory");
        return NULL;
    }
    q->db = pk_db_open(path, err, errlen);
    if (!q->db) {
        free(q);
        return NULL;
    }
    sqlite3_commit_hook(q->db, count_commit, q);
    pthread_mutex_init(&q->mu, NULL);
    pthread_mutex_init(&q->state_mu, NULL);
    pthread_mutex_init(&q->ev_mu, NULL);
    pthread_cond_init(&q->ev_cond, NULL);
    for (int i = 0; i < READERS; i++)
        pthread_mutex_init(&q->rd[i].mu, NULL);
    for (int i = 0; i < READERS; i++) {
        /* after the writer: the file exists, is in WAL mode and migrated */
        q->rd[i].db = pk_db_open_reader(path, err, errlen);
        if (!q->rd[i].db) {
            pk_queue_close(q);
            return NULL;
        }
    }
    return q;
}

void pk_queue_close(pk_queue *q)
{
    if (!q)
        return;
    for (int i = 0; i < READERS; i++) {
        sqlite3_close(q->rd[i].db); /* NULL: a no-op */
        pthread_mutex_destroy(&q->rd[i].mu);
    }
    sqlite3_close(q->db);
    pthread_mutex_destroy(&q->mu);
    pthread_mutex_destroy(&q->state_mu);
    pthread_mutex_destroy(&q->ev_mu);
    pthread_cond_destroy(&q->ev_cond);
    free(q);
}

/* Inside an open transaction: PK_Q_EXISTING (id filled) or PK_Q_KEY_CONFLICT
 * when s's idempotency key was seen, rolled back; PK_Q_OK otherwise. */
static int seen_key(pk_queue *q, const pk_submit *s, char id[37])
{
    if (!s->idempotency_key)
        return PK_Q_OK;
    json_t *k =
        one_row(prep(q, "SELECT request_sha256, job_id FROM idempotency WHERE owner=? AND key=?",
                     "ss", s->owner, s->idempotency_key));
    if (!k)
        return PK_Q_OK;
    int same = !strcmp(json_string_value(json_object_get(k, "request_sha256")),
                       s->request_sha256 ? s->request_sha256 : "");
    snprintf(id, 37, "%s", json_string_value(json_object_get(k, "job_id")));
    json_decref(k);
    rollback(q);
    return same ? PK_Q_EXISTING : PK_Q_KEY_CONFLICT;
}

/* Inside an open transaction: the idempotency row of the new job id (if s
 * has a key), its status event, the commit.  A PK_Q_* code. */
static int submit_end(pk_queue *q, const pk_submit *s, const char *id, double now)
{
    if (s->idempotency_key &&
        run(q,
            prep(q,
                 "INSERT INTO idempotency(owner, key, request_sha256, job_id, created) VALUES "
                 "(?,?,?,?,?)",
                 "ssssd", s->owner, s->idempotency_key, s->request_sha256 ? s->request_sha256 : "",
                 id, now)) != 1) {
        int code = sqlite3_errcode(q->db);
        rollback(q);
        if (code == SQLITE_FULL || code == SQLITE_IOERR || code == SQLITE_READONLY) {
            note_write(q, 0);
            return PK_Q_UNWRITABLE;
        }
        return PK_Q_ERROR;
    }
    add_status_event(q, id);
    /* only a committed job is answered 201 */
    return commit(q) == 0 ? PK_Q_OK : PK_Q_UNWRITABLE;
}

/* The code of a failed INSERT of a job row (rolled back). */
static int insert_failed(pk_queue *q)
{
    int code = sqlite3_errcode(q->db);
    rollback(q);
    if (code == SQLITE_FULL || code == SQLITE_IOERR || code == SQLITE_READONLY) {
        note_write(q, 0);
        return PK_Q_UNWRITABLE;
    }
    return PK_Q_ERROR;
}

/* Take the writer and open a submission's transaction: PK_Q_OK, or the
 * code to answer (no transaction left open; the writer still held). */
static int submit_begin(pk_queue *q, const pk_submit *s, char id[37])
{
    pthread_mutex_lock(&q->mu);
    if (begin(q) != SQLITE_OK) {
        note_write(q, 0);
        return PK_Q_UNWRITABLE;
    }
    return seen_key(q, s, id);
}

/* Release the writer after a submission; a new job wakes the listeners. */
static int submit_done(pk_queue *q, int rc)
{
    pthread_mutex_unlock(&q->mu);
    if (rc == PK_Q_OK)
        notify(q);
    return rc;
}

int pk_queue_submit(pk_queue *q, const pk_submit *s, char id[37])
{
    int rc = submit_begin(q, s, id);
    if (rc != PK_Q_OK)
        goto out;
    if (scalar(q, prep(q, "SELECT count(*) FROM jobs WHERE status='accepted'", NULL)) >=
        s->max_queued) {
        rollback(q);
        rc = PK_Q_FULL;
        goto out;
    }
    if (scalar(q,
               prep(q, "SELECT count(*) FROM jobs WHERE owner=? AND status='accepted'", "s",
                    s->owner)) >= s->max_queued_per_owner) {
        rollback(q);
        rc = PK_Q_OWNER_FULL;
        goto out;
    }
    if (s->id && strlen(s->id) < 37)
        snprintf(id, 37, "%s", s->id);
    else if (pk_uuid4(id) != 0) {
        rollback(q);
        rc = PK_Q_ERROR;
        goto out;
    }
    double now = pk_queue_now();
    if (run(q,
            prep(q,
                 "INSERT INTO jobs(id, process, inputs, owner, status, message, created, updated,"
                 " cache_key) VALUES (?,?,?,?,'accepted','queued',?,?,?)",
                 "ssssdds", id, s->process, s->inputs_json, s->owner, now, now, s->cache_key)) !=
        1) {
        rc = insert_failed(q);
        goto out;
    }
    rc = submit_end(q, s, id, now);
out:
    return submit_done(q, rc);
}

int pk_queue_find_reusable(pk_queue *q, const char *key, const char *owner, double not_before,
                           char src[37])
{
    reader *rd = reader_take(q);
    json_t *r = one_row(rprep(rd,
                              "SELECT id FROM jobs WHERE cache_key=? AND owner=? AND"
                              " status='successful' AND finished >= ? AND"
                              " coalesce(json_extract(summary, '$.complete'), 1) != 0"
                              " ORDER BY finished DESC LIMIT 1",
                              "ssd", key, owner, not_before));
    reader_give(rd);
    const char *id = json_string_value(json_object_get(r, "id"));
    int found = id && strlen(id) < 37;
    if (found)
        snprintf(src, 37, "%s", id);
    json_decref(r);
    return found;
}

int pk_queue_submit_reused(pk_queue *q, const pk_submit *s, const char *src, char id[37])
{
    int rc = submit_begin(q, s, id);
    if (rc != PK_Q_OK)
        goto out;
    double now = pk_queue_now();
    char msg[120];
    snprintf(msg, sizeof msg, "the result of job %s (the same inputs and seed, run by this packd)",
             src);
    int n =
        run(q,
            prep(q,
                 "INSERT INTO jobs(id, process, inputs, owner, status, progress, message,"
                 " created, finished, updated, summary, result_sha256, result_size,"
                 " cache_key) SELECT ?, ?, ?, ?, 'successful', 100, ?, ?, ?, ?, summary,"
                 " result_sha256, result_size, cache_key FROM jobs"
                 " WHERE id=? AND status='successful'",
                 "sssssddds", id, s->process, s->inputs_json, s->owner, msg, now, now, now, src));
    if (n == 0) {
        rollback(q);
        rc = PK_Q_GONE;
        goto out;
    }
    if (n != 1) {
        rc = insert_failed(q);
        goto out;
    }
    pk_metrics_job_ended(q->db, id, "successful"); /* never started: no run time */
    rc = submit_end(q, s, id, now);
out:
    return submit_done(q, rc);
}

#define JOB_COLUMNS                                                                                \
    "id, process, inputs, owner, status, progress, message, created, started, "                    \
    "finished, updated, attempts, cancel_requested, worker_pid, rev, summary, "                    \
    "result_sha256, result_size, executor_ref"

json_t *pk_queue_get(pk_queue *q, const char *id)
{
    reader *rd = reader_take(q);
    json_t *r = one_row(rprep(rd, "SELECT " JOB_COLUMNS " FROM jobs WHERE id=?", "s", id));
    reader_give(rd);
    return r;
}

json_t *pk_queue_list(pk_queue *q, const pk_job_filter *f, int limit, int offset, int *total)
{
    /* Arrays are bound as JSON text and unpacked by json_each; a NaN bound
     * as a double is NULL in SQLite, so NAN means "no bound" below. */
    const char *where = " WHERE (?1 IS NULL OR status IN (SELECT value FROM json_each(?1)))"
                        " AND (?2 IS NULL OR process IN (SELECT value FROM json_each(?2)))"
                        " AND (?5 IS NULL OR owner=?5)"
                        " AND (?6 IS NULL OR created >= ?6) AND (?7 IS NULL OR created < ?7)"
                        " AND ((?8 IS NULL AND ?9 IS NULL) OR (started IS NOT NULL AND"
                        "  (finished IS NOT NULL OR status='running') AND"
                        "  coalesce(finished, ?10) - started BETWEEN coalesce(?8, -1e300) AND "
                        "coalesce(?9, 1e300)))";
    char sql[1024];
    double now = pk_queue_now();
    reader *rd = reader_take(q);
    snprintf(sql, sizeof sql, "SELECT count(*) FROM jobs%s", where);
    if (total)
        *total = (int)scalar(q,
                             rprep(rd, sql, "ssiisddddd", f->status_json, f->process_json, 0, 0,
                                   f->owner, f->created_from, f->created_before, f->min_duration,
                                   f->max_duration, now));
    snprintf(
        sql, sizeof sql,
        "SELECT id, process, status, progress, message, created, started, finished, updated, rev"
        " FROM jobs%s ORDER BY seq DESC LIMIT ?3 OFFSET ?4",
        where);
    json_t *r =
        rows(rprep(rd, sql, "ssiisddddd", f->status_json, f->process_json, limit, offset, f->owner,
                   f->created_from, f->created_before, f->min_duration, f->max_duration, now));
    reader_give(rd);
    return r;
}

json_t *pk_queue_claim(pk_queue *q) { return pk_queue_claim_by_wall(q, PK_CLAIM_ANY, 0); }

json_t *pk_queue_claim_by_wall(pk_queue *q, pk_claim which, double bound_s)
{
    json_t *r = NULL;
    pthread_mutex_lock(&q->mu);
    if (begin(q) != SQLITE_OK)
        goto out;
    /* a job a back end holds (executor_ref) is not claimable, even while accepted */
    json_t *next = one_row(
        prep(q,
             "SELECT id FROM jobs WHERE status='accepted' AND executor_ref IS NULL AND"
             " (?1=0 OR (coalesce(json_extract(inputs, '$.limits.wall_time_s') <= ?2, 0) = (?1=1)))"
             " ORDER BY seq LIMIT 1",
             "id", (int)which, bound_s));
    if (!next) {
        rollback(q);
        goto out;
    }
    const char *id = json_string_value(json_object_get(next, "id"));
    double now = pk_queue_now();
    /* The status condition makes the claim atomic: a job is running at most once. */
    if (run(q,
            prep(q,
                 "UPDATE jobs SET status='running', attempts=attempts+1, started=?, updated=?,"
                 " message='running', progress=0, rev=rev+1 WHERE id=? AND status='accepted'",
                 "dds", now, now, id)) == 1) {
        add_status_event(q, id);
        r = one_row(prep(q, "SELECT " JOB_COLUMNS " FROM jobs WHERE id=?", "s", id));
        commit(q);
    } else {
        rollback(q);
    }
    json_decref(next);
out:
    pthread_mutex_unlock(&q->mu);
    if (r)
        notify(q);
    return r;
}

void pk_queue_set_worker(pk_queue *q, const char *id, int pid)
{
    pthread_mutex_lock(&q->mu);
    run(q, prep(q, "UPDATE jobs SET worker_pid=? WHERE id=?", "is", pid, id));
    pthread_mutex_unlock(&q->mu);
}

void pk_queue_progress(pk_queue *q, const char *id, int percent, json_t *data)
{
    pthread_mutex_lock(&q->mu);
    const char *msg = json_string_value(json_object_get(data, "message"));
    if (begin(q) == SQLITE_OK) {
        if (run(q,
                prep(q,
                     "UPDATE jobs SET progress=?, message=coalesce(?, message), updated=?,"
                     " rev=rev+1 WHERE id=? AND status='running'",
                     "isds", percent, msg, pk_queue_now(), id)) == 1)
            add_event(q, id, "progress", data);
        commit(q);
    }
    pthread_mutex_unlock(&q->mu);
    notify(q);
}

static const char *finish_tx(pk_queue *q, const char *id, const char *status, const char *message,
                             const char *summary_json, const char *sha256, long long size);

const char *pk_queue_finish(pk_queue *q, const char *id, const char *status, const char *message,
                            const char *summary_json, const char *sha256, long long size)
{
    const char *ended = NULL; /* not recorded, unless the commit below succeeds */
    pthread_mutex_lock(&q->mu);
    if (begin(q) != SQLITE_OK) {
        note_write(q, 0);
    } else if (!(ended = finish_tx(q, id, status, message, summary_json, sha256, size))) {
        note_write(q, 0); /* the database took no write (full, I/O error) */
        rollback(q);
    } else if (commit(q) != 0) {
        ended = NULL;
    }
    pthread_mutex_unlock(&q->mu);
    notify(q);
    return ended;
}

/* pk_queue_finish inside an open transaction: the end recorded, "unchanged"
 * when the job is not ours to end, NULL when the database took no write. */
static const char *finish_tx(pk_queue *q, const char *id, const char *status, const char *message,
                             const char *summary_json, const char *sha256, long long size)
{
    const char *ended;
    double now = pk_queue_now();
    int n =
        run(q,
            prep(q,
                 "UPDATE jobs SET status=?, message=?, progress=CASE WHEN ?='successful'"
                 " THEN 100 ELSE progress END, finished=?, updated=?, summary=?,"
                 " result_sha256=?, result_size=?, worker_pid=NULL, rev=rev+1"
                 " WHERE id=? AND status='running'",
                 "sssddssIs", status, message, status, now, now, summary_json, sha256, size, id));
    if (n == 1) {
        ended = !strcmp(status, "successful") ? "successful" : "failed";
        pk_metrics_job_ended(q->db, id, ended);
    } else if (n == 0) {
        n = run(q,
                prep(q,
                     "UPDATE jobs SET finished=?, updated=?, worker_pid=NULL, rev=rev+1,"
                     " message='dismissed; worker stopped' WHERE id=? AND"
                     " status='dismissed' AND finished IS NULL",
                     "dds", now, now, id));
        if (n == 0)
            return "unchanged"; /* not ours to end */
        if (n != 1)
            return NULL;
        ended = "dismissed";
        pk_metrics_job_ended(q->db, id, "dismissed"); /* its worker stopped */
    } else {
        return NULL;
    }
    add_status_event(q, id);
    /* History stays small: of the progress events only the last is kept. */
    run(q,
        prep(q,
             "DELETE FROM events WHERE job_id=?1 AND kind='progress' AND id <"
             " (SELECT max(id) FROM events WHERE job_id=?1 AND kind='progress')",
             "s", id));
    return ended;
}

int pk_queue_dismiss(pk_queue *q, const char *id, char was[16])
{
    int rc = -1;
    pthread_mutex_lock(&q->mu);
    if (begin(q) != SQLITE_OK)
        goto out;
    json_t *r = one_row(prep(q, "SELECT status FROM jobs WHERE id=?", "s", id));
    if (!r) {
        rollback(q);
        goto out;
    }
    snprintf(was, 16, "%s", json_string_value(json_object_get(r, "status")));
    json_decref(r);
    double now = pk_queue_now();
    if (!strcmp(was, "running"))
        run(q,
            prep(q,
                 "UPDATE jobs SET status='dismissed', cancel_requested=1, message='dismissed;"
                 " stopping the worker', updated=?, rev=rev+1 WHERE id=?",
                 "ds", now, id));
    else if (strcmp(was, "dismissed") != 0)
        run(q,
            prep(q,
                 "UPDATE jobs SET status='dismissed', message='dismissed', updated=?,"
                 " finished=coalesce(finished, ?), rev=rev+1 WHERE id=?",
                 "dds", now, now, id));
    if (!strcmp(was, "accepted")) /* a finished job was counted when it ended */
        pk_metrics_job_ended(q->db, id, "dismissed");
    add_status_event(q, id);
    commit(q);
    rc = 0;
out:
    pthread_mutex_unlock(&q->mu);
    if (rc == 0)
        notify(q);
    return rc;
}

json_t *pk_queue_cancel_requests(pk_queue *q)
{
    pthread_mutex_lock(&q->mu);
    json_t *r = rows(prep(q,
                          "SELECT id, worker_pid FROM jobs WHERE cancel_requested=1 AND"
                          " finished IS NULL",
                          NULL));
    pthread_mutex_unlock(&q->mu);
    return r;
}

int pk_queue_recover(pk_queue *q, int max_attempts, int *failed)
{
    int requeued = 0;
    *failed = 0;
    pthread_mutex_lock(&q->mu);
    if (begin(q) == SQLITE_OK) {
        json_t *left = rows(prep(q,
                                 "SELECT id, attempts, status FROM jobs WHERE executor_ref IS NULL"
                                 " AND (status='running' OR (cancel_requested=1 AND"
                                 " finished IS NULL))",
                                 NULL));
        double now = pk_queue_now();
        size_t i;
        json_t *r;
        json_array_foreach (left, i, r) {
            const char *id = json_string_value(json_object_get(r, "id"));
            if (strcmp(json_string_value(json_object_get(r, "status")), "running") != 0) {
                run(q,
                    prep(q, "UPDATE jobs SET finished=?, worker_pid=NULL WHERE id=?", "ds", now,
                         id));
                pk_metrics_job_ended(q->db, id, "dismissed");
                continue;
            }
            int attempts = (int)json_integer_value(json_object_get(r, "attempts"));
            if (attempts < max_attempts) {
                run(q,
                    prep(q,
                         "UPDATE jobs SET status='accepted', worker_pid=NULL, progress=0,"
                         " message='re-queued after the daemon stopped (attempt ' || attempts || "
                         "')',"
                         " updated=?, rev=rev+1 WHERE id=?",
                         "ds", now, id));
                requeued++;
            } else {
                run(q,
                    prep(q,
                         "UPDATE jobs SET status='failed', worker_pid=NULL, finished=?, updated=?,"
                         " message='interrupted ' || attempts || ' times by daemon restarts; not"
                         " retried', rev=rev+1 WHERE id=?",
                         "dds", now, now, id));
                pk_metrics_job_ended(q->db, id, "failed");
                (*failed)++;
            }
            add_status_event(q, id);
        }
        json_decref(left);
        commit(q);
    }
    pthread_mutex_unlock(&q->mu);
    return requeued;
}

void pk_queue_requeue(pk_queue *q, const char *id, const char *why)
{
    pthread_mutex_lock(&q->mu);
    if (begin(q) == SQLITE_OK) {
        if (run(q,
                prep(q,
                     "UPDATE jobs SET status='accepted', attempts=max(attempts-1, 0),"
                     " worker_pid=NULL, progress=0, message=?, updated=?, rev=rev+1"
                     " WHERE id=? AND status='running'",
                     "sds", why, pk_queue_now(), id)) == 1)
            add_status_event(q, id);
        commit(q);
    }
    pthread_mutex_unlock(&q->mu);
    notify(q);
}

json_t *pk_queue_events(pk_queue *q, const char *id, long long after, int limit)
{
    reader *rd = reader_take(q);
    json_t *r = rows(rprep(rd,
                           "SELECT id, kind, data FROM events WHERE job_id=? AND id>? ORDER BY id"
                           " LIMIT ?",
                           "sIi", id, after, limit));
    reader_give(rd);
    return r;
}

json_t *pk_queue_status_events(pk_queue *q, long long after, int limit)
{
    reader *rd = reader_take(q);
    json_t *r = after < 0
        ? one_row(rprep(rd, "SELECT coalesce(max(id), 0) AS id FROM events", NULL))
        : rows(rprep(rd,
                     "SELECT id, job_id, data FROM events WHERE kind='status'"
                     " AND id>? ORDER BY id LIMIT ?",
                     "Ii", after, limit));
    reader_give(rd);
    return r;
}

long long pk_queue_event_seq(pk_queue *q)
{
    pthread_mutex_lock(&q->ev_mu);
    long long s = q->ev_seq;
    pthread_mutex_unlock(&q->ev_mu);
    return s;
}

long long pk_queue_wait_event(pk_queue *q, long long seen, int timeout_ms)
{
    struct timespec until;
    clock_gettime(CLOCK_REALTIME, &until);
    until.tv_sec += timeout_ms / 1000;
    until.tv_nsec += (long)(timeout_ms % 1000) * 1000000L;
    if (until.tv_nsec >= 1000000000L) {
        until.tv_sec++;
        until.tv_nsec -= 1000000000L;
    }
    pthread_mutex_lock(&q->ev_mu);
    while (q->ev_seq == seen)
        if (pthread_cond_timedwait(&q->ev_cond, &q->ev_mu, &until) == ETIMEDOUT)
            break;
    long long s = q->ev_seq;
    pthread_mutex_unlock(&q->ev_mu);
    return s;
}

void pk_queue_wake_all(pk_queue *q) { notify(q); }

json_t *pk_queue_stats(pk_queue *q)
{
    reader *rd = reader_take(q);
    json_t *by = rows(rprep(rd, "SELECT status, count(*) AS n FROM jobs GROUP BY status", NULL));
    int ok = scalar(q, rprep(rd, "SELECT count(*) FROM jobs", NULL)) >= 0; /* it answers */
    json_t *metrics = pk_metrics_read(rd->db);
    reader_give(rd);
    json_t *jobs = json_object();
    const char *all[] = {"accepted", "running", "successful", "failed", "dismissed"};
    for (size_t i = 0; i < 5; i++)
        json_object_set_new(jobs, all[i], json_integer(0));
    size_t i;
    json_t *r;
    json_array_foreach (by, i, r) {
        const char *st = json_string_value(json_object_get(r, "status"));
        json_object_set(jobs, st, json_object_get(r, "n"));
    }
    json_decref(by);
    json_object_set_new(metrics, "jobs", jobs);
    json_object_set_new(metrics, "ok", json_boolean(ok));
    return metrics;
}

/* While writes fail, a write as large as a job's end with its summary and
 * events (PROBE_BYTES, committed, then deleted) is tried at most once a
 * second: the state clears only when such a write commits, so space freed
 * makes /healthz ready by itself and a write that merely fits in the WAL's
 * slack does not. */
#define PROBE_BYTES 16384

static void probe_write(pk_queue *q)
{
    const char *sql[] = {"INSERT INTO events(job_id, kind, data, created)"
                         " VALUES ('', 'probe', hex(zeroblob(?)), 0)",
                         "DELETE FROM events WHERE job_id='' AND kind='probe'"};
    for (int i = 0; i < 2; i++) {
        if (begin(q) != SQLITE_OK) {
            note_write(q, 0);
            return;
        }
        if (run(q, prep(q, sql[i], i ? NULL : "i", PROBE_BYTES / 2)) < 0) {
            note_write(q, 0);
            rollback(q);
            return;
        }
        if (commit(q) != 0)
            return;
    }
}

int pk_queue_writable(pk_queue *q, char *why, size_t n)
{
    double now = pk_queue_now();
    pthread_mutex_lock(&q->state_mu);
    int probe = q->write_failed_at > 0 && now - q->probed_at >= 1.0;
    if (probe)
        q->probed_at = now;
    pthread_mutex_unlock(&q->state_mu);
    /* a writer busy now reports its own outcome: no waiting for it */
    if (probe && pthread_mutex_trylock(&q->mu) == 0) {
        probe_write(q);
        pthread_mutex_unlock(&q->mu);
    }
    pthread_mutex_lock(&q->state_mu);
    int ok = q->write_failed_at == 0;
    if (!ok)
        snprintf(why, n, "%s; last failed write %.0f s ago", q->write_error,
                 fmax(now - q->write_failed_at, 0));
    pthread_mutex_unlock(&q->state_mu);
    return ok;
}

int pk_queue_add_file(pk_queue *q, const char *id, const char *sha256, long long size,
                      const char *media_type, const char *owner)
{
    pthread_mutex_lock(&q->mu);
    int n = run(q,
                prep(q,
                     "INSERT OR IGNORE INTO files(id, sha256, size, media_type, owner, created)"
                     " VALUES (?,?,?,?,?,?)",
                     "ssIssd", id, sha256, size, media_type, owner, pk_queue_now()));
    pthread_mutex_unlock(&q->mu);
    return n < 0 ? -1 : 0;
}

json_t *pk_queue_get_file(pk_queue *q, const char *id, const char *owner)
{
    reader *rd = reader_take(q);
    json_t *r = one_row(rprep(rd,
                              "SELECT id, sha256, size, media_type, created FROM files WHERE id=?1"
                              " AND (?2 IS NULL OR owner=?2) LIMIT 1",
                              "ss", id, owner));
    reader_give(rd);
    return r;
}

json_t *pk_queue_held_jobs(pk_queue *q, const char *backend)
{
    pthread_mutex_lock(&q->mu);
    json_t *r = rows(prep(q,
                          "SELECT id, process, status, attempts, progress, message, owner, inputs,"
                          " executor_ref FROM jobs WHERE executor_ref LIKE ?1 || ':%' AND"
                          " executor_ref NOT LIKE '%:ended' ORDER BY seq",
                          "s", backend));
    pthread_mutex_unlock(&q->mu);
    return r;
}

/* One change of pk_queue_sync inside its transaction; 1 when a status or
 * progress event was added. */
static int sync_one(pk_queue *q, json_t *c, double now)
{
    const char *id = json_string_value(json_object_get(c, "id"));
    const char *op = json_string_value(json_object_get(c, "op"));
    const char *msg = json_string_value(json_object_get(c, "message"));
    const char *ref = json_string_value(json_object_get(c, "ref"));
    int attempts = (int)json_integer_value(json_object_get(c, "attempts"));
    if (!id || !op)
        return 0;
    if (ref)
        run(q, prep(q, "UPDATE jobs SET executor_ref=? WHERE id=?", "ss", ref, id));
    if (!strcmp(op, "queued") || !strcmp(op, "running")) {
        int queued = op[0] == 'q';
        /* attempts 0: keep; a change of status or message is a status event */
        int n =
            run(q,
                prep(q,
                     "UPDATE jobs SET status=?1, message=?2,"
                     " attempts=CASE WHEN ?3>0 THEN ?3 ELSE attempts END,"
                     " started=CASE WHEN ?1='running' THEN coalesce(started, ?4) ELSE"
                     " started END, updated=?4, rev=rev+1 WHERE id=?5 AND status IN"
                     " ('accepted','running') AND (status<>?1 OR message<>?2 OR"
                     " (?3>0 AND attempts<>?3))",
                     "ssids", queued ? "accepted" : "running", msg ? msg : "", attempts, now, id));
        if (n == 1)
            add_status_event(q, id);
        json_t *data = json_object_get(c, "progress");
        if (!queued && json_is_object(data)) {
            json_int_t pct = json_integer_value(json_object_get(data, "progress"));
            if (run(q,
                    prep(q,
                         "UPDATE jobs SET progress=?, updated=?, rev=rev+1 WHERE id=? AND"
                         " status='running' AND progress<>?",
                         "idsi", (int)pct, now, id, (int)pct)) == 1) {
                add_event(q, id, "progress", data);
                n = 1;
            }
        }
        return n == 1;
    }
    if (!strcmp(op, "finish")) {
        run(q,
            prep(q,
                 "UPDATE jobs SET status='running', started=coalesce(started, ?) WHERE id=?"
                 " AND status='accepted'",
                 "ds", now, id));
        const char *sum = json_string_value(json_object_get(c, "summary"));
        const char *sha = json_string_value(json_object_get(c, "sha256"));
        const char *status = json_string_value(json_object_get(c, "status"));
        /* NULL: not written; the job stays running and the next cycle ends it again */
        const char *e = finish_tx(q, id, status ? status : "failed", msg ? msg : "", sum, sha,
                                  json_integer_value(json_object_get(c, "size")));
        return e && strcmp(e, "unchanged") != 0;
    }
    if (!strcmp(op, "requeue")) {
        if (run(q,
                prep(q,
                     "UPDATE jobs SET status='accepted', attempts=max(attempts-1, 0),"
                     " progress=0, message=?, updated=?, rev=rev+1 WHERE id=? AND"
                     " status='running' AND executor_ref IS NULL",
                     "sds", msg ? msg : "re-queued", now, id)) == 1) {
            add_status_event(q, id);
            return 1;
        }
    }
    return 0;
}

int pk_queue_sync(pk_queue *q, json_t *changes)
{
    if (!json_array_size(changes))
        return 0;
    int events = 0, rc = -1;
    double now = pk_queue_now();
    pthread_mutex_lock(&q->mu);
    if (begin(q) == SQLITE_OK) {
        size_t i;
        json_t *c;
        json_array_foreach (changes, i, c)
            events += sync_one(q, c, now);
        rc = commit(q);
    }
    pthread_mutex_unlock(&q->mu);
    if (events)
        notify(q);
    return rc;
}
