/* GET /metrics (Prometheus text format 0.0.4) and GET /healthz. */
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "conn_guard.h"
#include "http.h"
#include "api/process.h"

typedef struct buf {
    char *p;
    size_t n, cap;
} buf;

static void put(buf *b, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void put(buf *b, const char *fmt, ...)
{
    va_list ap;
    for (;;) {
        va_start(ap, fmt);
        int k = vsnprintf(b->p ? b->p + b->n : NULL, b->p ? b->cap - b->n : 0, fmt, ap);
        va_end(ap);
        if (k < 0)
            return;
        if (b->p && b->n + (size_t)k < b->cap) {
            b->n += (size_t)k;
            return;
        }
        size_t cap = (b->cap + (size_t)k + 1) * 2;
        char *np = realloc(b->p, cap);
        if (!np)
            return;
        b->p = np;
        b->cap = cap;
    }
}

/* The processes to label: every known one (so each series exists from the
 * start, at 0) and any other the database has counted. */
static json_t *process_names(json_t *st)
{
    json_t *names = json_object();
    for (size_t i = 0; pk_processes[i]; i++)
        json_object_set_new(names, pk_processes[i]->id, json_true());
    const char *k;
    json_t *v;
    json_object_foreach (json_object_get(st, "finished"), k, v)
        json_object_set_new(names, k, json_true());
    json_object_foreach (json_object_get(st, "durations"), k, v)
        json_object_set_new(names, k, json_true());
    return names;
}

/* Counters and the run-time histogram of ended jobs (job_metrics.h): kept
 * in the database, they never go down when a job is dismissed or the
 * daemon restarts. */
static void put_job_counters(buf *b, json_t *st)
{
    static const char *const ended[] = {"successful", "failed", "dismissed"};
    json_t *names = process_names(st), *v;
    const char *p;
    put(b,
        "# HELP packd_jobs_finished_total Jobs that ended, by process and final status"
        " (a job dismissed after it ended stays counted as it ended).\n"
        "# TYPE packd_jobs_finished_total counter\n");
    json_object_foreach (names, p, v) {
        json_t *counts = json_object_get(json_object_get(st, "finished"), p);
        for (size_t i = 0; i < sizeof ended / sizeof *ended; i++)
            put(b, "packd_jobs_finished_total{process=\"%s\",status=\"%s\"} %lld\n", p, ended[i],
                (long long)json_integer_value(json_object_get(counts, ended[i])));
    }
    put(b,
        "# HELP packd_job_duration_seconds Run time of jobs that ran to an end (started to"
        " finished), by process.\n# TYPE packd_job_duration_seconds histogram\n");
    json_t *bounds = json_object_get(st, "bounds");
    json_object_foreach (names, p, v) {
        json_t *d = json_object_get(json_object_get(st, "durations"), p);
        long long cum = 0;
        size_t i;
        json_t *le;
        json_array_foreach (bounds, i, le) {
            cum += json_integer_value(json_array_get(json_object_get(d, "n"), i));
            if (json_is_null(le))
                put(b, "packd_job_duration_seconds_bucket{process=\"%s\",le=\"+Inf\"} %lld\n", p,
                    cum);
            else
                put(b, "packd_job_duration_seconds_bucket{process=\"%s\",le=\"%g\"} %lld\n", p,
                    json_number_value(le), cum);
        }
        put(b, "packd_job_duration_seconds_sum{process=\"%s\"} %.6f\n", p,
            json_number_value(json_object_get(d, "sum")));
        put(b, "packd_job_duration_seconds_count{process=\"%s\"} %lld\n", p,
            (long long)json_integer_value(json_object_get(d, "count")));
    }
    json_decref(names);
}

enum MHD_Result route_metrics(pk_req *r)
{
    pk_service *svc = r->svc;
    json_t *st = pk_queue_stats(svc->q);
    buf b = {0};
    put(&b, "# HELP packd_up 1 while the daemon serves.\n# TYPE packd_up gauge\npackd_up 1\n");
    put(&b,
        "# HELP packd_build_info Version of packd.\n# TYPE packd_build_info gauge\n"
        "packd_build_info{version=\"%s\"} 1\n",
        PACKD_VERSION);
    put(&b, "# HELP packd_jobs Jobs in the queue database by status.\n# TYPE packd_jobs gauge\n");
    const char *k;
    json_t *v;
    json_object_foreach (json_object_get(st, "jobs"), k, v)
        put(&b, "packd_jobs{status=\"%s\"} %lld\n", k, (long long)json_integer_value(v));
    put(&b,
        "# HELP packd_queue_depth Jobs accepted and waiting for a worker.\n"
        "# TYPE packd_queue_depth gauge\npackd_queue_depth %lld\n",
        (long long)json_integer_value(json_object_get(json_object_get(st, "jobs"), "accepted")));
    put(&b,
        "# HELP packd_workers_busy Worker processes running.\n# TYPE packd_workers_busy gauge\n"
        "packd_workers_busy %d\n",
        pk_supervisor_busy(svc->sup));
    put(&b,
        "# HELP packd_workers_max Configured maximum of worker processes.\n"
        "# TYPE packd_workers_max gauge\npackd_workers_max %d\n",
        pk_supervisor_capacity(svc->sup));
    put_job_counters(&b, st);
    put(&b,
        "# HELP packd_http_responses_total HTTP responses by status code.\n"
        "# TYPE packd_http_responses_total counter\n");
    for (int c = 100; c < 600; c++) {
        unsigned long long n = __atomic_load_n(&svc->responses[c], __ATOMIC_RELAXED);
        if (n)
            put(&b, "packd_http_responses_total{code=\"%d\"} %llu\n", c, n);
    }
    long long by_deadline, evicted;
    pk_conn_guard_counts(&by_deadline, &evicted);
    put(&b,
        "# HELP packd_http_connections_closed_total Connections closed by the server: a head or "
        "body past its deadline, or evicted as the slowest near max_connections.\n"
        "# TYPE packd_http_connections_closed_total counter\n"
        "packd_http_connections_closed_total{reason=\"deadline\"} %lld\n"
        "packd_http_connections_closed_total{reason=\"evicted\"} %lld\n",
        by_deadline, evicted);
    put(&b,
        "# HELP packd_uptime_seconds Seconds since the daemon started.\n"
        "# TYPE packd_uptime_seconds gauge\npackd_uptime_seconds %.1f\n",
        pk_queue_now() - svc->started);
    json_decref(st);
    enum MHD_Result rc =
        pk_send_text(r, 200, "text/plain; version=0.0.4; charset=utf-8", b.p ? b.p : "");
    free(b.p);
    return rc;
}

enum MHD_Result route_healthz(pk_req *r)
{
    pk_service *svc = r->svc;
    json_t *st = pk_queue_stats(svc->q); /* a real query: the database answers */
    char why[200] = "";
    int db_ok =
        json_is_true(json_object_get(st, "ok")) && pk_queue_writable(svc->q, why, sizeof why);
    json_decref(st);
    int draining = __atomic_load_n(&svc->draining, __ATOMIC_RELAXED);
    int ready = db_ok && !draining;
    json_t *doc =
        json_pack("{s:s,s:b,s:b,s:s,s:{s:i,s:i},s:f}", "status", ready ? "ok" : "unavailable",
                  "live", 1, "ready", ready, "database", db_ok ? "ok" : "error", "workers", "busy",
                  pk_supervisor_busy(svc->sup), "max", pk_supervisor_capacity(svc->sup), "uptime_s",
                  pk_queue_now() - svc->started);
    if (why[0])
        json_object_set_new(doc, "database_error", json_string(why));
    return pk_send_json(r, ready ? 200 : 503, doc, NULL);
}
