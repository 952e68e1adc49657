/* route_dashboard.c — the browser dashboard: the files of web/ and the examples compiled
 * in (web_assets.h), the page at / for a browser, and the job's inputs the
 * job page shows, and the queue's counts above the list.  The page runs only its own script (Content-Security-Policy);
 * it reads the API as any client does, with the user's bearer token. */
#include "route_dashboard.h"

#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "auth.h"
#include "web_assets.h"

/* Pictures and downloads of an auth'd page are fetched with the token and
 * shown from blob: URLs. */
#define CSP "default-src 'self'; img-src 'self' blob:; object-src 'none'; frame-ancestors 'none'"
/* The API page runs only its own scripts too; Swagger UI sets style
 * attributes and draws icons from data: URLs, and calls only this service. */
#define API_PAGE_CSP                                                                               \
    "default-src 'none'; script-src 'self'; style-src 'self' 'unsafe-inline'; "                    \
    "img-src 'self' data:; connect-src 'self'; base-uri 'none'; form-action 'none'; "              \
    "frame-ancestors 'none'"

/* q of the most specific range of accept matching type ("text/html"):
 * an exact type, then its major type with a wildcard subtype, then any
 * type; 0 when none matches. */
static double accept_q(const char *accept, const char *type)
{
    size_t major = strcspn(type, "/");
    double best = 0;
    int best_rank = -1;
    for (const char *p = accept; *p;) {
        size_t n = strcspn(p, ",");
        char range[128];
        snprintf(range, sizeof range, "%.*s", (int)(n < sizeof range ? n : sizeof range - 1), p);
        p += n + (p[n] == ',');
        char *params = strchr(range, ';');
        double q = 1;
        if (params) {
            *params++ = 0;
            char *qs = strstr(params, "q=");
            if (qs)
                q = strtod(qs + 2, NULL);
        }
        char *t = range + strspn(range, " \t");
        t[strcspn(t, " \t")] = 0;
        int rank = -1;
        if (!strcasecmp(t, type))
            rank = 2;
        else if (!strncasecmp(t, type, major + 1) && !strcmp(t + major + 1, "*"))
            rank = 1;
        else if (!strcmp(t, "*/*"))
            rank = 0;
        if (rank > best_rank) {
            best_rank = rank;
            best = q;
        }
    }
    return best;
}

int pk_prefers_html(pk_req *r)
{
    const char *accept = pk_header(r, "Accept");
    return accept && accept_q(accept, "text/html") > accept_q(accept, "application/json");
}

static const pk_web_asset *asset(const char *name)
{
    for (const pk_web_asset *a = pk_web_assets; a->name; a++)
        if (!strcmp(a->name, name))
            return a;
    return NULL;
}

static const char *media_type(const char *name)
{
    static const char *const types[][2] = {
        {".html", "text/html; charset=utf-8"}, {".js", "text/javascript; charset=utf-8"},
        {".css", "text/css; charset=utf-8"},   {".svg", "image/svg+xml"},
        {".json", "application/json"},         {".txt", "text/plain; charset=utf-8"},
    };
    const char *dot = strrchr(name, '.');
    for (size_t i = 0; dot && i < sizeof types / sizeof *types; i++)
        if (!strcmp(dot, types[i][0]))
            return types[i][1];
    return "application/octet-stream";
}

static enum MHD_Result send_asset_csp(pk_req *r, const pk_web_asset *a, const char *csp)
{
    struct MHD_Response *resp =
        MHD_create_response_from_buffer(a->len, (void *)a->data, MHD_RESPMEM_PERSISTENT);
    if (resp) {
        MHD_add_response_header(resp, "Content-Type", media_type(a->name));
        MHD_add_response_header(resp, "Content-Security-Policy", csp);
        MHD_add_response_header(resp, "Cache-Control", "no-cache");
        MHD_add_response_header(resp, "Vary", "Accept");
    }
    return pk_send(r, 200, resp);
}

static enum MHD_Result send_asset(pk_req *r, const pk_web_asset *a)
{
    return send_asset_csp(r, a, CSP);
}

/* A page of web/ under its own policy. */
static enum MHD_Result send_page(pk_req *r, const char *name, const char *csp)
{
    const pk_web_asset *a = asset(name);
    if (!a)
        return pk_reply_problem(r, PK_P_INTERNAL, "the page is not compiled in");
    return send_asset_csp(r, a, csp);
}

enum MHD_Result pk_send_api_page(pk_req *r) { return send_page(r, "api.html", API_PAGE_CSP); }

enum MHD_Result pk_send_dashboard_page(pk_req *r) { return send_page(r, "index.html", CSP); }

enum MHD_Result route_dashboard_asset(pk_req *r)
{
    /* the pages are served at / and /api only: their links are relative to them,
     * and each has its own Content-Security-Policy */
    const char *dot = strrchr(r->seg[1], '.');
    const pk_web_asset *a = dot && !strcmp(dot, ".html") ? NULL : asset(r->seg[1]);
    if (!a)
        return pk_reply_problem(r, PK_P_NOT_FOUND, "no such dashboard file");
    return send_asset(r, a);
}

/* [{name, process, comment, inputs}] of every example compiled in. */
enum MHD_Result route_dashboard_examples(pk_req *r)
{
    json_t *list = json_array();
    for (const pk_web_asset *a = pk_web_assets; a->name; a++) {
        if (strncmp(a->name, "examples/", 9) != 0)
            continue;
        json_t *ex = json_loadb((const char *)a->data, a->len, 0, NULL);
        if (json_is_object(ex) && json_is_object(json_object_get(ex, "inputs"))) {
            json_object_set_new(ex, "name", json_string(a->name + 9));
            json_array_append(list, ex);
        }
        json_decref(ex);
    }
    return pk_send_json(r, 200, json_pack("{s:o}", "examples", list), NULL);
}

/* The queue and the workers, counted over every owner: no job ids, no owners
 * (the figures of /metrics, which is for admins only). */
enum MHD_Result route_dashboard_queue(pk_req *r)
{
    json_t *st = pk_queue_stats(r->svc->q);
    json_t *jobs = json_object_get(st, "jobs");
    json_t *doc = json_pack(
        "{s:I,s:I,s:i,s:i,s:s}", "accepted", json_integer_value(json_object_get(jobs, "accepted")),
        "running", json_integer_value(json_object_get(jobs, "running")), "workers_busy",
        pk_executor_busy(r->svc->exec), "workers_max", pk_executor_capacity(r->svc->exec),
        "executor", pk_executor_name(r->svc->exec));
    json_decref(st);
    return pk_send_json(r, 200, doc, NULL);
}

/* {owner, admin} of the request: an admin's list may be filtered by owner
 * (GET /jobs?owner=), so the page offers that filter to admins only. */
enum MHD_Result route_dashboard_me(pk_req *r)
{
    return pk_send_json(r, 200, json_pack("{s:s,s:b}", "owner", r->owner, "admin", r->admin), NULL);
}

/* {process, inputs} as the job was submitted: the queue's row, from which the
 * job file its worker reads is written when it starts (so also while it waits). */
enum MHD_Result route_dashboard_inputs(pk_req *r)
{
    json_t *row = pk_job_visible(r, r->seg[2]);
    if (!row)
        return pk_reply_problem(r, PK_P_NO_SUCH_JOB, r->seg[2]);
    json_t *job = json_pack("{s:O,s:O}", "process", json_object_get(row, "process"), "inputs",
                            json_object_get(row, "inputs"));
    json_decref(row);
    if (!job)
        return pk_reply_problem(r, PK_P_NOT_FOUND, "the job's inputs are not kept");
    return pk_send_json(r, 200, job, NULL);
}
