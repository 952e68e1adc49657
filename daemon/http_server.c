/* http_server.c — libmicrohttpd set-up, request bodies (with the size limit)
 * and dispatch through the route table: unknown path 404, known path with
 * another method 405 + Allow. */
#include <arpa/inet.h>
#include <netinet/in.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "auth.h"
#include "http.h"
#include "log.h"

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

static enum MHD_Result dispatch(pk_req *r)
{
    if (split_path(r, r->url) != 0)
        return pk_send_problem(r, 404, PK_PROBLEM_GENERIC, "Not Found", "no such resource", NULL, 0);
    char allow[128] = "";
    for (const pk_route *rt = pk_routes; rt->method; rt++) {
        if (!match(r, rt->pattern))
            continue;
        if (!strcmp(rt->method, r->method)) {
            enum MHD_Result refused;
            return pk_authorize(r, rt->access, &refused) ? rt->handler(r) : refused;
        }
        if (!strstr(allow, rt->method)) {
            size_t l = strlen(allow);
            snprintf(allow + l, sizeof allow - l, "%s%s", l ? ", " : "", rt->method);
            if (!strcmp(rt->method, "GET") && !strstr(allow, "HEAD")) {
                l = strlen(allow);
                snprintf(allow + l, sizeof allow - l, ", HEAD");
            }
        }
    }
    if (!allow[0])
        return pk_send_problem(r, 404, PK_PROBLEM_GENERIC, "Not Found", "no such resource", NULL, 0);
    char detail[200];
    snprintf(detail, sizeof detail, "%s is not allowed here; allowed: %s", r->method, allow);
    struct MHD_Response *resp = pk_json_response(
        pk_problem(405, PK_PROBLEM_GENERIC, "Method Not Allowed", detail), "application/problem+json");
    MHD_add_response_header(resp, "Allow", allow);
    return pk_send(r, 405, resp);
}

static enum MHD_Result on_request(void *cls, struct MHD_Connection *conn, const char *url,
                                  const char *method, const char *version, const char *upload,
                                  size_t *upload_size, void **con_cls)
{
    pk_service *svc = cls;
    pk_req *r = *con_cls;
    if (!r) {
        r = calloc(1, sizeof *r);
        if (!r)
            return MHD_NO;
        r->conn = conn;
        r->svc = svc;
        r->url = url;
        r->method = !strcmp(method, "HEAD") ? "GET" : method;
        *con_cls = r;
        const char *cl = MHD_lookup_connection_value(conn, MHD_HEADER_KIND, "Content-Length");
        pk_config cfg = pk_service_config(svc);
        if (cl && strtoll(cl, NULL, 10) > cfg.max_body_bytes) {
            r->too_large = 2; /* answered before reading the body */
            char d[128];
            snprintf(d, sizeof d, "the body exceeds max_body_bytes = %ld", cfg.max_body_bytes);
            return pk_send_problem(r, 413, PK_PROBLEM_GENERIC, "Content Too Large", d, NULL, 0);
        }
        return MHD_YES;
    }
    if (*upload_size) {
        if (r->too_large != 2 && !r->too_large) {
            pk_config cfg = pk_service_config(svc);
            if ((long)(r->body_len + *upload_size) > cfg.max_body_bytes) {
                r->too_large = 1;
                free(r->body);
                r->body = NULL;
                r->body_len = r->body_cap = 0;
            } else {
                if (r->body_len + *upload_size + 1 > r->body_cap) {
                    size_t cap = (r->body_len + *upload_size + 1) * 2;
                    char *nb = realloc(r->body, cap);
                    if (!nb)
                        return MHD_NO;
                    r->body = nb;
                    r->body_cap = cap;
                }
                memcpy(r->body + r->body_len, upload, *upload_size);
                r->body_len += *upload_size;
                r->body[r->body_len] = 0;
            }
        }
        *upload_size = 0;
        return MHD_YES;
    }
    if (r->too_large == 2)
        return MHD_YES;
    if (r->too_large) {
        pk_config cfg = pk_service_config(svc);
        char d[128];
        snprintf(d, sizeof d, "the body exceeds max_body_bytes = %ld", cfg.max_body_bytes);
        return pk_send_problem(r, 413, PK_PROBLEM_GENERIC, "Content Too Large", d, NULL, 0);
    }
    (void)version;
    return dispatch(r);
}

static void on_completed(void *cls, struct MHD_Connection *conn, void **con_cls,
                         enum MHD_RequestTerminationCode toe)
{
    pk_req *r = *con_cls;
    if (r) {
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
    struct MHD_Daemon *d = MHD_start_daemon(
        MHD_USE_INTERNAL_POLLING_THREAD | MHD_USE_THREAD_PER_CONNECTION | MHD_USE_ERROR_LOG |
            MHD_USE_ITC,
        (uint16_t)cfg.port, NULL, NULL, on_request, svc,
        MHD_OPTION_EXTERNAL_LOGGER, mhd_log, NULL,
        MHD_OPTION_SOCK_ADDR, (struct sockaddr *)&addr,
        MHD_OPTION_NOTIFY_COMPLETED, on_completed, NULL,
        MHD_OPTION_CONNECTION_LIMIT, (unsigned)256,
        MHD_OPTION_CONNECTION_TIMEOUT, (unsigned)120,
        MHD_OPTION_END);
    if (!d) {
        snprintf(err, errlen, "cannot listen on %s:%d (in use or not permitted)", cfg.bind, cfg.port);
        return NULL;
    }
    const union MHD_DaemonInfo *info = MHD_get_daemon_info(d, MHD_DAEMON_INFO_BIND_PORT);
    *port = info ? info->port : cfg.port;
    return d;
}
