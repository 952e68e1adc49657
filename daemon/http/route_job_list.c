/* GET /jobs — the job list of OGC API – Processes Part 1, requirements class
 * job-list (/req/job-list/…); the parameters and their rules are in docs/service.md.
 *
 * status, processID and type are arrays: repeated parameters and
 * comma-separated values add up (any of them matches).  datetime filters on
 * the job's created time, minDuration/maxDuration (seconds) on started..finished
 * (..now while running).  owner (admins) lists one owner's jobs; a user's
 * list is its own whatever it names.  limit is 1..10000 (default 10; above the maximum it
 * is the maximum, not an error).  A bad value is a 400 naming the parameter
 * and its rule.  Paging links (self, next, prev) keep the filters.  Also as
 * HTML (f=html or Accept: text/html; html_page.h). */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "auth.h"
#include "html_page.h"
#include "http.h"
#include "api/http/http_status_info.h"
#include "api/http/http_time.h"

#define LIMIT_DEFAULT 10
#define LIMIT_MAX 10000
#define OFFSET_MAX 1000000000LL /* keeps offset + limit far from overflow */

static const char *const statuses[] = {"accepted", "running", "successful", "failed", "dismissed"};

typedef struct list_query {
    json_t *status, *process, *type; /* arrays of the values given, or NULL */
    const char *datetime, *limit, *offset, *min_duration, *max_duration, *owner;
    char bad[240]; /* the first rule broken */
} list_query;

static void add_items(json_t **into, const char *value)
{
    if (!*into)
        *into = json_array();
    while (value && *value) {
        size_t n = strcspn(value, ",");
        if (n)
            json_array_append_new(*into, json_stringn(value, n));
        value += n + (value[n] == ',');
    }
}

static void once(list_query *q, const char **slot, const char *key, const char *value)
{
    if (*slot && !q->bad[0])
        snprintf(q->bad, sizeof q->bad, "query parameter %s may be given once", key);
    *slot = value ? value : "";
}

static enum MHD_Result collect(void *cls, enum MHD_ValueKind kind, const char *key,
                               const char *value)
{
    list_query *q = cls;
    (void)kind;
    if (!strcmp(key, "status"))
        add_items(&q->status, value);
    else if (!strcmp(key, "processID"))
        add_items(&q->process, value);
    else if (!strcmp(key, "type"))
        add_items(&q->type, value);
    else if (!strcmp(key, "datetime"))
        once(q, &q->datetime, key, value);
    else if (!strcmp(key, "limit"))
        once(q, &q->limit, key, value);
    else if (!strcmp(key, "offset"))
        once(q, &q->offset, key, value);
    else if (!strcmp(key, "minDuration"))
        once(q, &q->min_duration, key, value);
    else if (!strcmp(key, "maxDuration"))
        once(q, &q->max_duration, key, value);
    else if (!strcmp(key, "owner"))
        once(q, &q->owner, key, value);
    return MHD_YES;
}

/* An integer in min..; *out = def when s is NULL.  -1 otherwise. */
static int integer(const char *s, long long min, long long def, long long *out)
{
    *out = def;
    if (!s)
        return 0;
    char *end;
    errno = 0;
    long long v = strtoll(s, &end, 10);
    if (end == s || *end || errno == ERANGE || v < min)
        return -1;
    *out = v;
    return 0;
}

/* One end of a datetime interval: "" or ".." is open (NAN). */
static int interval_end(const char *s, size_t n, double *t, double *span)
{
    char buf[64];
    if (n == 0 || (n == 2 && !strncmp(s, "..", 2))) {
        *t = NAN;
        return 0;
    }
    if (n >= sizeof buf)
        return -1;
    memcpy(buf, s, n);
    buf[n] = 0;
    return pk_time_parse_rfc3339(buf, t, span);
}

/* datetime: an instant (the created times it names: its span) or an
 * interval "a/b", either end open ("..", or empty). */
static int parse_datetime(const char *s, pk_job_filter *f)
{
    const char *slash = strchr(s, '/');
    double span = 1, span_b = 1, a, b;
    if (!slash) {
        if (pk_time_parse_rfc3339(s, &a, &span) != 0)
            return -1;
        f->created_from = a;
        f->created_before = a + span;
        return 0;
    }
    if (strchr(slash + 1, '/') || interval_end(s, (size_t)(slash - s), &a, &span) != 0 ||
        interval_end(slash + 1, strlen(slash + 1), &b, &span_b) != 0 || (isnan(a) && isnan(b)) ||
        (!isnan(a) && !isnan(b) && a > b))
        return -1;
    f->created_from = a;
    f->created_before = isnan(b) ? NAN : b + span_b;
    return 0;
}

static int known_status(const char *s)
{
    for (size_t i = 0; i < sizeof statuses / sizeof *statuses; i++)
        if (!strcmp(s, statuses[i]))
            return 1;
    return 0;
}

/* The filter from the parameters; 0, or -1 with q->bad set. */
static int parse(list_query *q, pk_job_filter *f, long long *limit, long long *offset)
{
    if (q->bad[0])
        return -1;
    size_t i;
    json_t *v;
    json_array_foreach (q->status, i, v)
        if (!known_status(json_string_value(v))) {
            snprintf(q->bad, sizeof q->bad,
                     "query parameter status: '%s' is not one of accepted, "
                     "running, successful, failed, dismissed",
                     json_string_value(v));
            return -1;
        }
    json_array_foreach (q->type, i, v)
        if (strcmp(json_string_value(v), "process") != 0) {
            snprintf(q->bad, sizeof q->bad,
                     "query parameter type: '%s' is not a job type here "
                     "(every job is of type process)",
                     json_string_value(v));
            return -1;
        }
    if (q->datetime && parse_datetime(q->datetime, f) != 0) {
        snprintf(q->bad, sizeof q->bad,
                 "query parameter datetime: an RFC 3339 date-time, or an "
                 "interval start/end whose open end is '..' or empty (start not after end)");
        return -1;
    }
    long long d;
    if (integer(q->min_duration, 0, -1, &d) != 0) {
        snprintf(q->bad, sizeof q->bad, "query parameter minDuration: whole seconds, 0 or more");
        return -1;
    }
    f->min_duration = d < 0 ? NAN : (double)d;
    if (integer(q->max_duration, 0, -1, &d) != 0) {
        snprintf(q->bad, sizeof q->bad, "query parameter maxDuration: whole seconds, 0 or more");
        return -1;
    }
    f->max_duration = d < 0 ? NAN : (double)d;
    if (q->owner && !*q->owner) {
        snprintf(q->bad, sizeof q->bad, "query parameter owner: an owner's name, not empty");
        return -1;
    }
    if (integer(q->limit, 1, LIMIT_DEFAULT, limit) != 0) {
        snprintf(q->bad, sizeof q->bad,
                 "query parameter limit: an integer, 1 or more (at most %d "
                 "jobs are listed; a larger limit lists that many)",
                 LIMIT_MAX);
        return -1;
    }
    if (*limit > LIMIT_MAX)
        *limit = LIMIT_MAX;
    if (integer(q->offset, 0, 0, offset) != 0 || *offset > OFFSET_MAX) {
        snprintf(q->bad, sizeof q->bad, "query parameter offset: an integer in 0..%lld",
                 OFFSET_MAX);
        return -1;
    }
    return 0;
}

static void put_encoded(FILE *f, const char *s)
{
    for (; *s; s++) {
        unsigned char c = (unsigned char)*s;
        if ((c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') ||
            strchr("-._~:", c))
            fputc(c, f);
        else
            fprintf(f, "%%%02X", c);
    }
}

static void put_array(FILE *f, const char *key, json_t *a)
{
    if (!json_array_size(a))
        return;
    fprintf(f, "&%s=", key);
    size_t i;
    json_t *v;
    json_array_foreach (a, i, v) {
        if (i)
            fputc(',', f);
        put_encoded(f, json_string_value(v));
    }
}

static void put_value(FILE *f, const char *key, const char *v)
{
    if (v) {
        fprintf(f, "&%s=", key);
        put_encoded(f, v);
    }
}

/* The filters as a query string ("&k=v…"), for the paging links. */
static char *filters_query(const list_query *q)
{
    char *text = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&text, &len);
    if (!f)
        return NULL;
    put_array(f, "status", q->status);
    put_array(f, "processID", q->process);
    put_array(f, "type", q->type);
    put_value(f, "datetime", q->datetime);
    put_value(f, "minDuration", q->min_duration);
    put_value(f, "maxDuration", q->max_duration);
    put_value(f, "owner", q->owner);
    fclose(f);
    return text;
}

static void add_link(json_t *links, const char *rel, long long limit, long long offset,
                     const char *qs)
{
    size_t n = strlen(qs ? qs : "") + 64;
    char *href = malloc(n);
    if (!href)
        return;
    snprintf(href, n, "/jobs?limit=%lld&offset=%lld%s", limit, offset, qs ? qs : "");
    json_array_append_new(
        links, json_pack("{s:s,s:s,s:s}", "href", href, "rel", rel, "type", "application/json"));
    free(href);
}

enum MHD_Result route_jobs(pk_req *r)
{
    list_query q = {0};
    MHD_get_connection_values(r->conn, MHD_GET_ARGUMENT_KIND, collect, &q);
    pk_job_filter f = {.owner = pk_scope(r), .created_from = NAN, .created_before = NAN};
    long long limit, offset;
    enum MHD_Result rc;
    if (parse(&q, &f, &limit, &offset) != 0) {
        rc = pk_send_problem(r, 400, PK_PROBLEM_INVALID_INPUT, "Invalid query parameter", q.bad,
                             NULL, 0);
        goto out;
    }
    /* owner narrows an admin's list; a user's list is its own, so naming
     * another owner lists nothing (as if that owner had no jobs) */
    int other_owner = q.owner && f.owner && strcmp(q.owner, f.owner) != 0;
    if (q.owner)
        f.owner = q.owner;
    char *st = json_array_size(q.status) ? json_dumps(q.status, JSON_COMPACT) : NULL;
    char *pr = json_array_size(q.process) ? json_dumps(q.process, JSON_COMPACT) : NULL;
    f.status_json = st;
    f.process_json = pr;
    int total = 0;
    json_t *rows =
        other_owner ? json_array() : pk_queue_list(r->svc->q, &f, (int)limit, (int)offset, &total);
    free(st);
    free(pr);
    json_t *jobs = json_array();
    size_t i;
    json_t *row;
    json_array_foreach (rows, i, row)
        json_array_append_new(jobs, pk_status_info(row));
    json_decref(rows);
    char *qs = filters_query(&q);
    json_t *links = json_array();
    add_link(links, "self", limit, offset, qs);
    if (offset + limit < total)
        add_link(links, "next", limit, offset + limit, qs);
    if (offset > 0)
        add_link(links, "prev", limit, offset > limit ? offset - limit : 0, qs);
    free(qs);
    rc = pk_send_doc(r,
                     json_pack("{s:o,s:i,s:I,s:o}", "jobs", jobs, "numberMatched", total,
                               "numberReturned", (json_int_t)json_array_size(jobs), "links", links),
                     "Jobs", pk_html_jobs);
out:
    json_decref(q.status);
    json_decref(q.process);
    json_decref(q.type);
    return rc;
}
