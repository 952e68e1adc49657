/* GET /metrics (Prometheus text format 0.0.4) and GET /healthz. */
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "conn_guard.h"
#include "http.h"
#include "http_durations.h"
#include "text_buf.h"
#include "api/process.h"
#include "daemon/proc_stats.h"

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
static void put_job_counters(pk_text_buf *b, json_t *st)
{
    static const char *const ended[] = {"successful", "failed", "dismissed"};
    json_t *names = process_names(st), *v;
    const char *p;
    pk_text_put(b,
                "# HELP packd_jobs_finished_total Jobs that ended, by process and final status"
                " (a job dismissed after it ended stays counted as it ended).\n"
                "# TYPE packd_jobs_finished_total counter\n");
    json_object_foreach (names, p, v) {
        json_t *counts = json_object_get(json_object_get(st, "finished"), p);
        for (size_t i = 0; i < sizeof ended / sizeof *ended; i++)
            pk_text_put(b, "packd_jobs_finished_total{process=\"%s\",status=\"%s\"} %lld\n", p,
                        ended[i], (long long)json_integer_value(json_object_get(counts, ended[i])));
    }
    pk_text_put(b,
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
                pk_text_put(b,
                            "packd_job_duration_seconds_bucket{process=\"%s\",le=\"+Inf\"} %lld\n",
                            p, cum);
            else
                pk_text_put(b, "packd_job_duration_seconds_bucket{process=\"%s\",le=\"%g\"} %lld\n",
                            p, json_number_value(le), cum);
        }
        pk_text_put(b, "packd_job_duration_seconds_sum{process=\"%s\"} %.6f\n", p,
                    json_number_value(json_object_get(d, "sum")));
        pk_text_put(b, "packd_job_duration_seconds_count{process=\"%s\"} %lld\n", p,
                    (long long)json_integer_value(json_object_get(d, "count")));
    }
    json_decref(names);
}

/* The standard process metrics (the names of Prometheus's client
 * libraries), from /proc/self; a value the kernel did not give is left out. */
static void put_process(pk_text_buf *b)
{
    pk_proc_stats ps;
    pk_proc_stats_read(&ps);
    if (ps.cpu_s >= 0)
        pk_text_put(b,
                    "# HELP process_cpu_seconds_total Total user and system CPU time spent in "
                    "seconds.\n# TYPE process_cpu_seconds_total counter\n"
                    "process_cpu_seconds_total %.2f\n",
                    ps.cpu_s);
    if (ps.start_time_s >= 0)
        pk_text_put(b,
                    "# HELP process_start_time_seconds Start time of the process since unix epoch "
                    "in seconds.\n# TYPE process_start_time_seconds gauge\n"
                    "process_start_time_seconds %.2f\n",
                    ps.start_time_s);
    if (ps.rss_bytes >= 0)
        pk_text_put(b,
                    "# HELP process_resident_memory_bytes Resident memory size in bytes.\n"
                    "# TYPE process_resident_memory_bytes gauge\n"
                    "process_resident_memory_bytes %lld\n",
                    ps.rss_bytes);
    if (ps.vsize_bytes >= 0)
        pk_text_put(b,
                    "# HELP process_virtual_memory_bytes Virtual memory size in bytes.\n"
                    "# TYPE process_virtual_memory_bytes gauge\n"
                    "process_virtual_memory_bytes %lld\n",
                    ps.vsize_bytes);
    if (ps.open_fds >= 0)
        pk_text_put(b,
                    "# HELP process_open_fds Number of open file descriptors.\n"
                    "# TYPE process_open_fds gauge\nprocess_open_fds %lld\n",
                    ps.open_fds);
    if (ps.max_fds >= 0)
        pk_text_put(b,
                    "# HELP process_max_fds Maximum number of open file descriptors.\n"
                    "# TYPE process_max_fds gauge\nprocess_max_fds %lld\n",
                    ps.max_fds);
}

enum MHD_Result route_metrics(pk_req *r)
{
    pk_service *svc = r->svc;
    json_t *st = pk_queue_stats(svc->q);
    pk_text_buf b = {0};
    pk_text_put(&b,
                "# HELP packd_up 1 while the daemon serves.\n# TYPE packd_up gauge\npackd_up 1\n");
    pk_text_put(&b,
                "# HELP packd_build_info Version of packd.\n# TYPE packd_build_info gauge\n"
                "packd_build_info{version=\"%s\"} 1\n",
                PACKD_VERSION);
    pk_text_put(
        &b, "# HELP packd_jobs Jobs in the queue database by status.\n# TYPE packd_jobs gauge\n");
    const char *k;
    json_t *v;
    json_object_foreach (json_object_get(st, "jobs"), k, v)
        pk_text_put(&b, "packd_jobs{status=\"%s\"} %lld\n", k, (long long)json_integer_value(v));
    pk_text_put(
        &b,
        "# HELP packd_queue_depth Jobs accepted and waiting for a worker.\n"
        "# TYPE packd_queue_depth gauge\npackd_queue_depth %lld\n",
        (long long)json_integer_value(json_object_get(json_object_get(st, "jobs"), "accepted")));
    pk_text_put(
        &b,
        "# HELP packd_workers_busy Worker processes running.\n# TYPE packd_workers_busy gauge\n"
        "packd_workers_busy %d\n",
        pk_executor_busy(svc->exec));
    pk_text_put(&b,
                "# HELP packd_workers_max Configured maximum of worker processes.\n"
                "# TYPE packd_workers_max gauge\npackd_workers_max %d\n",
                pk_executor_capacity(svc->exec));
    put_job_counters(&b, st);
    pk_text_put(
        &b,
        "# HELP packd_queue_transactions_total Transactions the queue database committed.\n"
        "# TYPE packd_queue_transactions_total counter\npackd_queue_transactions_total %lld\n",
        pk_queue_transactions(svc->q));
    long long cycles;
    double cycle_s;
    if (pk_executor_poll_stats(svc->exec, &cycles, &cycle_s))
        pk_text_put(
            &b,
            "# HELP packd_executor_poll_cycles_total Poll cycles of the executor (slurm: one "
            "squeue and one queue transaction each).\n"
            "# TYPE packd_executor_poll_cycles_total counter\npackd_executor_poll_cycles_total "
            "%lld\n# HELP packd_executor_poll_seconds_total Wall seconds the poll cycles took.\n"
            "# TYPE packd_executor_poll_seconds_total counter\n"
            "packd_executor_poll_seconds_total %.6f\n",
            cycles, cycle_s);
    pk_text_put(&b,
                "# HELP packd_result_cache_requests_total Execute requests that could be answered"
                " from an equal successful job (result_cache_max_age_s), by outcome: hit (answered"
                " from it) or miss (run).\n# TYPE packd_result_cache_requests_total counter\n"
                "packd_result_cache_requests_total{outcome=\"hit\"} %llu\n"
                "packd_result_cache_requests_total{outcome=\"miss\"} %llu\n",
                __atomic_load_n(&svc->cache_hits, __ATOMIC_RELAXED),
                __atomic_load_n(&svc->cache_misses, __ATOMIC_RELAXED));
    pk_text_put(&b,
                "# HELP packd_http_responses_total HTTP responses by status code.\n"
                "# TYPE packd_http_responses_total counter\n");
    for (int c = 100; c < 600; c++) {
        unsigned long long n = __atomic_load_n(&svc->responses[c], __ATOMIC_RELAXED);
        if (n)
            pk_text_put(&b, "packd_http_responses_total{code=\"%d\"} %llu\n", c, n);
    }
    long long by_deadline, evicted;
    pk_conn_guard_counts(&by_deadline, &evicted);
    pk_text_put(
        &b,
        "# HELP packd_http_connections_closed_total Connections closed by the server: a head or "
        "body past its deadline, or evicted as the slowest near max_connections.\n"
        "# TYPE packd_http_connections_closed_total counter\n"
        "packd_http_connections_closed_total{reason=\"deadline\"} %lld\n"
        "packd_http_connections_closed_total{reason=\"evicted\"} %lld\n",
        by_deadline, evicted);
    pk_text_put(&b,
                "# HELP packd_uptime_seconds Seconds since the daemon started.\n"
                "# TYPE packd_uptime_seconds gauge\npackd_uptime_seconds %.1f\n",
                pk_queue_now() - svc->started);
    pk_http_durations_expose(&b);
    put_process(&b);
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
    int unrecorded = pk_executor_unrecorded(svc->exec); /* job ends waiting for the database */
    int ready = db_ok && !draining && unrecorded == 0;
    json_t *doc =
        json_pack("{s:s,s:b,s:b,s:s,s:{s:i,s:i},s:f}", "status", ready ? "ok" : "unavailable",
                  "live", 1, "ready", ready, "database", db_ok ? "ok" : "error", "workers", "busy",
                  pk_executor_busy(svc->exec), "max", pk_executor_capacity(svc->exec), "uptime_s",
                  pk_queue_now() - svc->started);
    if (why[0])
        json_object_set_new(doc, "database_error", json_string(why));
    if (unrecorded)
        json_object_set_new(doc, "unrecorded_job_ends", json_integer(unrecorded));
    /* a degraded executor (Slurm controller away) keeps the service ready:
     * jobs are accepted and wait; the status and the reason say so */
    char exec_why[300];
    int exec_ok = pk_executor_healthy(svc->exec, exec_why, sizeof exec_why);
    json_object_set_new(doc, "executor",
                        json_pack("{s:s,s:s}", "name", pk_executor_name(svc->exec), "state",
                                  exec_ok ? "ok" : "degraded"));
    if (!exec_ok) {
        json_object_set_new(json_object_get(doc, "executor"), "reason", json_string(exec_why));
        if (ready)
            json_object_set_new(doc, "status", json_string("degraded"));
    }
    return pk_send_json(r, ready ? 200 : 503, doc, NULL);
}
