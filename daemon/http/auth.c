/* auth.c — bearer-token authorisation and owner scoping of every request.
 * Contract: daemon/http/auth.h. */
#include "auth.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <stdio.h>
#include <string.h>
#include <strings.h>

#include "daemon/store/tokens.h"

static int is_loopback(const char *addr)
{
    struct in_addr a4;
    struct in6_addr a6;
    if (inet_pton(AF_INET, addr, &a4) == 1)
        return (ntohl(a4.s_addr) >> 24) == 127;
    return inet_pton(AF_INET6, addr, &a6) == 1 && IN6_IS_ADDR_LOOPBACK(&a6);
}

int pk_auth_required(const pk_config *c, const char **why)
{
    const char *w;
    int on;
    if (c->auth == PK_AUTH_ON) {
        on = 1,
        w = "auth = on: every route but /, /conformance, /api and /healthz needs a bearer token";
    } else if (c->auth == PK_AUTH_OFF) {
        on = 0,
        w = c->trusted_proxy[0]
            ? "auth = off behind a trusted proxy: everyone who reaches the proxy may read, submit "
              "and dismiss every job, as any owner"
            : "auth = off: every client that reaches the port may read, submit and dismiss every "
              "job";
    } else if (c->trusted_proxy[0]) {
        /* a proxy on this host forwards whoever reaches it: loopback says nothing of who */
        on = 1,
        w = "auth = auto and a trusted proxy is configured: the proxy forwards clients from "
            "elsewhere, so every route but /, /conformance, /api and /healthz needs a bearer token";
    } else if (is_loopback(c->bind)) {
        on = 0,
        w = "auth = auto, bind is a loopback address and no trusted proxy is configured: only "
            "processes on this host can connect (any local forwarder opens it further), and every "
            "local user may read, submit and dismiss every job (auth = on to require tokens)";
    } else {
        on = 1,
        w = "auth = auto and bind is not a loopback address: every route but /, /conformance, "
            "/api and /healthz needs a bearer token";
    }
    if (why)
        *why = w;
    return on;
}

static void peer_address(pk_req *r, char *out, size_t n)
{
    const union MHD_ConnectionInfo *ci =
        MHD_get_connection_info(r->conn, MHD_CONNECTION_INFO_CLIENT_ADDRESS);
    snprintf(out, n, "unknown");
    const struct sockaddr *sa = ci ? ci->client_addr : NULL;
    if (sa && sa->sa_family == AF_INET)
        inet_ntop(AF_INET, &((const struct sockaddr_in *)sa)->sin_addr, out, (socklen_t)n);
    else if (sa && sa->sa_family == AF_INET6)
        inet_ntop(AF_INET6, &((const struct sockaddr_in6 *)sa)->sin6_addr, out, (socklen_t)n);
}

/* "Bearer <token>" (RFC 6750 section 2.1); NULL for any other scheme or none. */
static const char *bearer(pk_req *r, char *buf, size_t n)
{
    const char *h = pk_header(r, "Authorization");
    if (!h)
        return NULL;
    h += strspn(h, " \t");
    if (strncasecmp(h, "Bearer", 6) != 0 || (h[6] != ' ' && h[6] != '\t'))
        return NULL;
    h += 6;
    h += strspn(h, " \t");
    snprintf(buf, n, "%s", h);
    size_t l = strlen(buf);
    while (l && (buf[l - 1] == ' ' || buf[l - 1] == '\t'))
        buf[--l] = 0;
    return buf;
}

static enum MHD_Result refuse(pk_req *r, unsigned status, const char *type, const char *title,
                              const char *detail, const char *challenge)
{
    struct MHD_Response *resp =
        pk_json_response(pk_problem((int)status, type, title, detail), "application/problem+json");
    if (resp && challenge)
        MHD_add_response_header(resp, "WWW-Authenticate", challenge);
    return pk_send(r, status, resp);
}

/* A name a trusted proxy may give: printable ASCII without spaces, < 128 bytes. */
static int owner_ok(const char *s)
{
    size_t n = strlen(s);
    if (n == 0 || n >= sizeof((pk_req *)0)->owner)
        return 0;
    for (size_t i = 0; i < n; i++)
        if (s[i] <= ' ' || s[i] > '~')
            return 0;
    return 1;
}

int pk_authorize(pk_req *r, pk_access access, enum MHD_Result *reply)
{
    pk_config cfg = pk_service_config(r->svc);
    char peer[64];
    peer_address(r, peer, sizeof peer);
    /* X-Packd-Owner only from the configured proxy: anyone else could name any owner. */
    const char *named = cfg.trusted_proxy[0] && !strcmp(peer, cfg.trusted_proxy)
        ? pk_header(r, "X-Packd-Owner")
        : NULL;
    if (named && !*named)
        named = NULL;
    if (named && !owner_ok(named)) {
        *reply = pk_reply_problem(r, PK_P_BAD_REQUEST,
                                  "X-Packd-Owner: 1 to 127 printable characters without spaces");
        return 0;
    }
    snprintf(r->owner, sizeof r->owner, "%s", named ? named : peer);
    if (access == PK_PUBLIC || !pk_auth_required(&cfg, NULL)) {
        /* Public routes show no job data; with auth off every client may do
         * everything, and the owner only scopes quotas and idempotency keys. */
        r->admin = 1;
        return 1;
    }
    char buf[256], name[PK_TOKEN_NAME_MAX];
    const char *token = bearer(r, buf, sizeof buf);
    if (!token || !*token) {
        *reply = refuse(r, 401, PK_PROBLEM_PACKD "unauthorized", "Unauthorized",
                        "this route needs a bearer token: Authorization: Bearer <token>",
                        "Bearer realm=\"packd\"");
        return 0;
    }
    int admin = 0, ok = pk_tokens_verify(r->svc->tokens, token, name, &admin);
    if (ok < 0) {
        *reply = pk_send_problem(r, 503, PK_PROBLEM_GENERIC, "Service Unavailable",
                                 "cannot check the token: the database does not answer", NULL, 5);
        return 0;
    }
    if (!ok) {
        *reply = refuse(r, 401, PK_PROBLEM_PACKD "unauthorized", "Unauthorized",
                        "the bearer token is unknown or revoked",
                        "Bearer realm=\"packd\", error=\"invalid_token\", "
                        "error_description=\"unknown or revoked token\"");
        return 0;
    }
    /* Through the proxy the named person acts, with a user's rights only. */
    if (!named)
        snprintf(r->owner, sizeof r->owner, "%s", name);
    r->admin = admin && !named;
    if (access == PK_ADMIN && !r->admin) {
        *reply = refuse(r, 403, PK_PROBLEM_PACKD "forbidden", "Forbidden",
                        "this route needs an admin token",
                        "Bearer realm=\"packd\", error=\"insufficient_scope\"");
        return 0;
    }
    return 1;
}

const char *pk_scope(const pk_req *r) { return r->admin ? NULL : r->owner; }

json_t *pk_job_visible(pk_req *r, const char *id)
{
    json_t *row = pk_queue_get(r->svc->q, id);
    const char *scope = pk_scope(r);
    if (row && scope && strcmp(json_string_value(json_object_get(row, "owner")), scope) != 0) {
        json_decref(row);
        return NULL;
    }
    return row;
}
