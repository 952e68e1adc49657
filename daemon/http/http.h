/* http.h — the daemon's HTTP layer over libmicrohttpd: one route table
 * (routes.c), one handler per route file (route_*.c), and the reply helpers
 * every handler uses (http_reply.c).  Every error is application/problem+json. */
#ifndef PK_HTTP_H
#define PK_HTTP_H

#include <jansson.h>
#include <microhttpd.h>
#include <stddef.h>

#include "api/http/http_problem.h"
#include "daemon/service.h"

#ifndef PACKD_VERSION
#define PACKD_VERSION "0.0.0"
#endif

#define PK_MAX_SEGMENTS 8

typedef struct pk_req {
    struct MHD_Connection *conn;
    pk_service *svc;
    const char *method; /* HEAD is routed as GET */
    const char *url;
    char seg[PK_MAX_SEGMENTS][160]; /* path segments; a route's '*' captures one */
    int nseg;
    char *body;
    size_t body_len, body_cap;
    int too_large;
    int first_call_done;
    char owner[128]; /* who asks (auth.c): token name, proxy's X-Packd-Owner or address */
    int admin;       /* sees every owner's jobs and uploads */
    int answered;    /* answered from the headers alone (413, 415): the body is not read */
    const struct pk_route *route;   /* the route matched and authorised from the headers */
    const struct pk_route *matched; /* the route matched, authorised or not (metrics) */
    double started;                 /* when the headers were complete (pk_queue_now clock) */
    /* A request that waits without a thread (http_park.h): once its
     * connection resumes, resume is called instead of the route; wait is
     * its state, freed by wait_free when the request ends. */
    enum MHD_Result (*resume)(struct pk_req *r);
    void *wait;
    void (*wait_free)(void *wait);
    char sync_job[40]; /* answered synchronously for this job (Prefer: respond-sync):
                                  pk_send adds Preference-Applied and Link rel=monitor */
} pk_req;

typedef enum MHD_Result (*pk_handler)(pk_req *r);

/* Who may call a route once auth is on (auth.c). */
typedef enum { PK_PUBLIC, PK_USER, PK_ADMIN } pk_access;

typedef struct pk_route {
    const char *method;
    const char *pattern; /* e.g. "/jobs/{*}": a star segment matches any one segment */
    pk_handler handler;
    pk_access access;
} pk_route;

extern const pk_route pk_routes[]; /* terminated by {NULL} */

/* Start/stop the listener.  Returns NULL with err on failure.  *port gets the
 * bound port (useful with port 0). */
struct MHD_Daemon *pk_http_start(pk_service *svc, int *port, char *err, size_t errlen);
/* End the streams (svc->stopping must be set), then stop the listener. */
void pk_http_stop(struct MHD_Daemon *d);

/* --- replies (each queues the response and counts it for /metrics) --- */
enum MHD_Result pk_send(pk_req *r, unsigned status, struct MHD_Response *resp);
/* Every "href" of doc that is a path ("/jobs/…") made absolute from the
 * configured public_url, else the request's Host.  pk_send_json and the
 * problem senders do it; pk_send makes a path Location header absolute. */
void pk_absolute_links(pk_req *r, json_t *doc);
/* This service's URL as the client reaches it: public_url, else http://<Host>. */
void pk_base_url(pk_req *r, char *out, size_t n);
/* Links of doc made absolute under base (a URL pk_base_url gave). */
void pk_absolute_links_at(json_t *doc, const char *base);
/* The inverse for a request's inputs: links into this service given as
 * absolute URLs (as its documents give them) become paths again. */
void pk_own_links_as_paths(pk_req *r, json_t *inputs);
/* A document as a client sees it: no path of the data directory, links
 * absolute (what pk_send_json does before sending). */
void pk_client_view(pk_req *r, json_t *doc);
/* JSON body (stolen); etag may be NULL. */
enum MHD_Result pk_send_json(pk_req *r, unsigned status, json_t *body, const char *etag);
/* A response with a JSON body (stolen, indented, ends with a newline). */
struct MHD_Response *pk_json_response(json_t *body, const char *ctype);
/* Text body copied; content type given. */
enum MHD_Result pk_send_text(pk_req *r, unsigned status, const char *ctype, const char *text);
/* application/problem+json; extra members (stolen, may be NULL) merged in;
 * retry_after > 0 adds Retry-After. */
enum MHD_Result pk_send_problem(pk_req *r, unsigned status, const char *type, const char *title,
                                const char *detail, json_t *extra, int retry_after);
/* The problem of code (api/http/http_problem.h: the code decides status,
 * type and title) with detail (may be NULL). */
enum MHD_Result pk_reply_problem(pk_req *r, pk_problem_code code, const char *detail);
/* A problem document already built (stolen). */
enum MHD_Result pk_send_problem_doc(pk_req *r, unsigned status, json_t *doc, int retry_after);

/* Request headers / query arguments (NULL if absent). */
const char *pk_header(pk_req *r, const char *name);
const char *pk_query(pk_req *r, const char *name);
/* Integer query parameter name in min..max (def when absent): 0, or -1 with
 * a detail naming the parameter and its range (for a 400). */
int pk_query_int(pk_req *r, const char *name, long long def, long long min, long long max,
                 long long *out, char *detail, size_t n);
/* Who submits (r->owner, set by pk_authorize before the handler runs). */
void pk_owner(pk_req *r, char *out, size_t n);

/* Route handlers */
enum MHD_Result route_landing(pk_req *r);
enum MHD_Result route_conformance(pk_req *r);
enum MHD_Result route_api(pk_req *r);
enum MHD_Result route_processes(pk_req *r);
enum MHD_Result route_process(pk_req *r);
enum MHD_Result route_execute(pk_req *r);
enum MHD_Result route_jobs(pk_req *r);
enum MHD_Result route_job(pk_req *r);
enum MHD_Result route_job_delete(pk_req *r);
enum MHD_Result route_events(pk_req *r);
enum MHD_Result route_results(pk_req *r);
enum MHD_Result route_result_file(pk_req *r);
enum MHD_Result route_files_post(pk_req *r);
enum MHD_Result route_file_get(pk_req *r);
enum MHD_Result route_metrics(pk_req *r);
enum MHD_Result route_healthz(pk_req *r);

/* Serve a file with Content-Length, ETag, digest headers and single Range
 * requests (206/416), If-None-Match (304). */
enum MHD_Result pk_send_file(pk_req *r, const char *path, const char *ctype, const char *sha256_hex,
                             const char *download_name);

#endif
