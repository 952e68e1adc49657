/* client_job.c — what the client commands do with one job (problem, events, result).
 * Contract: daemon/cli/client_job.h. */
#include "client_job.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "api/results/result_digest.h"

const char *pk_doc_str(const json_t *doc, const char *key)
{
    const char *s = json_string_value(json_object_get(doc, key));
    return s ? s : "";
}

int pk_client_report(const char *cmd, const pk_reply *r)
{
    if (r->status == 0) {
        fprintf(stderr, "packd %s: %s\n", cmd, r->error[0] ? r->error : "no answer");
        return 2;
    }
    json_t *p = pk_reply_json(r);
    const char *title = json_string_value(json_object_get(p, "title"));
    const char *detail = json_string_value(json_object_get(p, "detail"));
    if (title || detail) {
        fprintf(stderr, "packd %s: %ld %s%s%s\n", cmd, r->status, title ? title : "",
                title && detail ? ": " : "", detail ? detail : "");
        size_t i;
        json_t *e;
        json_array_foreach (json_object_get(p, "errors"), i, e) {
            const char *ptr = json_string_value(json_object_get(e, "pointer"));
            const char *rule = json_string_value(json_object_get(e, "rule"));
            fprintf(stderr, "  %s: %s%s%s%s\n", ptr && *ptr ? ptr : "/", pk_doc_str(e, "message"),
                    rule ? " (rule " : "", rule ? rule : "", rule ? ")" : "");
        }
    } else {
        fprintf(stderr, "packd %s: HTTP %ld: %.*s\n", cmd, r->status,
                (int)(r->len > 400 ? 400 : r->len), r->body ? r->body : "");
    }
    json_decref(p);
    return r->status >= 500 ? 2 : 1;
}

static int is_final(const char *st)
{
    return st && (!strcmp(st, "successful") || !strcmp(st, "failed") || !strcmp(st, "dismissed"));
}

/* ------------------------------------------------------------ progress */

typedef struct follow {
    const char *id;
    int quiet, tty;
    char last_id[64];
    char status[16];
    int percent;
    char detail[160]; /* from the last progress event */
    double last_print;
    int line_open; /* a \r line is on the terminal */
} follow;

static double now_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + t.tv_nsec * 1e-9;
}

static void show(follow *f, int force)
{
    if (f->quiet)
        return;
    double t = now_s();
    /* a terminal gets a redrawn line; a log gets a line on each status
     * change and at most one every 5 s between */
    if (!force && t - f->last_print < (f->tty ? 0.1 : 5.0))
        return;
    f->last_print = t;
    char line[256];
    snprintf(line, sizeof line, "packd: job %.8s %-10s %3d %%  %s", f->id, f->status, f->percent,
             f->detail);
    if (f->tty) {
        fprintf(stderr, "\r%-79.200s", line);
        f->line_open = 1;
    } else {
        fprintf(stderr, "%s\n", line);
    }
    fflush(stderr);
}

static int on_event(const char *event, const char *data, const char *id, void *ctx)
{
    follow *f = ctx;
    snprintf(f->last_id, sizeof f->last_id, "%s", id);
    json_t *d = json_loads(data, 0, NULL);
    if (!d)
        return 0;
    int stop = 0;
    if (!strcmp(event, "status")) {
        const char *st = json_string_value(json_object_get(d, "status"));
        int changed = st && strcmp(st, f->status);
        if (st)
            snprintf(f->status, sizeof f->status, "%s", st);
        if (json_is_integer(json_object_get(d, "progress")))
            f->percent = (int)json_integer_value(json_object_get(d, "progress"));
        const char *msg = json_string_value(json_object_get(d, "message"));
        if (msg && changed)
            snprintf(f->detail, sizeof f->detail, "%s", msg);
        show(f, changed);
        stop = is_final(st);
    } else if (!strcmp(event, "progress")) {
        json_t *fr = json_object_get(d, "fraction"), *eta = json_object_get(d, "eta_s");
        json_t *done = json_object_get(d, "done"), *total = json_object_get(d, "total");
        if (json_is_number(fr))
            f->percent = (int)(100 * json_number_value(fr));
        int n = snprintf(f->detail, sizeof f->detail, "%s", pk_doc_str(d, "stage"));
        if (json_is_number(json_object_get(d, "phi")) && n < (int)sizeof f->detail)
            n += snprintf(f->detail + n, sizeof f->detail - n, "  phi %.4f",
                          json_number_value(json_object_get(d, "phi")));
        if (json_is_integer(done) && json_is_integer(total) && n < (int)sizeof f->detail)
            n +=
                snprintf(f->detail + n, sizeof f->detail - n, "  %lld/%lld",
                         (long long)json_integer_value(done), (long long)json_integer_value(total));
        if (json_is_number(eta) && n < (int)sizeof f->detail)
            snprintf(f->detail + n, sizeof f->detail - n, "  eta %.0f s", json_number_value(eta));
        show(f, 0);
    }
    json_decref(d);
    return stop;
}

json_t *pk_client_wait(const pk_client *c, const char *id, int quiet)
{
    follow f = {.id = id, .quiet = quiet, .tty = isatty(2), .last_print = -1e9};
    char events[200], self[200];
    snprintf(events, sizeof events, "/jobs/%s/events", id);
    snprintf(self, sizeof self, "/jobs/%s", id);
    json_t *doc = NULL;
    int failures = 0;
    for (;;) {
        pk_reply r;
        /* the stream ends when the job is final or the connection drops; the
         * job's document says which (a service without events is polled) */
        pk_client_events(c, events, f.last_id, on_event, &f, &r);
        int streamed = r.status >= 200 && r.status < 300;
        pk_reply_free(&r);
        if (pk_client_request(c, "GET", self, NULL, &r) != 0 || r.status != 200) {
            if (r.status != 0 || ++failures > 5) {
                if (f.line_open)
                    fputc('\n', stderr);
                pk_client_report("wait", &r);
                pk_reply_free(&r);
                return NULL;
            }
            pk_reply_free(&r);
            sleep(1);
            continue;
        }
        failures = 0;
        doc = pk_reply_json(&r);
        pk_reply_free(&r);
        const char *st = json_string_value(json_object_get(doc, "status"));
        if (st) {
            int changed = strcmp(st, f.status) != 0;
            snprintf(f.status, sizeof f.status, "%s", st);
            if (json_is_integer(json_object_get(doc, "progress")))
                f.percent = (int)json_integer_value(json_object_get(doc, "progress"));
            if (is_final(st)) {
                snprintf(f.detail, sizeof f.detail, "%s", pk_doc_str(doc, "message"));
                if (changed || f.tty)
                    show(&f, 1);
                break;
            }
            show(&f, changed);
        }
        json_decref(doc);
        doc = NULL;
        usleep(streamed ? 200000 : 500000);
    }
    if (f.line_open)
        fputc('\n', stderr);
    return doc;
}

/* ------------------------------------------------------------- results */

/* Where to fetch a link from: an absolute href under the server's URL as it
 * is; another absolute href (a service naming its public URL while the user
 * reaches it another way) by its path from the server the user chose, so
 * the token goes nowhere else. */
static const char *link_path(const pk_client *c, const char *href)
{
    size_t n = strlen(c->server);
    while (n && c->server[n - 1] == '/')
        n--;
    const char *p = strstr(href, "://");
    if (!p || (!strncmp(href, c->server, n) && (href[n] == '/' || !href[n])))
        return href;
    p = strchr(p + 3, '/');
    return p ? p : "/";
}

/* Download href to out via out.part, verify, rename.  0, or 2. */
static int download_verified(const pk_client *c, const char *href, const char *out,
                             const char *declared, json_t *info)
{
    href = link_path(c, href);
    char part[4200], hex[65], err[400];
    snprintf(part, sizeof part, "%s.part", out);
    pk_reply r;
    if (pk_client_download(c, href, part, hex, &r) != 0 || r.status != 200) {
        int rc = pk_client_report("fetch", &r);
        pk_reply_free(&r);
        remove(part);
        return rc;
    }
    if (pk_client_verify(hex, declared, r.sha256_header, err, sizeof err) != 0) {
        fprintf(stderr, "packd fetch: %s: %s (%zu bytes received); file removed\n", href, err,
                r.len);
        pk_reply_free(&r);
        remove(part);
        return 2;
    }
    if (rename(part, out) != 0) {
        perror(out);
        remove(part);
        pk_reply_free(&r);
        return 2;
    }
    json_object_set_new(info, "output", json_string(out));
    json_object_set_new(info, "sha256", json_string(hex));
    json_object_set_new(info, "size", json_integer((json_int_t)r.len));
    pk_reply_free(&r);
    return 0;
}

/* The content hash the server states (summary "result_digest") against the
 * one recomputed from the downloaded file: the same grains for the same
 * job, whatever the timings in the file.  0 (or nothing stated), or 2 with
 * the file removed. */
static int check_result_digest(const char *out, const char *stated, json_t *info)
{
    if (!stated)
        return 0;
    char got[65];
    if (pk_result_digest_file(out, got) != 0 || strcmp(got, stated) != 0) {
        fprintf(stderr, "packd fetch: %s: result_digest %s, the server states %s; file removed\n",
                out, pk_result_digest_file(out, got) == 0 ? got : "cannot be computed", stated);
        remove(out);
        return 2;
    }
    json_object_set_new(info, "result_digest", json_string(got));
    return 0;
}

int pk_client_fetch(const pk_client *c, const char *id, const char *out, json_t **info_out)
{
    char path[200];
    snprintf(path, sizeof path, "/jobs/%s/results", id);
    pk_reply r;
    if (pk_client_request(c, "GET", path, NULL, &r) != 0) {
        int rc = pk_client_report("fetch", &r);
        pk_reply_free(&r);
        return rc;
    }
    json_t *doc = pk_reply_json(&r);
    json_t *info = json_object();
    int rc;
    const char *type = json_string_value(json_object_get(doc, "type"));
    if (r.status == 200) {
        json_t *res = json_object_get(doc, "result");
        const char *href = json_string_value(json_object_get(res, "href"));
        if (!href) {
            fprintf(stderr, "packd fetch: the results document names no result file\n");
            rc = 2;
        } else {
            rc = download_verified(c, href, out, json_string_value(json_object_get(res, "sha256")),
                                   info);
        }
        json_t *v = json_object_get(json_object_get(doc, "summary"), "value");
        if (v)
            json_object_set(info, "summary", v);
        if (rc == 0)
            rc = check_result_digest(out, json_string_value(json_object_get(v, "result_digest")),
                                     info);
    } else if (r.status == 422 && type && strstr(type, "job-failed")) {
        /* the job failed: say why; its partial file is still worth keeping, at
         * OUT.partial, so that OUT exists only for a job that succeeded */
        pk_client_report("fetch", &r);
        json_t *part = json_object_get(doc, "partial_result");
        const char *href = json_string_value(json_object_get(part, "href"));
        char partial[4200];
        snprintf(partial, sizeof partial, "%s.partial", out);
        if (href &&
            download_verified(c, href, partial, json_string_value(json_object_get(part, "sha256")),
                              info) == 0)
            fprintf(stderr, "packd fetch: partial result of the failed job in %s (not %s)\n",
                    partial, out);
        if (json_object_get(doc, "summary"))
            json_object_set(info, "summary", json_object_get(doc, "summary"));
        rc = 3;
    } else {
        rc = pk_client_report("fetch", &r);
        /* a dismissed job will never have a result */
        const char *st = json_string_value(json_object_get(doc, "jobStatus"));
        if (st && is_final(st))
            rc = 3;
    }
    json_decref(doc);
    pk_reply_free(&r);
    if (info_out)
        *info_out = info;
    else
        json_decref(info);
    return rc;
}
