/* POST /processes/{pid}/execution — validate by the process's schema (the
 * same code path as `packd validate`), apply the server's caps, queue the job:
 * 201 + Location + statusInfo.  Idempotency-Key: the same key and request
 * return the same job; the same key with another request is 422.
 * "Prefer: respond-sync" (RFC 7240, optionally "wait=N") waits up to
 * sync_wait_s for the job, parked without a thread (http_park.h), and answers
 * 200 with its results as "response"/"outputs" ask; a job not finished by
 * then is answered 201 as usual.  "Prefer: respond-async" is always
 * honoured: its 201 says so in Preference-Applied. */
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "auth.h"
#include "http.h"
#include "http_park.h"
#include "results_send.h"
#include "daemon/input_refs.h"
#include "api/http/http_process_doc.h"
#include "api/http/http_status_info.h"
#include "api/inputs/input_confine.h"
#include "api/inputs/json_depth.h"
#include "daemon/log.h"
#include "daemon/result_cache.h"
#include "daemon/store/job_files.h"
#include "daemon/store/uuid.h"
#include "api/digest.h"

/* A synchronous execute waiting for its job. */
typedef struct sync_wait {
    char id[37];
    double deadline; /* pk_queue_now clock */
    pk_parked *park;
    pk_exec_opts opts;
    int replayed;
} sync_wait;

static void sync_wait_free(void *p)
{
    sync_wait *w = p;
    pk_park_unregister(w->park);
    pk_exec_opts_free(&w->opts);
    free(w);
}

/* The preferences of a "Prefer" header (RFC 7240) this route knows:
 * respond-sync, respond-async, and wait=N (4.3), which shortens the
 * service's bound on a synchronous answer. */
typedef struct prefer {
    int sync, async;
    double wait;
} prefer;

static prefer parse_prefer(const char *header, double bound)
{
    prefer pr = {.wait = bound};
    for (const char *p = header; p && *p;) {
        p += strspn(p, " \t,");
        size_t n = strcspn(p, ",;");
        while (n && (p[n - 1] == ' ' || p[n - 1] == '\t'))
            n--;
        if (n == 12 && !strncasecmp(p, "respond-sync", 12))
            pr.sync = 1;
        else if (n == 13 && !strncasecmp(p, "respond-async", 13))
            pr.async = 1;
        else if (n > 5 && !strncasecmp(p, "wait=", 5)) {
            double v = strtod(p + 5, NULL);
            if (v >= 0 && v < pr.wait)
                pr.wait = v;
        }
        p += n;
        p += strcspn(p, ","); /* parameters of a preference (";…") are not used */
    }
    return pr;
}

/* Seconds the client asks to wait for the answer: 0 unless it prefers respond-sync. */
static double sync_seconds(const char *header, double bound)
{
    prefer pr = parse_prefer(header, bound);
    return pr.sync ? pr.wait : 0;
}

static enum MHD_Result reply_job(pk_req *r, const char *id, int replayed);

/* Look at the job; answer once it is final or the wait is over, else park
 * (MHD calls again when the connection resumes). */
static enum MHD_Result sync_check(pk_req *r)
{
    sync_wait *w = r->wait;
    for (;;) {
        long long seq = pk_queue_event_seq(r->svc->q);
        json_t *row = pk_queue_get(r->svc->q, w->id);
        const char *st = row ? json_string_value(json_object_get(row, "status")) : "dismissed";
        if (!strcmp(st, "successful") || !strcmp(st, "failed")) {
            snprintf(r->sync_job, sizeof r->sync_job, "%s", w->id);
            r->resume = NULL;
            return pk_send_results(r, row, &w->opts);
        }
        int gone = !strcmp(st, "dismissed");
        json_decref(row);
        int parked =
            gone || pk_queue_now() >= w->deadline ? -1 : pk_park(w->park, seq, w->deadline);
        if (parked > 0)
            return MHD_YES;
        if (parked < 0) {
            r->resume = NULL;
            return reply_job(r, w->id, w->replayed);
        }
    }
}

/* Answer the job submitted (or replayed): wait for it first when the
 * client prefers a synchronous answer. */
static enum MHD_Result answer(pk_req *r, const char *id, int replayed, pk_exec_opts *opts)
{
    pk_config cfg = pk_service_config(r->svc);
    double secs = sync_seconds(pk_header(r, "Prefer"), cfg.sync_wait_s);
    sync_wait *w = secs > 0 ? calloc(1, sizeof *w) : NULL;
    if (w)
        w->park = pk_park_register(r->conn);
    if (!w || !w->park) {
        free(w);
        pk_exec_opts_free(opts);
        return reply_job(r, id, replayed);
    }
    snprintf(w->id, sizeof w->id, "%s", id);
    w->deadline = pk_queue_now() + secs;
    w->opts = *opts; /* moved */
    w->replayed = replayed;
    r->wait = w;
    r->wait_free = sync_wait_free;
    r->resume = sync_check;
    return sync_check(r);
}

static enum MHD_Result reply_job(pk_req *r, const char *id, int replayed)
{
    json_t *row = pk_queue_get(r->svc->q, id);
    if (!row)
        return pk_reply_problem(r, PK_P_INTERNAL, "job vanished");
    json_t *info = pk_status_info(row);
    pk_absolute_links(r, info);
    struct MHD_Response *resp = pk_json_response(info, "application/json");
    json_decref(row);
    char loc[80];
    snprintf(loc, sizeof loc, "/jobs/%s", id);
    MHD_add_response_header(resp, "Location", loc);
    if (replayed)
        MHD_add_response_header(resp, "Idempotent-Replayed", "true");
    /* asked for and given (OGC /req/core/process-execute-default-execution-mode):
     * a respond-sync that ran out of time is not named, the answer is async all the same */
    if (resp && parse_prefer(pk_header(r, "Prefer"), 0).async)
        MHD_add_response_header(resp, "Preference-Applied", "respond-async");
    return pk_send(r, 201, resp);
}

/* "Cache-Control: no-cache" (RFC 9111 5.2.1.4): the client wants a fresh run. */
static int wants_fresh(pk_req *r)
{
    const char *cc = pk_header(r, "Cache-Control");
    for (; cc && *cc; cc++)
        if (!strncasecmp(cc, "no-cache", 8))
            return 1;
    return 0;
}

/* Queue the job s->id, or answer it from an equal successful job of the
 * same owner that finished within max_age_s (result_cache.h): the job is
 * then made already successful, its files hard links to the old one's.
 * A PK_Q_* code; id is the job answered, *reused 1 when it was answered
 * from an earlier one (nothing for the executor to run). */
static int submit(pk_req *r, const pk_submit *s, const char *data, double max_age_s, char id[37],
                  int *reused)
{
    pk_service *svc = r->svc;
    char src[37];
    if (s->cache_key && max_age_s > 0 && !wants_fresh(r)) {
        int rc = PK_Q_GONE;
        if (pk_queue_find_reusable(svc->q, s->cache_key, s->owner, pk_queue_now() - max_age_s,
                                   src) &&
            pk_result_cache_link(data, src, s->id) == 0) {
            snprintf(id, 37, "%s", s->id);
            rc = pk_queue_submit_reused(svc->q, s, src, id); /* EXISTING: id is the earlier job */
            if (rc != PK_Q_OK)
                pk_result_cache_unlink(data, s->id);
        }
        if (rc == PK_Q_OK) {
            *reused = 1;
            __atomic_add_fetch(&svc->cache_hits, 1, __ATOMIC_RELAXED);
            pk_log(PK_LOG_INFO, "job answered from an equal one", "{s:s,s:s,s:s}", "job", id,
                   "from", src, "owner", s->owner);
        }
        if (rc == PK_Q_OK || rc == PK_Q_EXISTING || rc == PK_Q_KEY_CONFLICT)
            return rc;
        __atomic_add_fetch(&svc->cache_misses, 1, __ATOMIC_RELAXED);
    }
    return pk_queue_submit(svc->q, s, id);
}

enum MHD_Result route_execute(pk_req *r)
{
    pk_service *svc = r->svc;
    const pk_process *p = pk_process_find(r->seg[1]);
    if (!p)
        return pk_reply_problem(r, PK_P_NO_SUCH_PROCESS, r->seg[1]);
    if (__atomic_load_n(&svc->draining, __ATOMIC_RELAXED))
        return pk_send_problem(r, 503, PK_PROBLEM_PACKD "shutting-down", "Service Unavailable",
                               "the daemon is stopping; submit again shortly", NULL, 10);
    json_error_t jerr;
    json_t *body = r->body_len ? json_loadb(r->body, r->body_len, 0, &jerr) : NULL;
    if (!body) {
        char d[300];
        if (r->body_len)
            snprintf(d, sizeof d, "the body is not JSON: %s (line %d, column %d)", jerr.text,
                     jerr.line, jerr.column);
        else
            snprintf(d, sizeof d, "the body is empty; expected {\"inputs\": {...}}");
        return pk_reply_problem(r, PK_P_BAD_REQUEST, d);
    }
    if (!pk_json_depth_within(body, PK_JSON_MAX_DEPTH)) {
        json_decref(body);
        char d[120];
        snprintf(d, sizeof d, "the body nests objects and arrays deeper than %d levels (limit)",
                 PK_JSON_MAX_DEPTH);
        return pk_reply_problem(r, PK_P_BAD_REQUEST, d);
    }
    json_t *inputs = json_object_get(body, "inputs");
    pk_exec_opts opts = {0};
    char bad_opts[200];
    if (json_is_object(body) && pk_exec_opts_parse(body, &opts, bad_opts, sizeof bad_opts) != 0) {
        json_decref(body);
        return pk_send_problem(r, 400, PK_PROBLEM_INVALID_INPUT, "Invalid execute request",
                               bad_opts, NULL, 0);
    }
    if (!json_is_object(body) || !json_is_object(inputs)) {
        pk_exec_opts_free(&opts);
        pk_schema_errors e = {0};
        pk_schema_errors_add(&e, json_is_object(body) ? "/inputs" : "",
                             json_is_object(body) ? "required" : "type",
                             "the body must be an object with an \"inputs\" object");
        json_decref(body);
        enum MHD_Result rc = pk_send_problem_doc(
            r, 400, pk_problem_invalid(400, "malformed execute request", &e), 0);
        pk_schema_errors_free(&e);
        return rc;
    }
    /* A job file {"process", "inputs"} is a valid body too, if it names this process. */
    json_t *named = json_object_get(body, "process");
    if (named && !(json_is_string(named) && !strcmp(json_string_value(named), p->id))) {
        pk_schema_errors e = {0};
        pk_schema_errors_add(&e, "/process", "const", "this is POST /processes/%s/execution",
                             p->id);
        json_decref(body);
        pk_exec_opts_free(&opts);
        enum MHD_Result rc =
            pk_send_problem_doc(r, 400, pk_problem_invalid(400, "process mismatch", &e), 0);
        pk_schema_errors_free(&e);
        return rc;
    }
    pk_config cfg = pk_service_config(svc);
    pk_process_apply_caps(p, inputs, cfg.max_particles, cfg.max_wall_time_s);
    pk_schema_errors errs = {0};
    /* server paths first (refused, or confined to input_dir), then
     * {"href": "[<this service>]/files/…"} and {"href": "[…]/jobs/…/results/result"}
     * → {"file": path}; the checks open no file (check_ctx.h): the worker reads them */
    pk_own_links_as_paths(r, inputs);
    char data_abs[PATH_MAX];
    const char *data = realpath(cfg.data, data_abs) ? data_abs : cfg.data;
    const pk_check_ctx request = {.service = 1};
    if (pk_input_files_confine(inputs, cfg.input_dir, cfg.input_max_bytes, &errs) > 0 ||
        pk_resolve_input_refs(inputs, data, svc->q, pk_scope(r), &errs) > 0 ||
        pk_process_validate_inputs(p, inputs, &request, &errs) > 0) {
        pk_schema_errors_prefix(&errs, 0, "/inputs"); /* pointers relative to the body */
        char d[80];
        snprintf(d, sizeof d, "%zu invalid input%s", errs.n, errs.n == 1 ? "" : "s");
        json_decref(body);
        pk_exec_opts_free(&opts);
        enum MHD_Result rc = pk_send_problem_doc(r, 422, pk_problem_invalid(422, d, &errs), 0);
        pk_schema_errors_free(&errs);
        return rc;
    }
    char *text = json_dumps(inputs, JSON_COMPACT | JSON_SORT_KEYS);
    char fp_src_hash[65], owner[128], id[37];
    size_t plen = strlen(p->id), tlen = strlen(text);
    char *fp_src = malloc(plen + tlen + 2);
    memcpy(fp_src, p->id, plen);
    fp_src[plen] = '\n';
    memcpy(fp_src + plen + 1, text, tlen + 1);
    pk_sha256_hex(fp_src, plen + tlen + 1, fp_src_hash);
    free(fp_src);
    pk_owner(r, owner, sizeof owner);
    const char *key = pk_header(r, "Idempotency-Key");
    char cache_key[65], new_id[37];
    if (pk_uuid4(new_id) != 0) {
        json_decref(body);
        free(text);
        pk_exec_opts_free(&opts);
        return pk_reply_problem(r, PK_P_INTERNAL, "no job id");
    }
    /* the options are in place before the job exists: its first event may
     * go to a subscriber (callbacks.h) */
    pk_base_url(r, opts.base, sizeof opts.base);
    if (pk_results_opts_save(r, new_id, &opts) != 0)
        pk_log(PK_LOG_WARN, "cannot store the execute options; results answer as a document",
               "{s:s}", "job", new_id);
    pk_submit s = {.id = new_id,
                   .process = p->id,
                   .inputs_json = text,
                   .owner = owner,
                   .idempotency_key = key && *key ? key : NULL,
                   .request_sha256 = fp_src_hash,
                   .cache_key =
                       pk_result_cache_key(p->id, inputs, cache_key) == 0 ? cache_key : NULL,
                   .max_queued = cfg.max_queued,
                   .max_queued_per_owner = cfg.max_queued_per_owner};
    int reused = 0;
    int rc = submit(r, &s, data, cfg.result_cache_max_age_s, id, &reused);
    json_decref(body);
    free(text);
    if (rc != PK_Q_OK) /* no job of that id: its options go */
        pk_job_dir_remove(data, new_id);
    if (rc != PK_Q_OK && rc != PK_Q_EXISTING)
        pk_exec_opts_free(&opts);
    switch (rc) {
    case PK_Q_OK:
        if (!reused) {
            pk_log(PK_LOG_INFO, "job accepted", "{s:s,s:s,s:s}", "job", id, "process", p->id,
                   "owner", owner);
            pk_executor_wake(svc->exec);
        }
        return answer(r, id, 0, &opts);
    case PK_Q_EXISTING: return answer(r, id, 1, &opts);
    case PK_Q_KEY_CONFLICT:
        return pk_send_problem(r, 422, PK_PROBLEM_PACKD "idempotency-key-reused",
                               "Idempotency key reused",
                               "this Idempotency-Key was used for a different request",
                               json_pack("{s:s}", "jobID", id), 0);
    case PK_Q_FULL:
        return pk_send_problem(r, 503, PK_PROBLEM_PACKD "queue-full", "Queue full",
                               "max_queued jobs are waiting; try again later", NULL, 30);
    case PK_Q_UNWRITABLE: {
        char why[200], d[300];
        pk_queue_writable(svc->q, why, sizeof why);
        snprintf(d, sizeof d, "the queue database cannot be written (%s); try again later", why);
        pk_log(PK_LOG_ERROR, "job refused: queue not writable", "{s:s}", "error", why);
        return pk_send_problem(r, 503, PK_PROBLEM_PACKD "queue-unwritable", "Service Unavailable",
                               d, NULL, 30);
    }
    case PK_Q_OWNER_FULL:
        return pk_send_problem(r, 429, PK_PROBLEM_PACKD "owner-queue-full", "Too many queued jobs",
                               "max_queued_per_owner of your jobs are waiting", NULL, 30);
    default:
        return pk_send_problem(r, 500, PK_PROBLEM_GENERIC, "Internal Server Error",
                               "the queue database refused the job", NULL, 5);
    }
}
