/* http_server.c — libmicrohttpd set-up, request bodies (with the size limit
 * and the media type of JSON routes) and dispatch through the route table:
 * unknown path 404, known path with another method 405 + Allow, OPTIONS of
 * a known path 204 + Allow (and CORS preflights, cors.h).
 *
 * Connections are served by http_threads epoll event loops (MHD's thread
 * pool), never a thread per connection: a slow or idle client costs a
 * socket and its buffer, bounded by max_connections, max_connections_per_ip
 * and idle_timeout_s.  Handlers therefore must not block: they do short
 * SQLite transactions and bounded work (bodies are at most max_body_bytes,
 * files go out as fd responses); SSE streams park (http_park.h). */
#include <arpa/inet.h>
#include <netinet/in.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/resource.h>

#include "auth.h"
#include "conn_guard.h"
#include "cors.h"
#include "host_check.h"
#include "http.h"
#include "http_park.h"
#include "callbacks.h"
#include "daemon/log.h"

pk_config pk_service_config(pk_service *s)
{
    pthread_mutex_lock(&s->mu);
    pk_config c = s->cfg;
    pthread_mutex_unlock(&s->mu);
    return c;
}

/* The next path segment at or after p: its start, and its length in *n
 * (0 at the end of the path).  Runs of '/' count as one separator. */
static const char *next_segment(const char *p, size_t *n)
{
    while (*p == '/')
        p++;
    *n = strcspn(p, "/");
    return p;
}

/* Split the path into segments; -1 if too many/long or it contains "..". */
static int split_path(pk_req *r, const char *url)
{
    r->nseg = 0;
    size_t n;
    for (const char *p = next_segment(url, &n); n; p = next_segment(p + n, &n)) {
        if (r->nseg == PK_MAX_SEGMENTS || n >= sizeof r->seg[0])
            return -1;
        memcpy(r->seg[r->nseg], p, n);
        r->seg[r->nseg][n] = 0;
        if (!strcmp(r->seg[r->nseg], "..") || !strcmp(r->seg[r->nseg], "."))
            return -1;
        r->nseg++;
    }
    return 0;
}

static int match(const pk_req *r, const char *pattern)
{
    int i = 0;
    size_t n;
    for (const char *p = next_segment(pattern, &n); n; p = next_segment(p + n, &n)) {
        if (i >= r->nseg)
            return 0;
        if (!(n == 1 && *p == '*') && (strlen(r->seg[i]) != n || strncmp(r->seg[i], p, n) != 0))
            return 0;
        i++;
    }
    return i == r->nseg;
}

/* The route of this method and path (HEAD is GET); NULL if none.  An
 * unknown path is 404; a known path with another method 405 with Allow. */
static const pk_route *find_route(pk_req *r)
{
    if (split_path(r, r->url) != 0)
        return NULL;
    for (const pk_route *rt = pk_routes; rt->method; rt++)
        if (!strcmp(rt->method, r->method) && match(r, rt->pattern))
            return rt;
    return NULL;
}

/* The methods of the routes of this path ("GET, HEAD, DELETE"); "" if none. */
static void allowed_methods(pk_req *r, char *allow, size_t size)
{
    allow[0] = 0;
    if (split_path(r, r->url) == 0)
        for (const pk_route *rt = pk_routes; rt->method; rt++) {
            if (!match(r, rt->pattern) || strstr(allow, rt->method))
                continue;
            size_t l = strlen(allow);
            snprintf(allow + l, size - l, "%s%s", l ? ", " : "", rt->method);
            if (!strcmp(rt->method, "GET") && !strstr(allow, "HEAD")) {
                l = strlen(allow);
                snprintf(allow + l, size - l, ", HEAD");
            }
        }
}

static int has_body(pk_req *r);

/* OPTIONS (RFC 9110 9.3.7) of a known path, whose methods are allow: 204
 * with Allow, and for a CORS preflight from a configured origin the methods
 * and headers it may use (cors.h).  Answered before authorisation: a
 * preflight carries no token. */
static enum MHD_Result options(pk_req *r, const char *allow)
{
    struct MHD_Response *resp = MHD_create_response_from_buffer(0, "", MHD_RESPMEM_PERSISTENT);
    if (!resp)
        return MHD_NO;
    MHD_add_response_header(resp, "Allow", allow);
    pk_config cfg = pk_service_config(r->svc);
    if (pk_header(r, "Access-Control-Request-Method"))
        pk_cors_preflight_headers(&cfg, pk_header(r, "Origin"), allow, resp);
    return pk_send(r, 204, resp);
}

static enum MHD_Result no_route(pk_req *r)
{
    char allow[128];
    allowed_methods(r, allow, sizeof allow);
    if (!allow[0])
        return pk_reply_problem(r, PK_P_NOT_FOUND, "no such resource");
    if (!strcmp(r->method, "OPTIONS") && !has_body(r))
        return options(r, allow);
    char detail[200];
    snprintf(detail, sizeof detail, "%s is not allowed here; allowed: %s", r->method, allow);
    struct MHD_Response *resp =
        pk_json_response(pk_problem(405, PK_PROBLEM_GENERIC, "Method Not Allowed", detail),
                         "application/problem+json");
    MHD_add_response_header(resp, "Allow", allow);
    return pk_send(r, 405, resp);
}

/* Routes whose body is a JSON document: anything else is refused with 415
 * before the body is read (a web page can post text/plain or form bodies
 * across origins without a preflight; it cannot post application/json). */
static const char *const json_body_routes[] = {"/processes/*/execution", NULL};

static int wants_json_body(pk_req *r)
{
    for (const char *const *p = json_body_routes; *p; p++)
        if (match(r, *p))
            return 1;
    return 0;
}

/* Why an upload's Content-Type is refused, or NULL.  A web page may post
 * text/plain and form types across origins without a preflight (the Fetch
 * standard's CORS-safelisted values), so no page of another site can store
 * a file; the type is stored and echoed, so it must be printable ASCII. */
static const char *upload_type_refused(const char *ct)
{
    static const char *const simple[] = {"text/plain", "application/x-www-form-urlencoded",
                                         "multipart/form-data", NULL};
    if (!ct || !*(ct + strspn(ct, " \t")))
        return "an upload names its data in Content-Type (application/octet-stream, "
               "application/x-hdf5, ...): none given";
    size_t len = strlen(ct);
    for (size_t i = 0; i < len; i++)
        if ((unsigned char)ct[i] < 0x20 || (unsigned char)ct[i] > 0x7e)
            return "Content-Type must be printable ASCII";
    if (len > 255)
        return "Content-Type is longer than 255 bytes";
    ct += strspn(ct, " \t");
    for (const char *const *s = simple; *s; s++) {
        size_t n = strlen(*s);
        if (!strncasecmp(ct, *s, n) && strchr(" \t;", ct[n]))
            return "an upload names its data in Content-Type (application/octet-stream, "
                   "application/x-hdf5, ...); text/plain and form bodies are refused";
    }
    return NULL;
}

/* Whether the request announces a body: a Content-Length above 0 or a
 * Transfer-Encoding (chunked). */
static int has_body(pk_req *r)
{
    const char *cl = pk_header(r, "Content-Length");
    return (cl && strtoll(cl, NULL, 10) != 0) || pk_header(r, "Transfer-Encoding");
}

/* "application/json", any case, optionally followed by parameters
 * (";charset=utf-8"). */
static int is_json_media_type(const char *ct)
{
    static const char want[] = "application/json";
    if (!ct)
        return 0;
    ct += strspn(ct, " \t");
    if (strncasecmp(ct, want, sizeof want - 1) != 0)
        return 0;
    ct += sizeof want - 1;
    ct += strspn(ct, " \t");
    return *ct == 0 || *ct == ';';
}

/* First call of a request (headers complete): the route is found and the
 * client authorised before a byte of the body is read; a request refused,
 * one for no route (404, 405) and one with a body for a route that takes
 * none (413) are answered from the headers and their body is never kept. */
static enum MHD_Result on_headers(pk_req *r)
{
    pk_config cfg = pk_service_config(r->svc);
    const pk_route *rt = find_route(r);
    enum MHD_Result refused;
    r->matched = rt;
    r->answered = 1;
    if (!pk_host_allowed(&cfg, pk_header(r, "Host")))
        return pk_reply_problem(r, PK_P_MISDIRECTED,
                                "this service does not answer to that Host name (allowed_hosts)");
    if (!rt)
        return no_route(r);
    if (!pk_authorize(r, rt->access, &refused))
        return refused;
    if (strcmp(rt->method, "POST") != 0 && has_body(r))
        return pk_reply_problem(r, PK_P_CONTENT_TOO_LARGE, "this route takes no request body");
    if (wants_json_body(r) && !is_json_media_type(pk_header(r, "Content-Type")))
        return pk_reply_problem(
            r, PK_P_UNSUPPORTED_MEDIA_TYPE,
            "this route takes a JSON body: Content-Type must be application/json"
            " (a charset parameter is allowed)");
    const char *bad_type =
        strcmp(rt->pattern, "/files") ? NULL : upload_type_refused(pk_header(r, "Content-Type"));
    if (bad_type)
        return pk_reply_problem(r, PK_P_UNSUPPORTED_MEDIA_TYPE, bad_type);
    const char *cl = pk_header(r, "Content-Length");
    if (cl && strtoll(cl, NULL, 10) > cfg.max_body_bytes) {
        char d[128];
        snprintf(d, sizeof d, "the body exceeds max_body_bytes = %ld", cfg.max_body_bytes);
        return pk_reply_problem(r, PK_P_CONTENT_TOO_LARGE, d);
    }
    r->answered = 0;
    r->route = rt;
    if (strcmp(rt->method, "POST") == 0) { /* the body's deadline grows with its size */
        double allow = cfg.body_timeout_s;
        if (cl && cfg.head_timeout_s + (double)strtoll(cl, NULL, 10) / cfg.body_min_rate < allow)
            allow = cfg.head_timeout_s + (double)strtoll(cl, NULL, 10) / cfg.body_min_rate;
        pk_conn_guard_body(r->conn, allow);
    }
    return MHD_YES;
}

/* A chunk of the body: kept unless over max_body_bytes; MHD_NO (the
 * connection is closed) once the body takes longer than body_timeout_s. */
static enum MHD_Result on_body(pk_req *r, const char *upload, size_t n)
{
    pk_config cfg = pk_service_config(r->svc);
    if (pk_queue_now() - r->started > cfg.body_timeout_s) {
        pk_log(PK_LOG_WARN, "request body too slow; connection closed", "{s:s,s:s,s:f}", "method",
               r->method, "url", r->url, "body_timeout_s", cfg.body_timeout_s);
        return MHD_NO;
    }
    if (r->answered || r->too_large)
        return MHD_YES;
    if ((long)(r->body_len + n) > cfg.max_body_bytes) {
        r->too_large = 1;
        free(r->body);
        r->body = NULL;
        r->body_len = r->body_cap = 0;
        return MHD_YES;
    }
    if (r->body_len + n + 1 > r->body_cap) {
        size_t cap = (r->body_len + n + 1) * 2;
        char *nb = realloc(r->body, cap);
        if (!nb)
            return MHD_NO;
        r->body = nb;
        r->body_cap = cap;
    }
    memcpy(r->body + r->body_len, upload, n);
    r->body_len += n;
    r->body[r->body_len] = 0;
    return MHD_YES;
}

static enum MHD_Result on_request(void *cls, struct MHD_Connection *conn, const char *url,
                                  const char *method, const char *version, const char *upload,
                                  size_t *upload_size, void **con_cls)
{
    pk_service *svc = cls;
    pk_req *r = *con_cls;
    (void)version;
    if (!r) {
        r = calloc(1, sizeof *r);
        if (!r)
            return MHD_NO;
        r->conn = conn;
        r->svc = svc;
        r->url = url;
        r->method = !strcmp(method, "HEAD") ? "GET" : method;
        r->started = pk_queue_now();
        *con_cls = r;
        enum MHD_Result rc = on_headers(r);
        if (!r->route || strcmp(r->route->method, "POST") != 0)
            pk_conn_guard_response(conn);
        return rc;
    }
    if (*upload_size) {
        enum MHD_Result rc = on_body(r, upload, *upload_size);
        *upload_size = 0;
        return rc;
    }
    if (r->answered)
        return MHD_YES;
    if (r->resume)
        return r->resume(r);
    pk_conn_guard_response(conn);
    if (r->too_large) {
        pk_config cfg = pk_service_config(svc);
        char d[128];
        snprintf(d, sizeof d, "the body exceeds max_body_bytes = %ld", cfg.max_body_bytes);
        return pk_reply_problem(r, PK_P_CONTENT_TOO_LARGE, d);
    }
    return r->route->handler(r);
}

static void on_completed(void *cls, struct MHD_Connection *conn, void **con_cls,
                         enum MHD_RequestTerminationCode toe)
{
    pk_req *r = *con_cls;
    pk_conn_guard_head(conn); /* kept alive: the next head has head_timeout_s */
    if (r) {
        if (r->wait_free)
            r->wait_free(r->wait);
        free(r->body);
        free(r);
    }
    *con_cls = NULL;
}

static void mhd_log(void *cls, const char *fmt, va_list ap)
{
    char msg[512];
    vsnprintf(msg, sizeof msg, fmt, ap);
    msg[strcspn(msg, "\n")] = 0;
    pk_log(PK_LOG_WARN, "http", "{s:s}", "detail", msg);
}

/* Every connection is a file descriptor: lift the soft limit to the hard one,
 * and keep max_connections below it with room for the database, the
 * workers' pipes and MHD's own descriptors. */
static unsigned connection_limit(const pk_config *cfg)
{
    struct rlimit rl;
    unsigned want = (unsigned)cfg->max_connections;
    if (getrlimit(RLIMIT_NOFILE, &rl) != 0)
        return want;
    if (rl.rlim_cur < rl.rlim_max) {
        rlim_t was = rl.rlim_cur;
        rl.rlim_cur = rl.rlim_max;
        if (setrlimit(RLIMIT_NOFILE, &rl) != 0)
            rl.rlim_cur = was;
    }
    rlim_t reserve = 64 + 4 * (rlim_t)cfg->workers + 8 * (rlim_t)cfg->http_threads;
    rlim_t fit = rl.rlim_cur > 2 * reserve ? rl.rlim_cur - reserve : rl.rlim_cur / 2;
    if (rl.rlim_cur != RLIM_INFINITY && want > fit) {
        pk_log(PK_LOG_WARN, "max_connections lowered to fit the open-files limit", "{s:i,s:I,s:I}",
               "max_connections", cfg->max_connections, "nofile", (json_int_t)rl.rlim_cur, "used",
               (json_int_t)fit);
        want = (unsigned)fit;
    }
    return want;
}

struct MHD_Daemon *pk_http_start(pk_service *svc, int *port, char *err, size_t errlen)
{
    pk_config cfg = pk_service_config(svc);
    struct sockaddr_in addr;
    memset(&addr, 0, sizeof addr);
    addr.sin_family = AF_INET;
    addr.sin_port = htons((uint16_t)cfg.port);
    if (inet_pton(AF_INET, cfg.bind, &addr.sin_addr) != 1) {
        snprintf(err, errlen, "bind: '%s' is not an IPv4 address", cfg.bind);
        return NULL;
    }
    if (pk_park_start(svc) != 0) {
        snprintf(err, errlen, "cannot start the stream waker thread");
        return NULL;
    }
    if (pk_callbacks_start(svc) != 0) {
        pk_park_stop();
        snprintf(err, errlen, "cannot start the callback thread");
        return NULL;
    }
    unsigned limit = connection_limit(&cfg);
    if (pk_conn_guard_start(svc, limit) != 0) {
        pk_callbacks_stop();
        pk_park_stop();
        snprintf(err, errlen, "cannot start the connection deadline thread");
        return NULL;
    }
    struct MHD_Daemon *d = MHD_start_daemon(
        MHD_USE_EPOLL_INTERNAL_THREAD | MHD_ALLOW_SUSPEND_RESUME | MHD_USE_ERROR_LOG,
        (uint16_t)cfg.port, NULL, NULL, on_request, svc, MHD_OPTION_EXTERNAL_LOGGER, mhd_log, NULL,
        MHD_OPTION_SOCK_ADDR, (struct sockaddr *)&addr, MHD_OPTION_NOTIFY_COMPLETED, on_completed,
        NULL, MHD_OPTION_THREAD_POOL_SIZE, (unsigned)cfg.http_threads, MHD_OPTION_CONNECTION_LIMIT,
        limit, MHD_OPTION_PER_IP_CONNECTION_LIMIT, (unsigned)cfg.max_connections_per_ip,
        MHD_OPTION_CONNECTION_TIMEOUT, (unsigned)cfg.idle_timeout_s, MHD_OPTION_NOTIFY_CONNECTION,
        pk_conn_guard_notify, NULL, MHD_OPTION_END);
    if (!d) {
        pk_conn_guard_stop();
        pk_callbacks_stop();
        pk_park_stop();
        snprintf(err, errlen, "cannot listen on %s:%d (in use or not permitted)", cfg.bind,
                 cfg.port);
        return NULL;
    }
    const union MHD_DaemonInfo *info = MHD_get_daemon_info(d, MHD_DAEMON_INFO_BIND_PORT);
    *port = info ? info->port : cfg.port;
    pk_log(PK_LOG_INFO, "http", "{s:i,s:i,s:i,s:i,s:i,s:f}", "threads", cfg.http_threads,
           "max_connections", (int)limit, "evict_slowest_above",
           (int)pk_conn_guard_threshold(limit), "max_connections_per_ip",
           cfg.max_connections_per_ip, "idle_timeout_s", cfg.idle_timeout_s, "head_timeout_s",
           cfg.head_timeout_s);
    return d;
}

void pk_http_stop(struct MHD_Daemon *d)
{
    pk_park_stop(); /* resumes every parked stream: MHD must not stop with suspended ones */
    pk_callbacks_stop();
    pk_conn_guard_stop();
    MHD_stop_daemon(d);
}
