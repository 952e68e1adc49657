/* http_reply.c — the reply helpers of http.h: JSON, problem+json, files
 * (Content-Length, ETag, SHA-256 headers, single byte ranges). */
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "cors.h"
#include "http.h"
#include "http_durations.h"
#include "daemon/data_paths.h"
#include "daemon/log.h"
#include "api/digest.h"

/* The base of absolute links: public_url, else http://<Host> when the Host
 * header is a plain host[:port], else http://localhost. */
void pk_base_url(pk_req *r, char *out, size_t n)
{
    pk_config cfg = pk_service_config(r->svc);
    const char *host = pk_header(r, "Host");
    if (cfg.public_url[0]) {
        size_t len = strlen(cfg.public_url);
        while (len && cfg.public_url[len - 1] == '/')
            len--;
        snprintf(out, n, "%.*s", (int)len, cfg.public_url);
    } else if (host && *host && strlen(host) < 200 &&
               host[strspn(
                   host, "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789.-:[]")] ==
                   0)
        snprintf(out, n, "http://%s", host);
    else
        snprintf(out, n, "http://localhost");
}

static void absolute_hrefs(json_t *node, const char *base)
{
    const char *key;
    json_t *v;
    size_t i;
    if (json_is_array(node))
        json_array_foreach (node, i, v)
            absolute_hrefs(v, base);
    json_object_foreach (node, key, v) {
        const char *s = json_string_value(v);
        if (!strcmp(key, "href") && s && s[0] == '/') {
            char *abs = malloc(strlen(base) + strlen(s) + 1);
            if (abs) {
                strcpy(abs, base);
                strcat(abs, s);
                json_object_set_new(node, key, json_string(abs));
                free(abs);
            }
        } else if (json_is_object(v) || json_is_array(v)) {
            absolute_hrefs(v, base);
        }
    }
}

/* hrefs under base back to paths; others stay (and are refused later). */
static void relative_hrefs(json_t *node, const char *base, size_t bl)
{
    const char *key;
    json_t *v;
    size_t i;
    if (json_is_array(node))
        json_array_foreach (node, i, v)
            relative_hrefs(v, base, bl);
    json_object_foreach (node, key, v) {
        const char *s = json_string_value(v);
        if (!strcmp(key, "href") && s && !strncmp(s, base, bl) && s[bl] == '/')
            json_object_set_new(node, key, json_string(s + bl));
        else if (json_is_object(v) || json_is_array(v))
            relative_hrefs(v, base, bl);
    }
}

void pk_own_links_as_paths(pk_req *r, json_t *inputs)
{
    char base[300];
    pk_base_url(r, base, sizeof base);
    relative_hrefs(inputs, base, strlen(base));
}

void pk_absolute_links(pk_req *r, json_t *doc)
{
    char base[300];
    pk_base_url(r, base, sizeof base);
    absolute_hrefs(doc, base);
}

void pk_absolute_links_at(json_t *doc, const char *base) { absolute_hrefs(doc, base); }

/* A document as a client sees it: no path of the data directory, links absolute. */
void pk_client_view(pk_req *r, json_t *doc)
{
    pk_config cfg = pk_service_config(r->svc);
    pk_hide_data_paths_json(doc, cfg.data);
    pk_absolute_links(r, doc);
}

enum MHD_Result pk_send(pk_req *r, unsigned status, struct MHD_Response *resp)
{
    if (!resp)
        return MHD_NO;
    const char *loc = MHD_get_response_header(resp, "Location");
    if (loc && loc[0] == '/') { /* RFC 9110 allows relative; OGC clients need absolute */
        char base[300], abs[800], rel[500];
        pk_base_url(r, base, sizeof base);
        snprintf(rel, sizeof rel, "%s", loc);
        snprintf(abs, sizeof abs, "%s%s", base, rel);
        MHD_del_response_header(resp, "Location", loc);
        MHD_add_response_header(resp, "Location", abs);
    }
    if (r->sync_job[0]) { /* OGC /req/core/job-results-success-sync: a monitor link to the job */
        char base[300], link[500];
        pk_base_url(r, base, sizeof base);
        snprintf(link, sizeof link, "<%s/jobs/%s>; rel=\"monitor\"", base, r->sync_job);
        MHD_add_response_header(resp, "Link", link);
        MHD_add_response_header(resp, "Preference-Applied", "respond-sync");
    }
    if (status < 600)
        __atomic_add_fetch(&r->svc->responses[status], 1, __ATOMIC_RELAXED);
    pk_config cfg = pk_service_config(r->svc);
    pk_cors_response_headers(&cfg, pk_header(r, "Origin"), resp);
    pk_http_duration_observe(r->matched, status, pk_queue_now() - r->started);
    MHD_add_response_header(resp, "Server", "packd/" PACKD_VERSION);
    MHD_add_response_header(resp, "X-Content-Type-Options", "nosniff");
    enum MHD_Result rc = MHD_queue_response(r->conn, status, resp);
    MHD_destroy_response(resp);
    pk_log(PK_LOG_DEBUG, "request", "{s:s,s:s,s:i}", "method", r->method, "url", r->url, "status",
           (int)status);
    return rc;
}

struct MHD_Response *pk_json_response(json_t *body, const char *ctype)
{
    char *text = json_dumps(body, JSON_INDENT(2) | JSON_PRESERVE_ORDER | JSON_REAL_PRECISION(10));
    json_decref(body);
    if (!text)
        return NULL;
    size_t n = strlen(text);
    text[n] = 0;
    char *withnl = realloc(text, n + 2);
    if (withnl) {
        text = withnl;
        text[n++] = '\n';
        text[n] = 0;
    }
    struct MHD_Response *resp = MHD_create_response_from_buffer(n, text, MHD_RESPMEM_MUST_FREE);
    if (resp)
        MHD_add_response_header(resp, "Content-Type", ctype);
    return resp;
}

enum MHD_Result pk_send_json(pk_req *r, unsigned status, json_t *body, const char *etag)
{
    pk_client_view(r, body);
    struct MHD_Response *resp = pk_json_response(body, "application/json");
    if (resp && etag)
        MHD_add_response_header(resp, "ETag", etag);
    return pk_send(r, status, resp);
}

enum MHD_Result pk_send_text(pk_req *r, unsigned status, const char *ctype, const char *text)
{
    struct MHD_Response *resp =
        MHD_create_response_from_buffer(strlen(text), (void *)text, MHD_RESPMEM_MUST_COPY);
    if (resp)
        MHD_add_response_header(resp, "Content-Type", ctype);
    return pk_send(r, status, resp);
}

enum MHD_Result pk_send_problem_doc(pk_req *r, unsigned status, json_t *doc, int retry_after)
{
    pk_client_view(r, doc);
    struct MHD_Response *resp = pk_json_response(doc, "application/problem+json");
    if (resp && retry_after > 0) {
        char ra[32];
        snprintf(ra, sizeof ra, "%d", retry_after);
        MHD_add_response_header(resp, "Retry-After", ra);
    }
    return pk_send(r, status, resp);
}

enum MHD_Result pk_send_problem(pk_req *r, unsigned status, const char *type, const char *title,
                                const char *detail, json_t *extra, int retry_after)
{
    json_t *doc = pk_problem((int)status, type, title, detail);
    if (extra) {
        json_object_update(doc, extra);
        json_decref(extra);
    }
    return pk_send_problem_doc(r, status, doc, retry_after);
}

enum MHD_Result pk_reply_problem(pk_req *r, pk_problem_code code, const char *detail)
{
    return pk_send_problem_doc(r, pk_problem_status(code), pk_problem_of(code, detail), 0);
}

const char *pk_header(pk_req *r, const char *name)
{
    return MHD_lookup_connection_value(r->conn, MHD_HEADER_KIND, name);
}

const char *pk_query(pk_req *r, const char *name)
{
    return MHD_lookup_connection_value(r->conn, MHD_GET_ARGUMENT_KIND, name);
}

void pk_owner(pk_req *r, char *out, size_t n) { snprintf(out, n, "%s", r->owner); }

/* "bytes=a-b" | "bytes=a-" | "bytes=-n" → [*from, *to]; 0 ok, -1 unsatisfiable,
 * 1 ignore (malformed or multi-range: serve the whole file). */
static int parse_range(const char *h, long long size, long long *from, long long *to)
{
    if (strncmp(h, "bytes=", 6) != 0 || strchr(h, ','))
        return 1;
    const char *p = h + 6;
    char *end;
    if (*p == '-') {
        long long n = strtoll(p + 1, &end, 10);
        if (*end || end == p + 1)
            return 1;
        if (n <= 0 || size == 0)
            return -1;
        *from = n >= size ? 0 : size - n;
        *to = size - 1;
        return 0;
    }
    long long a = strtoll(p, &end, 10);
    if (end == p || *end != '-' || a < 0)
        return 1;
    const char *q = end + 1;
    long long b = size - 1;
    if (*q) {
        b = strtoll(q, &end, 10);
        if (*end || b < a)
            return 1;
    }
    if (a >= size)
        return -1;
    *from = a;
    *to = b >= size ? size - 1 : b;
    return 0;
}

enum MHD_Result pk_send_file(pk_req *r, const char *path, const char *ctype, const char *sha256_hex,
                             const char *download_name)
{
    int fd = open(path, O_RDONLY | O_CLOEXEC);
    struct stat st;
    if (fd < 0 || fstat(fd, &st) != 0) {
        if (fd >= 0)
            close(fd);
        return pk_reply_problem(r, PK_P_NOT_FOUND, "the file is gone");
    }
    char etag[80];
    snprintf(etag, sizeof etag, "\"%s\"", sha256_hex);
    const char *inm = pk_header(r, "If-None-Match");
    if (inm && (strstr(inm, etag) || !strcmp(inm, "*"))) {
        close(fd);
        struct MHD_Response *resp = MHD_create_response_from_buffer(0, "", MHD_RESPMEM_PERSISTENT);
        MHD_add_response_header(resp, "ETag", etag);
        return pk_send(r, 304, resp);
    }
    long long size = st.st_size, from = 0, to = size - 1;
    unsigned status = 200;
    const char *range = pk_header(r, "Range");
    const char *if_range = pk_header(r, "If-Range");
    if (range && (!if_range || !strcmp(if_range, etag))) {
        int pr = parse_range(range, size, &from, &to);
        if (pr < 0) {
            close(fd);
            char cr[64];
            snprintf(cr, sizeof cr, "bytes */%lld", size);
            struct MHD_Response *resp = pk_json_response(
                pk_problem(416, PK_PROBLEM_GENERIC, "Range Not Satisfiable", range),
                "application/problem+json");
            MHD_add_response_header(resp, "Content-Range", cr);
            return pk_send(r, 416, resp);
        }
        if (pr == 0)
            status = 206;
        else
            from = 0, to = size - 1;
    }
    struct MHD_Response *resp =
        MHD_create_response_from_fd_at_offset64((uint64_t)(to - from + 1), fd, (uint64_t)from);
    if (!resp) {
        close(fd);
        return MHD_NO;
    }
    unsigned char digest[32];
    char b64[48], digest_hdr[80], disp[200];
    if (pk_sha256_from_hex(sha256_hex, digest) == 0) {
        pk_base64(digest, 32, b64);
        snprintf(digest_hdr, sizeof digest_hdr, "sha-256=:%s:", b64);
        MHD_add_response_header(resp, "Repr-Digest", digest_hdr);
    }
    MHD_add_response_header(resp, "X-Content-SHA256", sha256_hex);
    MHD_add_response_header(resp, "Content-Type", ctype);
    MHD_add_response_header(resp, "ETag", etag);
    MHD_add_response_header(resp, "Accept-Ranges", "bytes");
    /* a file is data: opened by mistake as a page, it runs no script */
    MHD_add_response_header(resp, "Content-Security-Policy", "sandbox; default-src 'none'");
    if (download_name) {
        snprintf(disp, sizeof disp, "attachment; filename=\"%s\"", download_name);
        MHD_add_response_header(resp, "Content-Disposition", disp);
    }
    if (status == 206) {
        char cr[96];
        snprintf(cr, sizeof cr, "bytes %lld-%lld/%lld", from, to, size);
        MHD_add_response_header(resp, "Content-Range", cr);
    }
    return pk_send(r, status, resp);
}
