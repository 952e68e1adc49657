/* http_durations.c — the request-duration histogram; contract in
 * http_durations.h.  Lock-free: one atomic counter per bucket. */
#include "http_durations.h"

#include <string.h>

/* Prometheus's default buckets, extended down to 0.5 ms: a status poll
 * answers in about a millisecond on an idle machine. */
static const double bounds[] = {0.0005, 0.001, 0.0025, 0.005, 0.01, 0.025, 0.05,
                                0.1,    0.25,  0.5,    1,     2.5,  5,     10};
#define NB (sizeof bounds / sizeof *bounds)
#define ROUTE_SLOTS 32 /* the route table's rows (19 today) and "unmatched" last */
#define CODE_MIN 100
#define CODES 500 /* 100..599 */

typedef struct series {
    unsigned long long n[NB + 1]; /* per bucket, the last +Inf; not cumulative */
    unsigned long long ns;        /* sum in nanoseconds */
} series;

/* Zero pages until a (route, code) is first seen: ~1.9 MB reserved, a few
 * pages resident. */
static series hist[ROUTE_SLOTS][CODES];

static size_t route_slot(const pk_route *rt)
{
    size_t i = rt ? (size_t)(rt - pk_routes) : ROUTE_SLOTS - 1;
    return i < ROUTE_SLOTS - 1 ? i : ROUTE_SLOTS - 1;
}

void pk_http_duration_observe(const pk_route *rt, unsigned code, double seconds)
{
    if (code < CODE_MIN || code >= CODE_MIN + CODES)
        return;
    if (seconds < 0)
        seconds = 0;
    series *s = &hist[route_slot(rt)][code - CODE_MIN];
    size_t b = 0;
    while (b < NB && seconds > bounds[b])
        b++;
    __atomic_add_fetch(&s->n[b], 1, __ATOMIC_RELAXED);
    __atomic_add_fetch(&s->ns, (unsigned long long)(seconds * 1e9), __ATOMIC_RELAXED);
}

/* The OpenAPI path template of a route pattern (schemas/openapi.json): each
 * '*' segment named after the collection before it. */
static void route_template(const char *pattern, char *out, size_t n)
{
    static const char *const names[][2] = {{"processes", "{processId}"},
                                           {"jobs", "{jobId}"},
                                           {"results", "{outputId}"},
                                           {"files", "{fileId}"},
                                           {"dashboard", "{file}"}};
    size_t k = 0;
    const char *prev = "", *p = pattern;
    size_t prev_len = 0;
    out[0] = 0;
    while (*p == '/' && k + 1 < n) {
        const char *seg = ++p;
        size_t len = strcspn(seg, "/");
        const char *text = seg;
        size_t text_len = len;
        if (len == 1 && *seg == '*') {
            text = "{id}";
            for (size_t i = 0; i < sizeof names / sizeof *names; i++)
                if (strlen(names[i][0]) == prev_len && !strncmp(prev, names[i][0], prev_len))
                    text = names[i][1];
            text_len = strlen(text);
        }
        if (k + 1 + text_len >= n)
            break;
        out[k++] = '/';
        memcpy(out + k, text, text_len);
        k += text_len;
        out[k] = 0;
        prev = seg;
        prev_len = len;
        p = seg + len;
    }
    if (!out[0] && n > 1)
        strcpy(out, "/");
}

static void expose_series(pk_text_buf *b, const char *method, const char *route, unsigned code,
                          const series *s)
{
    unsigned long long cum = 0;
    for (size_t i = 0; i <= NB; i++) {
        cum += __atomic_load_n(&s->n[i], __ATOMIC_RELAXED);
        if (i < NB)
            pk_text_put(b,
                        "packd_http_request_duration_seconds_bucket{method=\"%s\",route=\"%s\","
                        "code=\"%u\",le=\"%g\"} %llu\n",
                        method, route, code, bounds[i], cum);
        else
            pk_text_put(b,
                        "packd_http_request_duration_seconds_bucket{method=\"%s\",route=\"%s\","
                        "code=\"%u\",le=\"+Inf\"} %llu\n",
                        method, route, code, cum);
    }
    pk_text_put(b,
                "packd_http_request_duration_seconds_sum{method=\"%s\",route=\"%s\",code=\"%u\"}"
                " %.9f\n",
                method, route, code, (double)__atomic_load_n(&s->ns, __ATOMIC_RELAXED) * 1e-9);
    pk_text_put(b,
                "packd_http_request_duration_seconds_count{method=\"%s\",route=\"%s\",code=\"%u\"}"
                " %llu\n",
                method, route, code, cum);
}

void pk_http_durations_expose(pk_text_buf *b)
{
    pk_text_put(b,
                "# HELP packd_http_request_duration_seconds Time from a request's complete "
                "head to its response queued, by method, route template and status code.\n"
                "# TYPE packd_http_request_duration_seconds histogram\n");
    size_t routes = 0;
    while (pk_routes[routes].method)
        routes++;
    for (size_t r = 0; r < ROUTE_SLOTS; r++) {
        int unmatched = r == ROUTE_SLOTS - 1;
        if (!unmatched && r >= routes)
            continue;
        char route[160];
        if (unmatched)
            strcpy(route, "unmatched");
        else
            route_template(pk_routes[r].pattern, route, sizeof route);
        const char *method = unmatched ? "other" : pk_routes[r].method;
        for (unsigned c = 0; c < CODES; c++) {
            const series *s = &hist[r][c];
            unsigned long long any = 0;
            for (size_t i = 0; i <= NB && !any; i++)
                any = __atomic_load_n(&s->n[i], __ATOMIC_RELAXED);
            if (any)
                expose_series(b, method, route, c + CODE_MIN, s);
        }
    }
}
