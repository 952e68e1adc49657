/* GET /jobs/{id}/events — Server-Sent Events of a job: every stored event
 * after Last-Event-ID (header, or ?lastEventId=), then live ones as they are
 * recorded; "status" events carry {status, progress, message}, "progress"
 * events the worker's object (stage, fraction, phi, done, total, ...,
 * progress).  A comment line every KEEPALIVE_S keeps proxies open.  The
 * stream ends once the job is final and every event has been sent.
 *
 * The reader never blocks: with nothing to send it parks the connection
 * (http_park.h) until the queue records an event or the keep-alive is due,
 * so a listener costs a socket and a few KiB, not a thread. */
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "auth.h"
#include "http.h"
#include "http_park.h"
#include "daemon/store/queue.h"

#define KEEPALIVE_S 10.0
#define BATCH 200

typedef struct sse {
    pk_service *svc;
    pk_parked *park;
    char id[37];
    long long last;       /* last event id sent */
    long long fetched_at; /* event sequence of the last fetch that got everything */
    char *pending;        /* formatted text not yet handed to MHD */
    size_t len, off;
    double last_write;
    int check_final; /* a status event (or a keep-alive) since the last look at the job row */
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

/* The last batch of events read, formatted.  Listeners of one job at the
 * same event id while the queue is at the same sequence get the same batch,
 * so waking N listeners of a job costs one query, not N. */
static struct {
    pthread_mutex_t mu;
    char job[37];
    long long after, seq; /* the batch: events of job after `after`, read at `seq` */
    long long last;       /* id of its last event */
    size_t got;
    int status; /* it holds a status event */
    char *text;
} batch = {.mu = PTHREAD_MUTEX_INITIALIZER, .seq = -1};

static void read_batch(pk_queue *q, const char *job, long long after, long long seq)
{
    json_t *ev = pk_queue_events(q, job, after, BATCH);
    char *text = NULL;
    size_t len = 0, i;
    FILE *f = open_memstream(&text, &len);
    json_t *e;
    batch.last = after;
    batch.status = 0;
    json_array_foreach (ev, i, e) {
        char *data = json_dumps(json_object_get(e, "data"), JSON_COMPACT | JSON_REAL_PRECISION(10));
        const char *kind = json_string_value(json_object_get(e, "kind"));
        batch.last = json_integer_value(json_object_get(e, "id"));
        if (f)
            fprintf(f, "id: %lld\nevent: %s\ndata: %s\n\n", batch.last, kind, data ? data : "{}");
        batch.status |= !strcmp(kind, "status");
        free(data);
    }
    if (f)
        fclose(f);
    batch.got = text ? json_array_size(ev) : 0;
    json_decref(ev);
    free(batch.text);
    batch.text = text;
    snprintf(batch.job, sizeof batch.job, "%s", job);
    batch.after = after;
    batch.seq = seq;
}

/* Add the events after s->last (read at event sequence seq) to s->pending;
 * how many (at most BATCH).  fresh: query even if a batch of that sequence
 * is at hand (a commit is visible a moment before its sequence moves). */
static size_t fetch(sse *s, long long seq, int fresh)
{
    pthread_mutex_lock(&batch.mu);
    if (fresh || batch.seq != seq || batch.after != s->last || strcmp(batch.job, s->id) != 0)
        read_batch(s->svc->q, s->id, s->last, seq);
    size_t got = batch.got;
    if (got) {
        append(s, batch.text);
        s->last = batch.last;
        s->check_final |= batch.status;
    }
    pthread_mutex_unlock(&batch.mu);
    return got;
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
        /* Read the sequence before looking, so an event recorded after the
         * look moves it and pk_park refuses or the waker resumes. */
        long long seq = pk_queue_event_seq(s->svc->q);
        if (seq != s->fetched_at) {
            size_t got = fetch(s, seq, 0);
            if (got < BATCH)
                s->fetched_at = seq;
            if (got)
                continue;
        }
        /* A job becomes final with a status event: look at its row then. */
        if (s->check_final) {
            s->check_final = 0;
            if (job_final(s)) { /* recheck: an event may have landed in between */
                if (!fetch(s, pk_queue_event_seq(s->svc->q), 1))
                    s->done = 1;
                continue;
            }
        }
        if (pk_queue_now() - s->last_write >= KEEPALIVE_S) {
            append(s, ": keep-alive\n\n");
            s->check_final = 1; /* and a look at the row now and then, whatever happened */
            continue;
        }
        int rc = s->park ? pk_park(s->park, seq, s->last_write + KEEPALIVE_S) : -1;
        if (rc > 0)
            return 0; /* parked: MHD calls again once resumed */
        if (rc < 0)
            s->done = 1;
    }
}

static void release(void *cls)
{
    sse *s = cls;
    pk_park_unregister(s->park);
    free(s->pending);
    free(s);
}

enum MHD_Result route_events(pk_req *r)
{
    json_t *row = pk_job_visible(r, r->seg[1]);
    if (!row)
        return pk_reply_problem(r, PK_P_NO_SUCH_JOB, r->seg[1]);
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
    s->fetched_at = -1;
    s->check_final = 1;
    s->park = pk_park_register(r->conn);
    append(s, "retry: 2000\n\n");
    struct MHD_Response *resp =
        MHD_create_response_from_callback(MHD_SIZE_UNKNOWN, 8192, reader, s, release);
    MHD_add_response_header(resp, "Content-Type", "text/event-stream");
    MHD_add_response_header(resp, "Cache-Control", "no-cache");
    MHD_add_response_header(resp, "X-Accel-Buffering", "no");
    return pk_send(r, 200, resp);
}
