/* test_queue.c — daemon/store/queue.c on a real SQLite file: submission limits,
 * idempotency keys, atomic claims, events, dismissal, recovery after a daemon
 * death (bounded attempts), concurrent writers through two connections, a
 * finished job's result reused for an equal request. */
#include <math.h>
#include <pthread.h>
#include <sqlite3.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "daemon/store/migrations.h"
#include "daemon/store/queue.h"

static char dir[] = "/tmp/pk_queue_XXXXXX";
static char db[256];

static pk_queue *fresh(void)
{
    static int n;
    snprintf(db, sizeof db, "%s/q%d.db", dir, n++);
    char err[256];
    pk_queue *q = pk_queue_open(db, err, sizeof err);
    CHECK_MSG(q != NULL, "%s", err);
    return q;
}

static int submit(pk_queue *q, const char *owner, const char *key, const char *fp, char id[37])
{
    pk_submit s = {.process = "pack",
                   .inputs_json = "{\"dim\":2}",
                   .owner = owner,
                   .idempotency_key = key,
                   .request_sha256 = fp,
                   .max_queued = 5,
                   .max_queued_per_owner = 3};
    return pk_queue_submit(q, &s, id);
}

static const char *str(json_t *row, const char *k)
{
    return json_string_value(json_object_get(row, k));
}

static void test_schema_version(void)
{
    pk_queue *q = fresh();
    pk_queue_close(q);
    sqlite3 *h;
    sqlite3_open(db, &h);
    sqlite3_stmt *st;
    sqlite3_prepare_v2(h, "PRAGMA user_version", -1, &st, NULL);
    CHECK(sqlite3_step(st) == SQLITE_ROW && sqlite3_column_int(st, 0) == pk_schema_version());
    sqlite3_finalize(st);
    sqlite3_prepare_v2(h, "PRAGMA journal_mode", -1, &st, NULL);
    CHECK(sqlite3_step(st) == SQLITE_ROW &&
          !strcmp((const char *)sqlite3_column_text(st, 0), "wal"));
    sqlite3_finalize(st);
    /* a database from a newer packd is refused, not silently used */
    sqlite3_exec(h, "PRAGMA user_version = 999", NULL, NULL, NULL);
    sqlite3_close(h);
    char err[256];
    CHECK(pk_queue_open(db, err, sizeof err) == NULL && strstr(err, "newer"));
}

static void test_submit_limits_and_keys(void)
{
    pk_queue *q = fresh();
    char a[37], b[37], c[37];
    CHECK(submit(q, "ann", "k1", "fpA", a) == PK_Q_OK);
    CHECK(submit(q, "ann", "k1", "fpA", b) == PK_Q_EXISTING && !strcmp(a, b));
    CHECK(submit(q, "ann", "k1", "fpB", c) == PK_Q_KEY_CONFLICT && !strcmp(a, c));
    CHECK(submit(q, "bob", "k1", "fpA", c) == PK_Q_OK && strcmp(a, c)); /* keys are per owner */
    CHECK(submit(q, "ann", NULL, NULL, b) == PK_Q_OK);
    CHECK(submit(q, "ann", NULL, NULL, b) == PK_Q_OK);
    CHECK(submit(q, "ann", NULL, NULL, b) == PK_Q_OWNER_FULL); /* 3 of ann waiting */
    CHECK(submit(q, "cid", NULL, NULL, b) == PK_Q_OK);
    CHECK(submit(q, "dan", NULL, NULL, b) == PK_Q_FULL); /* 5 waiting in all */
    int total = 0;
    pk_job_filter acc = {.status_json = "[\"accepted\"]",
                         .created_from = NAN,
                         .created_before = NAN,
                         .min_duration = NAN,
                         .max_duration = NAN};
    json_t *l = pk_queue_list(q, &acc, 2, 0, &total);
    CHECK(total == 5 && json_array_size(l) == 2);
    json_decref(l);
    pk_queue_close(q);
}

static void test_claim_run_finish(void)
{
    pk_queue *q = fresh();
    char a[37], b[37];
    submit(q, "ann", NULL, NULL, a);
    submit(q, "ann", NULL, NULL, b);
    json_t *j1 = pk_queue_claim(q), *j2 = pk_queue_claim(q), *j3 = pk_queue_claim(q);
    CHECK(j1 && j2 && !j3);
    CHECK(!strcmp(str(j1, "id"), a) && !strcmp(str(j2, "id"), b)); /* FIFO */
    CHECK(json_integer_value(json_object_get(j1, "attempts")) == 1);
    CHECK(json_is_object(json_object_get(j1, "inputs")));
    for (int k = 1; k <= 3; k++) {
        json_t *p = json_pack("{s:s,s:f}", "stage", "rsa", "fraction", 0.25 * k);
        pk_queue_progress(q, a, 25 * k, p);
        json_decref(p);
    }
    CHECK(!strcmp(pk_queue_finish(q, a, "successful", "finished", "{\"n\":1}", "ab", 12),
                  "successful"));
    json_t *row = pk_queue_get(q, a);
    CHECK(!strcmp(str(row, "status"), "successful") &&
          json_integer_value(json_object_get(row, "progress")) == 100);
    CHECK(json_integer_value(json_object_get(json_object_get(row, "summary"), "n")) == 1);
    json_decref(row);
    /* finishing twice does not resurrect or change a final job */
    CHECK(!strcmp(pk_queue_finish(q, a, "failed", "late", NULL, NULL, 0), "unchanged"));
    row = pk_queue_get(q, a);
    CHECK(!strcmp(str(row, "status"), "successful") && !strcmp(str(row, "message"), "finished"));
    json_decref(row);
    json_t *ev = pk_queue_events(q, a, 0, 100);
    /* accepted, running, the last of 3 progress events, successful */
    CHECK(json_array_size(ev) == 4);
    CHECK(!strcmp(str(json_array_get(ev, 0), "kind"), "status"));
    CHECK(!strcmp(str(json_array_get(ev, 2), "kind"), "progress"));
    CHECK(json_number_value(
              json_object_get(json_object_get(json_array_get(ev, 2), "data"), "fraction")) == 0.75);
    long long first = json_integer_value(json_object_get(json_array_get(ev, 0), "id"));
    json_t *later = pk_queue_events(q, a, first, 100); /* SSE resume */
    CHECK(json_array_size(later) == json_array_size(ev) - 1);
    json_decref(later);
    json_decref(ev);
    json_decref(j1);
    json_decref(j2);
    json_decref(j3);
    pk_queue_close(q);
}

static void test_dismiss_running(void)
{
    pk_queue *q = fresh();
    char a[37], was[16];
    submit(q, "ann", NULL, NULL, a);
    json_decref(pk_queue_claim(q));
    CHECK(pk_queue_dismiss(q, a, was) == 0 && !strcmp(was, "running"));
    json_t *req = pk_queue_cancel_requests(q);
    CHECK(json_array_size(req) == 1 && !strcmp(str(json_array_get(req, 0), "id"), a));
    json_decref(req);
    CHECK(!strcmp(pk_queue_finish(q, a, "successful", "x", NULL, NULL, 0), "dismissed"));
    req = pk_queue_cancel_requests(q);
    CHECK(json_array_size(req) == 0);
    json_decref(req);
    CHECK(pk_queue_dismiss(q, "no-such-id", was) == -1);
    pk_queue_close(q);
}

static void test_recover_bounded(void)
{
    pk_queue *q = fresh();
    char a[37];
    submit(q, "ann", NULL, NULL, a);
    int failed;
    for (int attempt = 1; attempt <= 2; attempt++) { /* the daemon dies twice mid-run */
        json_t *j = pk_queue_claim(q);
        CHECK(j != NULL);
        json_decref(j);
        CHECK(pk_queue_recover(q, 3, &failed) == 1 && failed == 0);
    }
    json_decref(pk_queue_claim(q)); /* third start, third death */
    CHECK(pk_queue_recover(q, 3, &failed) == 0 && failed == 1);
    json_t *row = pk_queue_get(q, a);
    CHECK(!strcmp(str(row, "status"), "failed") &&
          json_integer_value(json_object_get(row, "attempts")) == 3);
    json_decref(row);
    /* a graceful re-queue gives the start back */
    char b[37];
    submit(q, "ann", NULL, NULL, b);
    json_decref(pk_queue_claim(q));
    pk_queue_requeue(q, b, "shutdown");
    row = pk_queue_get(q, b);
    CHECK(!strcmp(str(row, "status"), "accepted") &&
          json_integer_value(json_object_get(row, "attempts")) == 0);
    json_decref(row);
    pk_queue_close(q);
}

/* Two connections (two daemons' worth of writers) on one file: every
 * submission lands once, every job is claimed once. */
typedef struct {
    pk_queue *q;
    int n, claimed;
    char owner[8];
} worker_arg;

static void *submit_and_claim(void *p)
{
    worker_arg *w = p;
    for (int i = 0; i < w->n; i++) {
        char id[37], key[32];
        snprintf(key, sizeof key, "key-%d", i % 10); /* 10 distinct keys per owner */
        pk_submit s = {.process = "pack",
                       .inputs_json = "{}",
                       .owner = w->owner,
                       .idempotency_key = key,
                       .request_sha256 = "same",
                       .max_queued = 1000,
                       .max_queued_per_owner = 1000};
        int rc = pk_queue_submit(w->q, &s, id);
        if (rc != PK_Q_OK && rc != PK_Q_EXISTING)
            return (void *)1;
        json_t *j = pk_queue_claim(w->q);
        if (j)
            w->claimed++;
        json_decref(j);
    }
    return NULL;
}

static void test_concurrent_connections(void)
{
    pk_queue *q1 = fresh();
    char err[256];
    pk_queue *q2 = pk_queue_open(db, err, sizeof err);
    CHECK(q2 != NULL);
    worker_arg w[4] = {{q1, 40, 0, "a"}, {q2, 40, 0, "a"}, {q1, 40, 0, "b"}, {q2, 40, 0, "b"}};
    pthread_t th[4];
    for (int i = 0; i < 4; i++)
        pthread_create(&th[i], NULL, submit_and_claim, &w[i]);
    int bad = 0;
    for (int i = 0; i < 4; i++) {
        void *r;
        pthread_join(th[i], &r);
        bad |= r != NULL;
    }
    CHECK(!bad);
    int total = 0;
    pk_job_filter all = {
        .created_from = NAN, .created_before = NAN, .min_duration = NAN, .max_duration = NAN};
    json_decref(pk_queue_list(q1, &all, 1, 0, &total));
    CHECK_MSG(total == 20, "jobs = %d (2 owners x 10 keys)", total);
    CHECK(w[0].claimed + w[1].claimed + w[2].claimed + w[3].claimed == 20);
    pk_queue_close(q1);
    pk_queue_close(q2);
}

/* A job run to an end with summary sum, under cache key k. */
static void run_keyed(pk_queue *q, const char *owner, const char *k, const char *sum, char id[37])
{
    pk_submit s = {.process = "pack",
                   .inputs_json = "{\"dim\":2}",
                   .owner = owner,
                   .cache_key = k,
                   .max_queued = 5,
                   .max_queued_per_owner = 3};
    CHECK(pk_queue_submit(q, &s, id) == PK_Q_OK);
    json_decref(pk_queue_claim(q));
    CHECK(!strcmp(pk_queue_finish(q, id, "successful", "done", sum, "ab", 12), "successful"));
}

static void test_reuse(void)
{
    pk_queue *q = fresh();
    char a[37], shortrun[37], src[37], r[37] = "00000000-0000-4000-8000-000000000001";
    run_keyed(q, "ann", "K", "{\"complete\":true}", a);
    run_keyed(q, "ann", "K2", "{\"complete\":false}", shortrun);
    CHECK(pk_queue_find_reusable(q, "K", "ann", 0, src) == 1 && !strcmp(src, a));
    CHECK(pk_queue_find_reusable(q, "K", "bob", 0, src) == 0);  /* another owner's */
    CHECK(pk_queue_find_reusable(q, "K2", "ann", 0, src) == 0); /* stopped short */
    CHECK(pk_queue_find_reusable(q, "K", "ann", pk_queue_now() + 1, src) == 0); /* too old */
    pk_submit s = {.process = "pack",
                   .inputs_json = "{\"dim\":2}",
                   .owner = "ann",
                   .idempotency_key = "k",
                   .request_sha256 = "fp",
                   .cache_key = "K"};
    CHECK(pk_queue_submit_reused(q, &s, a, r) == PK_Q_OK);
    json_t *row = pk_queue_get(q, r);
    CHECK(row && !strcmp(str(row, "status"), "successful") && strstr(str(row, "message"), a));
    CHECK(!strcmp(str(row, "result_sha256"), "ab") &&
          json_is_null(json_object_get(row, "started")));
    json_decref(row);
    char again[37] = "00000000-0000-4000-8000-000000000002";
    CHECK(pk_queue_submit_reused(q, &s, a, again) == PK_Q_EXISTING && !strcmp(again, r));
    char was[16];
    CHECK(pk_queue_dismiss(q, a, was) == 0);
    s.idempotency_key = NULL;
    char late[37] = "00000000-0000-4000-8000-000000000003";
    CHECK(pk_queue_submit_reused(q, &s, a, late) == PK_Q_GONE && !pk_queue_get(q, late));
    pk_queue_close(q);
}

int main(void)
{
    if (!mkdtemp(dir))
        return 1;
    RUN(test_schema_version);
    RUN(test_submit_limits_and_keys);
    RUN(test_claim_run_finish);
    RUN(test_dismiss_running);
    RUN(test_recover_bounded);
    RUN(test_concurrent_connections);
    RUN(test_reuse);
    char cmd[300];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    if (system(cmd) != 0)
        fprintf(stderr, "cannot remove %s\n", dir);
    return check_summary();
}
