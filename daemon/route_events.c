/* GET /jobs/{id}/events — Server-Sent Events of a job: every stored event
 * after Last-Event-ID (header, or ?lastEventId=), then live ones as they are
 * recorded; "status" events carry {status, progress, message}, "progress"
 * events the worker's object (stage, fraction, phi, done, total, ...,
 * progress).  A comment line every KEEPALIVE_S keeps proxies open.  The
 * stream ends once the job is final and every event has been sent. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "auth.h"
#include "http.h"
#include "queue.h"

#define KEEPALIVE_S 10.0
#define BATCH 200

typedef struct sse {
    pk_service *svc;
    char id[37];
    long long last;        /* last event id sent */
    char *pending;         /* formatted text not yet handed to MHD */
    size_t len, off;
    double last_write;
    int done;
} sse;

static void append(sse *s, const char *text)
{
    size_t n = strlen(text);
    char *p = realloc(s->pending, s->len + n + 1);
    if (!p)
        return;
    s->pending = p;
    memcpy(p + s->len, text, n + 1);
    s->len += n;
}

/* The job is over and nothing more will be recorded for it. */
static int job_final(sse *s)
{
    json_t *row = pk_queue_get(s->svc->q, s->id);
    if (!row)
        return 1;
    const char *st = json_string_value(json_object_get(row, "status"));
    int final = strcmp(st, "accepted") && strcmp(st, "running") &&
                (strcmp(st, "dismissed") || !json_is_null(json_object_get(row, "finished")));
    json_decref(row);
    return final;
}

/* Fill s->pending with new events; 1 if something was added. */
static int fetch(sse *s)
{
    json_t *ev = pk_queue_events(s->svc->q, s->id, s->last, BATCH);
    size_t i;
    json_t *e;
    json_array_foreach(ev, i, e) {
        char *data = json_dumps(json_object_get(e, "data"), JSON_COMPACT | JSON_REAL_PRECISION(10));
        long long id = json_integer_value(json_object_get(e, "id"));
        size_t n = strlen(data ? data : "{}") + 128;
        char *buf = malloc(n);
        snprintf(buf, n, "id: %lld\nevent: %s\ndata: %s\n\n", id,
                 json_string_value(json_object_get(e, "kind")), data ? data : "{}");
        append(s, buf);
        free(buf);
        free(data);
        s->last = id;
    }
    size_t got = json_array_size(ev);
    json_decref(ev);
    return got > 0;
}

static ssize_t reader(void *cls, uint64_t pos, char *buf, size_t max)
{
    sse *s = cls;
    (void)pos;
    for (;;) {
        if (s->off < s->len) {
            size_t n = s->len - s->off < max ? s->len - s->off : max;
            memcpy(buf, s->pending + s->off, n);
            s->off += n;
            if (s->off == s->len)
                s->off = s->len = 0;
            s->last_write = pk_queue_now();
            return (ssize_t)n;
        }
        if (s->done || __atomic_load_n(&s->svc->stopping, __ATOMIC_RELAXED))
            return MHD_CONTENT_READER_END_OF_STREAM;
        long long seq = pk_queue_event_seq(s->svc->q);
        if (fetch(s))
            continue;
        if (job_final(s)) { /* recheck: an event may have landed in between */
            if (!fetch(s))
                s->done = 1;
            continue;
        }
        if (pk_queue_now() - s->last_write >= KEEPALIVE_S) {
            append(s, ": keep-alive\n\n");
            continue;
        }
        pk_queue_wait_event(s->svc->q, seq, 1000);
    }
}

static void release(void *cls)
{
    sse *s = cls;
    free(s->pending);
    free(s);
}

enum MHD_Result route_events(pk_req *r)
{
    json_t *row = pk_job_visible(r, r->seg[1]);
    if (!row)
        return pk_send_problem(r, 404, PK_PROBLEM_NO_SUCH_JOB, "No such job", r->seg[1], NULL, 0);
    json_decref(row);
    sse *s = calloc(1, sizeof *s);
    s->svc = r->svc;
    if (snprintf(s->id, sizeof s->id, "%s", r->seg[1]) >= (int)sizeof s->id)
        s->done = 1; /* not a job id of ours (pk_queue_get found it, so never) */
    const char *last = pk_header(r, "Last-Event-ID");
    if (!last)
        last = pk_query(r, "lastEventId");
    s->last = last ? strtoll(last, NULL, 10) : 0;
    s->last_write = pk_queue_now();
    append(s, "retry: 2000\n\n");
    struct MHD_Response *resp = MHD_create_response_from_callback(MHD_SIZE_UNKNOWN, 8192, reader, s, release);
    MHD_add_response_header(resp, "Content-Type", "text/event-stream");
    MHD_add_response_header(resp, "Cache-Control", "no-cache");
    MHD_add_response_header(resp, "X-Accel-Buffering", "no");
    return pk_send(r, 200, resp);
}
