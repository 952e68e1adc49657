/* POST /processes/{pid}/execution — validate by the process's schema (the
 * same code path as `packd validate`), apply the server's caps, queue the job:
 * 201 + Location + statusInfo.  Idempotency-Key: the same key and request
 * return the same job; the same key with another request is 422. */
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "auth.h"
#include "http.h"
#include "daemon/input_refs.h"
#include "api/http/http_process_doc.h"
#include "api/http/http_status_info.h"
#include "api/inputs/input_confine.h"
#include "daemon/log.h"
#include "daemon/store/digest.h"

static enum MHD_Result reply_job(pk_req *r, const char *id, int replayed)
{
    json_t *row = pk_queue_get(r->svc->q, id);
    if (!row)
        return pk_send_problem(r, 500, PK_PROBLEM_GENERIC, "Internal Server Error", "job vanished", NULL, 0);
    json_t *info = pk_status_info(row);
    pk_absolute_links(r, info);
    struct MHD_Response *resp = pk_json_response(info, "application/json");
    json_decref(row);
    char loc[80];
    snprintf(loc, sizeof loc, "/jobs/%s", id);
    MHD_add_response_header(resp, "Location", loc);
    if (replayed)
        MHD_add_response_header(resp, "Idempotent-Replayed", "true");
    return pk_send(r, 201, resp);
}

enum MHD_Result route_execute(pk_req *r)
{
    pk_service *svc = r->svc;
    const pk_process *p = pk_process_find(r->seg[1]);
    if (!p)
        return pk_send_problem(r, 404, PK_PROBLEM_NO_SUCH_PROCESS, "No such process", r->seg[1], NULL, 0);
    if (__atomic_load_n(&svc->draining, __ATOMIC_RELAXED))
        return pk_send_problem(r, 503, PK_PROBLEM_PACKD "shutting-down", "Service Unavailable",
                               "the daemon is stopping; submit again shortly", NULL, 10);
    json_error_t jerr;
    json_t *body = r->body_len ? json_loadb(r->body, r->body_len, 0, &jerr) : NULL;
    if (!body) {
        char d[300];
        if (r->body_len)
            snprintf(d, sizeof d, "the body is not JSON: %s (line %d, column %d)", jerr.text, jerr.line,
                     jerr.column);
        else
            snprintf(d, sizeof d, "the body is empty; expected {\"inputs\": {...}}");
        return pk_send_problem(r, 400, PK_PROBLEM_GENERIC, "Bad Request", d, NULL, 0);
    }
    json_t *inputs = json_object_get(body, "inputs");
    if (!json_is_object(body) || !json_is_object(inputs)) {
        pk_schema_errors e = {0};
        pk_schema_errors_add(&e, json_is_object(body) ? "/inputs" : "", json_is_object(body) ? "required" : "type",
                             "the body must be an object with an \"inputs\" object");
        json_decref(body);
        enum MHD_Result rc = pk_send_problem_doc(r, 400, pk_problem_invalid(400, "malformed execute request", &e), 0);
        pk_schema_errors_free(&e);
        return rc;
    }
    /* A job file {"process", "inputs"} is a valid body too, if it names this process. */
    json_t *named = json_object_get(body, "process");
    if (named && !(json_is_string(named) && !strcmp(json_string_value(named), p->id))) {
        pk_schema_errors e = {0};
        pk_schema_errors_add(&e, "/process", "const", "this is POST /processes/%s/execution", p->id);
        json_decref(body);
        enum MHD_Result rc = pk_send_problem_doc(r, 400, pk_problem_invalid(400, "process mismatch", &e), 0);
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
        for (size_t i = 0; i < errs.n; i++) { /* pointers relative to the body */
            char ptr[sizeof errs.items[i].pointer + 8];
            snprintf(ptr, sizeof ptr, "/inputs%s", errs.items[i].pointer);
            ptr[sizeof errs.items[i].pointer - 1] = 0;
            memcpy(errs.items[i].pointer, ptr, sizeof errs.items[i].pointer);
        }
        char d[80];
        snprintf(d, sizeof d, "%zu invalid input%s", errs.n, errs.n == 1 ? "" : "s");
        json_decref(body);
        enum MHD_Result rc = pk_send_problem_doc(r, 422, pk_problem_invalid(422, d, &errs), 0);
        pk_schema_errors_free(&errs);
        return rc;
    }
    char *text = json_dumps(inputs, JSON_COMPACT | JSON_SORT_KEYS);
    json_decref(body);
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
    pk_submit s = {.process = p->id, .inputs_json = text, .owner = owner,
                   .idempotency_key = key && *key ? key : NULL, .request_sha256 = fp_src_hash,
                   .max_queued = cfg.max_queued, .max_queued_per_owner = cfg.max_queued_per_owner};
    int rc = pk_queue_submit(svc->q, &s, id);
    free(text);
    switch (rc) {
    case PK_Q_OK:
        pk_log(PK_LOG_INFO, "job accepted", "{s:s,s:s,s:s}", "job", id, "process", p->id, "owner", owner);
        pk_supervisor_wake(svc->sup);
        return reply_job(r, id, 0);
    case PK_Q_EXISTING:
        return reply_job(r, id, 1);
    case PK_Q_KEY_CONFLICT:
        return pk_send_problem(r, 422, PK_PROBLEM_PACKD "idempotency-key-reused", "Idempotency key reused",
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
        return pk_send_problem(r, 503, PK_PROBLEM_PACKD "queue-unwritable", "Service Unavailable", d,
                               NULL, 30);
    }
    case PK_Q_OWNER_FULL:
        return pk_send_problem(r, 429, PK_PROBLEM_PACKD "owner-queue-full", "Too many queued jobs",
                               "max_queued_per_owner of your jobs are waiting", NULL, 30);
    default:
        return pk_send_problem(r, 500, PK_PROBLEM_GENERIC, "Internal Server Error",
                               "the queue database refused the job", NULL, 5);
    }
}
