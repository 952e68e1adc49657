/* client_http.c — the command-line client's HTTP requests, hashed downloads
 * and SSE over libcurl; contract in client_http.h. */
#include "client_http.h"

#include <curl/curl.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "api/digest.h"

#ifndef PACKD_VERSION
#define PACKD_VERSION "0.0.0"
#endif

void pk_reply_free(pk_reply *r)
{
    free(r->body);
    r->body = NULL;
    r->len = 0;
}

json_t *pk_reply_json(const pk_reply *r)
{
    return r->body ? json_loadb(r->body, r->len, 0, NULL) : NULL;
}

/* ---------------------------------------------------------------- sinks */

typedef struct sink {
    pk_reply *r;
    FILE *file;    /* download target, or NULL: collect into r->body */
    pk_sha256 *md; /* hash of what goes to file */
    int write_failed;
    /* SSE */
    pk_sse_fn fn;
    void *ctx;
    char *line; /* partial line */
    size_t nline;
    char event[64], id[64];
    char *data;
    size_t ndata;
    int stopped;
} sink;

static int append(char **p, size_t *n, const char *d, size_t k)
{
    char *q = realloc(*p, *n + k + 1);
    if (!q)
        return -1;
    memcpy(q + *n, d, k);
    *n += k;
    q[*n] = 0;
    *p = q;
    return 0;
}

/* One line of a text/event-stream (without its newline): field lines build
 * the event, an empty line dispatches it (the WHATWG event-stream rules). */
static void sse_line(sink *s, char *line)
{
    if (!*line) {
        if (s->data && !s->stopped &&
            s->fn(s->event[0] ? s->event : "message", s->data, s->id, s->ctx))
            s->stopped = 1;
        free(s->data);
        s->data = NULL;
        s->ndata = 0;
        s->event[0] = 0;
        return;
    }
    if (*line == ':')
        return; /* comment (keep-alive) */
    char *v = strchr(line, ':');
    if (v) {
        *v++ = 0;
        if (*v == ' ')
            v++;
    } else {
        v = line + strlen(line);
    }
    if (!strcmp(line, "event"))
        snprintf(s->event, sizeof s->event, "%s", v);
    else if (!strcmp(line, "id"))
        snprintf(s->id, sizeof s->id, "%s", v);
    else if (!strcmp(line, "data")) {
        if (s->data)
            append(&s->data, &s->ndata, "\n", 1);
        else
            append(&s->data, &s->ndata, "", 0);
        append(&s->data, &s->ndata, v, strlen(v));
    }
}

static size_t on_body(char *d, size_t size, size_t nmemb, void *p)
{
    sink *s = p;
    size_t k = size * nmemb;
    int ok2xx = s->r->status == 0 || (s->r->status >= 200 && s->r->status < 300);
    if (!ok2xx || (!s->file && !s->fn)) { /* collect (documents, problems) */
        if (append(&s->r->body, &s->r->len, d, k) != 0)
            return 0;
        return k;
    }
    if (s->file) {
        if (fwrite(d, 1, k, s->file) != k) {
            s->write_failed = errno ? errno : EIO;
            return 0;
        }
        pk_sha256_update(s->md, d, k);
        s->r->len += k;
        return k;
    }
    for (size_t i = 0; i < k; i++) {
        if (d[i] == '\n') {
            if (s->nline && s->line[s->nline - 1] == '\r')
                s->line[--s->nline] = 0;
            append(&s->line, &s->nline, "", 0);
            sse_line(s, s->line);
            s->nline = 0;
            if (s->stopped)
                return 0; /* ends the transfer */
        } else if (append(&s->line, &s->nline, d + i, 1) != 0) {
            return 0;
        }
    }
    s->r->len += k;
    return k;
}

static size_t on_header(char *d, size_t size, size_t nmemb, void *p)
{
    sink *s = p;
    size_t k = size * nmemb;
    if (k > 5 && !strncmp(d, "HTTP/", 5)) { /* a new response (after a redirect or 100) */
        s->r->status = strtol(strchr(d, ' ') ? strchr(d, ' ') + 1 : d, NULL, 10);
        s->r->sha256_header[0] = 0;
        return k;
    }
    static const char name[] = "x-content-sha256:";
    if (k > sizeof name - 1 && !strncasecmp(d, name, sizeof name - 1)) {
        const char *v = d + sizeof name - 1;
        while (*v == ' ' || *v == '\t')
            v++;
        size_t n = 0;
        while (n < 64 && v + n < d + k && v[n] != '\r' && v[n] != '\n' && v[n] != ' ')
            n++;
        memcpy(s->r->sha256_header, v, n);
        s->r->sha256_header[n] = 0;
    }
    return k;
}

/* ----------------------------------------------------------- transfers */

enum mode { COLLECT, DOWNLOAD, STREAM };

static int perform(const pk_client *c, const char *method, const char *path, const char *body,
                   const char *last_event_id, enum mode mode, sink *s)
{
    static int inited;
    if (!inited) {
        curl_global_init(CURL_GLOBAL_DEFAULT);
        inited = 1;
    }
    pk_reply *r = s->r;
    r->status = 0;
    r->error[0] = 0;
    r->sha256_header[0] = 0;
    CURL *h = curl_easy_init();
    if (!h) {
        snprintf(r->error, sizeof r->error, "cannot initialise libcurl");
        return -1;
    }
    char url[2048];
    if (!strncmp(path, "http://", 7) || !strncmp(path, "https://", 8))
        snprintf(url, sizeof url, "%s", path);
    else {
        size_t n = strlen(c->server);
        while (n && c->server[n - 1] == '/')
            n--;
        snprintf(url, sizeof url, "%.*s%s", (int)n, c->server, path);
    }
    struct curl_slist *hdr = NULL;
    char line[1200];
    if (c->token && *c->token) {
        snprintf(line, sizeof line, "Authorization: Bearer %s", c->token);
        hdr = curl_slist_append(hdr, line);
    }
    if (body)
        hdr = curl_slist_append(hdr, "Content-Type: application/json");
    if (mode == STREAM) {
        hdr = curl_slist_append(hdr, "Accept: text/event-stream");
        if (last_event_id && *last_event_id) {
            snprintf(line, sizeof line, "Last-Event-ID: %s", last_event_id);
            hdr = curl_slist_append(hdr, line);
        }
    } else {
        hdr = curl_slist_append(hdr, mode == DOWNLOAD ? "Accept: */*" : "Accept: application/json");
    }
    curl_easy_setopt(h, CURLOPT_URL, url);
    curl_easy_setopt(h, CURLOPT_USERAGENT, "packd/" PACKD_VERSION);
    curl_easy_setopt(h, CURLOPT_HTTPHEADER, hdr);
    curl_easy_setopt(h, CURLOPT_CUSTOMREQUEST, method);
    if (body) {
        curl_easy_setopt(h, CURLOPT_POSTFIELDS, body);
        curl_easy_setopt(h, CURLOPT_POSTFIELDSIZE, (long)strlen(body));
    }
    curl_easy_setopt(h, CURLOPT_WRITEFUNCTION, on_body);
    curl_easy_setopt(h, CURLOPT_WRITEDATA, s);
    curl_easy_setopt(h, CURLOPT_HEADERFUNCTION, on_header);
    curl_easy_setopt(h, CURLOPT_HEADERDATA, s);
    curl_easy_setopt(h, CURLOPT_NOSIGNAL, 1L);
    curl_easy_setopt(h, CURLOPT_CONNECTTIMEOUT, 10L);
    curl_easy_setopt(h, CURLOPT_PROTOCOLS_STR, "http,https");
    if (mode == COLLECT) {
        curl_easy_setopt(h, CURLOPT_TIMEOUT, 120L);
    } else {
        /* long transfers: give up only when nothing arrives for a minute (the
         * event stream sends a keep-alive comment every few seconds) */
        curl_easy_setopt(h, CURLOPT_LOW_SPEED_LIMIT, 1L);
        curl_easy_setopt(h, CURLOPT_LOW_SPEED_TIME, 60L);
    }
    CURLcode rc = curl_easy_perform(h);
    long code = 0;
    curl_easy_getinfo(h, CURLINFO_RESPONSE_CODE, &code);
    if (code)
        r->status = code;
    curl_slist_free_all(hdr);
    curl_easy_cleanup(h);
    if (s->write_failed) {
        snprintf(r->error, sizeof r->error, "cannot write: %s", strerror(s->write_failed));
        r->status = 0;
        return -1;
    }
    if (rc != CURLE_OK && !(rc == CURLE_WRITE_ERROR && s->stopped)) {
        snprintf(r->error, sizeof r->error, "%.300s: %s", url, curl_easy_strerror(rc));
        if (mode != STREAM) /* a cut stream still told what it got */
            r->status = 0;
        return r->status ? 0 : -1;
    }
    return 0;
}

int pk_client_request(const pk_client *c, const char *method, const char *path, const char *body,
                      pk_reply *r)
{
    memset(r, 0, sizeof *r);
    sink s = {.r = r};
    return perform(c, method, path, body, NULL, COLLECT, &s);
}

int pk_client_download(const pk_client *c, const char *path, const char *file, char hex[65],
                       pk_reply *r)
{
    memset(r, 0, sizeof *r);
    hex[0] = 0;
    sink s = {.r = r, .file = fopen(file, "wb"), .md = pk_sha256_new()};
    if (!s.file || !s.md) {
        snprintf(r->error, sizeof r->error, "%s: %s", file,
                 s.file ? "cannot hash" : strerror(errno));
        if (s.file)
            fclose(s.file);
        pk_sha256_free(s.md);
        return -1;
    }
    int rc = perform(c, "GET", path, NULL, NULL, DOWNLOAD, &s);
    if (fclose(s.file) != 0 && rc == 0) {
        snprintf(r->error, sizeof r->error, "%s: %s", file, strerror(errno));
        r->status = 0;
        rc = -1;
    }
    unsigned char d[32];
    int hashed = pk_sha256_final(s.md, d) == 0;
    if (rc == 0 && r->status >= 200 && r->status < 300 && hashed)
        pk_hex(d, sizeof d, hex);
    else
        remove(file);
    return rc;
}

int pk_client_events(const pk_client *c, const char *path, const char *last_event_id, pk_sse_fn fn,
                     void *ctx, pk_reply *r)
{
    memset(r, 0, sizeof *r);
    sink s = {.r = r, .fn = fn, .ctx = ctx};
    int rc = perform(c, "GET", path, NULL, last_event_id, STREAM, &s);
    free(s.line);
    free(s.data);
    return rc;
}

int pk_client_verify(const char *got, const char *declared_doc, const char *declared_header,
                     char *err, size_t errlen)
{
    int have_doc = declared_doc && *declared_doc, have_hdr = declared_header && *declared_header;
    if (!have_doc && !have_hdr) {
        snprintf(err, errlen, "the service declared no SHA-256 for this file");
        return -1;
    }
    if (!got || strlen(got) != 64) {
        snprintf(err, errlen, "no digest of the downloaded file");
        return -1;
    }
    if (have_doc && strcasecmp(got, declared_doc) != 0) {
        snprintf(err, errlen, "SHA-256 mismatch: downloaded %s, results document says %s", got,
                 declared_doc);
        return -1;
    }
    if (have_hdr && strcasecmp(got, declared_header) != 0) {
        snprintf(err, errlen, "SHA-256 mismatch: downloaded %s, X-Content-SHA256 says %s", got,
                 declared_header);
        return -1;
    }
    return 0;
}
