/* callbacks.c — contract in callbacks.h. */
#include "callbacks.h"

#include <arpa/inet.h>
#include <curl/curl.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "http.h"
#include "results_send.h"
#include "api/http/http_status_info.h"
#include "daemon/data_paths.h"
#include "daemon/log.h"

#define RETRIES 3        /* after the first attempt: 2 s, 8 s, 32 s later */
#define PENDING_MAX 1000 /* deliveries waiting; beyond, the oldest is dropped */
#define BATCH 200
/* Deliveries in flight at once (curl multi), and of one owner: a receiver
 * that stalls holds its owner's slots for the 10 s timeout, never the
 * others'.  A job's deliveries go one at a time, in order. */
#define IN_FLIGHT_MAX 32
#define PER_OWNER_MAX 4

typedef struct delivery {
    char *uri, *body, *owner, job[37];
    int attempt;
    double due;
    struct delivery *next;
} delivery;

typedef struct conn_check {
    char allow[512];
    char refused[64];
} conn_check;

/* One POST under way: its delivery, handle, headers and address check. */
typedef struct transfer {
    delivery *d;
    CURL *h;
    struct curl_slist *hdr;
    conn_check cc;
} transfer;

static struct {
    pk_service *svc;
    pthread_t thread;
    int running, quit;
    pthread_mutex_t mu;
    delivery *head; /* in due order */
    size_t pending;
    long long last; /* the last status event handed on */
    CURLM *multi;   /* the follower thread's alone */
    transfer *flying[IN_FLIGHT_MAX];
    int nflying;
} C = {.mu = PTHREAD_MUTEX_INITIALIZER};

static int in4(uint32_t a, uint32_t net, int bits)
{
    return bits == 0 || (a >> (32 - bits)) == (net >> (32 - bits));
}

static int private4(uint32_t a)
{
    return in4(a, 0x00000000, 8) || in4(a, 0x0a000000, 8) || in4(a, 0x64400000, 10) ||
        in4(a, 0x7f000000, 8) || in4(a, 0xa9fe0000, 16) || in4(a, 0xac100000, 12) ||
        in4(a, 0xc0a80000, 16) || in4(a, 0xe0000000, 3); /* multicast and reserved */
}

static int listed(const char *ip, const char *allow)
{
    size_t n = strlen(ip);
    for (const char *p = allow; p && *p;) {
        p += strspn(p, " ,");
        size_t k = strcspn(p, " ,");
        if (k == n && !strncmp(p, ip, n))
            return 1;
        p += k;
    }
    return 0;
}

int pk_callback_address_ok(const char *ip, const char *allow)
{
    struct in_addr a4;
    struct in6_addr a6;
    if (listed(ip, allow))
        return 1;
    if (inet_pton(AF_INET, ip, &a4) == 1)
        return !private4(ntohl(a4.s_addr));
    if (inet_pton(AF_INET6, ip, &a6) != 1)
        return 0;
    if (IN6_IS_ADDR_V4MAPPED(&a6)) {
        uint32_t v;
        memcpy(&v, &a6.s6_addr[12], 4);
        return !private4(ntohl(v));
    }
    return !(IN6_IS_ADDR_LOOPBACK(&a6) || IN6_IS_ADDR_UNSPECIFIED(&a6) ||
             IN6_IS_ADDR_LINKLOCAL(&a6) || IN6_IS_ADDR_MULTICAST(&a6) ||
             (a6.s6_addr[0] & 0xfe) == 0xfc); /* fc00::/7, unique local */
}

/* --- the last event handed on, kept across restarts */

static void state_path(char *out, size_t n)
{
    pk_config cfg = pk_service_config(C.svc);
    snprintf(out, n, "%s/callbacks.last", cfg.data);
}

static void save_last(void)
{
    char path[1100], tmp[1200];
    state_path(path, sizeof path);
    snprintf(tmp, sizeof tmp, "%s.tmp", path);
    FILE *f = fopen(tmp, "w");
    if (f && fprintf(f, "%lld\n", C.last) > 0 && fclose(f) == 0)
        rename(tmp, path);
    else if (f)
        fclose(f);
}

static void load_last(void)
{
    char path[1100];
    state_path(path, sizeof path);
    FILE *f = fopen(path, "r");
    if (f && fscanf(f, "%lld", &C.last) == 1) {
        fclose(f);
        return;
    }
    if (f)
        fclose(f);
    json_t *r = pk_queue_status_events(C.svc->q, -1, 0); /* first start: from now on */
    C.last = json_integer_value(json_object_get(r, "id"));
    json_decref(r);
    save_last();
}

/* --- deliveries */

static void delivery_free(delivery *d)
{
    free(d->uri);
    free(d->body);
    free(d->owner);
    free(d);
}

/* d into the list at its due time (the oldest dropped when too many wait). */
static void insert(delivery *d)
{
    pthread_mutex_lock(&C.mu);
    if (C.pending >= PENDING_MAX && C.head) { /* the oldest goes */
        delivery *old = C.head;
        C.head = old->next;
        C.pending--;
        pk_log(PK_LOG_WARN, "callback dropped: too many waiting", "{s:s,s:s}", "job", old->job,
               "uri", old->uri);
        delivery_free(old);
    }
    delivery **p = &C.head;
    while (*p && (*p)->due <= d->due)
        p = &(*p)->next;
    d->next = *p;
    *p = d;
    C.pending++;
    pthread_mutex_unlock(&C.mu);
}

static void enqueue(const char *job, const char *owner, const char *uri, char *body, double due)
{
    delivery *d = calloc(1, sizeof *d);
    if (!d || !(d->uri = strdup(uri)) || !(d->owner = strdup(owner ? owner : ""))) {
        if (d)
            free(d->uri);
        free(d);
        free(body);
        return;
    }
    d->body = body;
    snprintf(d->job, sizeof d->job, "%s", job);
    d->due = due;
    insert(d);
}

/* libcurl's hook once connected, before the request: the address policy */
static int check_peer(void *cls, char *ip, char *local, int port, int local_port)
{
    conn_check *c = cls;
    (void)local, (void)port, (void)local_port;
    if (pk_callback_address_ok(ip, c->allow))
        return CURL_PREREQFUNC_OK;
    snprintf(c->refused, sizeof c->refused, "%s", ip);
    return CURL_PREREQFUNC_ABORT;
}

static size_t discard(char *p, size_t size, size_t n, void *cls)
{
    (void)p, (void)cls;
    return size * n;
}

/* Start d's POST on the multi handle; 0, or -1 (d left to the caller). */
static int post_start(delivery *d)
{
    pk_config cfg = pk_service_config(C.svc);
    transfer *t = calloc(1, sizeof *t);
    if (!t || !(t->h = curl_easy_init())) {
        free(t);
        return -1;
    }
    t->d = d;
    snprintf(t->cc.allow, sizeof t->cc.allow, "%s", cfg.callback_allow);
    t->hdr = curl_slist_append(NULL, "Content-Type: application/json");
    t->hdr = curl_slist_append(t->hdr, "User-Agent: packd/" PACKD_VERSION);
    CURL *h = t->h;
    curl_easy_setopt(h, CURLOPT_URL, d->uri);
    curl_easy_setopt(h, CURLOPT_PROTOCOLS_STR, "http,https");
    curl_easy_setopt(h, CURLOPT_FOLLOWLOCATION, 0L);
    curl_easy_setopt(h, CURLOPT_NOSIGNAL, 1L);
    curl_easy_setopt(h, CURLOPT_CONNECTTIMEOUT, 5L);
    curl_easy_setopt(h, CURLOPT_TIMEOUT, 10L);
    curl_easy_setopt(h, CURLOPT_HTTPHEADER, t->hdr);
    curl_easy_setopt(h, CURLOPT_POSTFIELDS, d->body);
    curl_easy_setopt(h, CURLOPT_PREREQFUNCTION, check_peer);
    curl_easy_setopt(h, CURLOPT_PREREQDATA, &t->cc);
    curl_easy_setopt(h, CURLOPT_WRITEFUNCTION, discard);
    curl_easy_setopt(h, CURLOPT_PRIVATE, t);
    if (curl_multi_add_handle(C.multi, h) != CURLM_OK) {
        curl_slist_free_all(t->hdr);
        curl_easy_cleanup(h);
        free(t);
        return -1;
    }
    C.flying[C.nflying++] = t;
    return 0;
}

/* How t's POST ended: 1 delivered, 0 to retry, -1 never (refused by the
 * address policy); why says it. */
static int post_outcome(transfer *t, CURLcode rc, char *why, size_t n)
{
    long code = 0;
    curl_easy_getinfo(t->h, CURLINFO_RESPONSE_CODE, &code);
    if (t->cc.refused[0]) {
        snprintf(why, n, "%s is a private, loopback or link-local address (callback_allow)",
                 t->cc.refused);
        return -1;
    }
    if (rc != CURLE_OK) {
        snprintf(why, n, "%s", curl_easy_strerror(rc));
        return 0;
    }
    snprintf(why, n, "HTTP %ld", code);
    return code >= 200 && code < 300;
}

/* A delivery tried: logged, and re-queued 2/8/32 s later while it may be
 * retried. */
static void settle(delivery *d, int ok, const char *why, double now)
{
    if (ok == 0 && d->attempt < RETRIES) {
        d->attempt++;
        pk_log(PK_LOG_WARN, "callback failed: retrying", "{s:s,s:s,s:s,s:i}", "job", d->job, "uri",
               d->uri, "error", why, "attempt", d->attempt);
        d->due = now + (double)(1 << (2 * d->attempt - 1));
        insert(d);
        return;
    }
    pk_log(ok > 0 ? PK_LOG_INFO : PK_LOG_WARN, ok > 0 ? "callback delivered" : "callback given up",
           "{s:s,s:s,s:s}", "job", d->job, "uri", d->uri, "answer", why);
    delivery_free(d);
}

static void transfer_end(transfer *t)
{
    curl_multi_remove_handle(C.multi, t->h);
    curl_easy_cleanup(t->h);
    curl_slist_free_all(t->hdr);
    for (int i = 0; i < C.nflying; i++)
        if (C.flying[i] == t) {
            C.flying[i] = C.flying[--C.nflying];
            break;
        }
    free(t);
}

/* 1 when d may start now: a slot free, its owner under its share, no
 * delivery of its job in flight. */
static int may_start(const delivery *d)
{
    int owner = 0;
    if (C.nflying >= IN_FLIGHT_MAX)
        return 0;
    for (int i = 0; i < C.nflying; i++) {
        const delivery *f = C.flying[i]->d;
        if (!strcmp(f->job, d->job))
            return 0;
        owner += !strcmp(f->owner, d->owner);
    }
    return owner < PER_OWNER_MAX;
}

/* Start the deliveries due by now that may start, in due order. */
static void start_due(double now)
{
    pthread_mutex_lock(&C.mu);
    for (delivery **p = &C.head; *p && (*p)->due <= now && C.nflying < IN_FLIGHT_MAX;) {
        delivery *d = *p;
        if (!may_start(d)) {
            p = &d->next;
            continue;
        }
        *p = d->next;
        C.pending--;
        if (post_start(d) != 0) {
            pthread_mutex_unlock(&C.mu);
            settle(d, 0, "cannot make an HTTP client", now);
            pthread_mutex_lock(&C.mu);
            p = &C.head; /* the list changed */
        }
    }
    pthread_mutex_unlock(&C.mu);
}

/* Move the transfers along for up to wait_ms (less when one ends) and
 * settle those that ended. */
static void run_transfers(int wait_ms)
{
    int still = 0, left = 0;
    curl_multi_perform(C.multi, &still);
    if (still)
        curl_multi_poll(C.multi, NULL, 0, wait_ms, NULL);
    curl_multi_perform(C.multi, &still);
    CURLMsg *m;
    while ((m = curl_multi_info_read(C.multi, &left))) {
        if (m->msg != CURLMSG_DONE)
            continue;
        char *priv = NULL;
        curl_easy_getinfo(m->easy_handle, CURLINFO_PRIVATE, &priv);
        transfer *t = (transfer *)priv;
        char why[200];
        int ok = post_outcome(t, m->data.result, why, sizeof why);
        delivery *d = t->d;
        transfer_end(t);
        settle(d, ok, why, pk_queue_now());
    }
}

/* --- status events to deliveries */

static void hand_on(json_t *ev)
{
    const char *job = json_string_value(json_object_get(ev, "job_id"));
    pk_config cfg = pk_service_config(C.svc);
    pk_exec_opts o;
    pk_results_opts_read(cfg.data, job, &o);
    json_t *data = json_object_get(ev, "data"); /* decoded by the queue */
    const char *st = json_string_value(json_object_get(data, "status"));
    const char *which = !st                                 ? NULL
        : !strcmp(st, "successful")                         ? "successUri"
        : !strcmp(st, "failed")                             ? "failedUri"
        : !strcmp(st, "accepted") || !strcmp(st, "running") ? "inProgressUri"
                                                            : NULL;
    const char *uri = which ? json_string_value(json_object_get(o.subscriber, which)) : NULL;
    json_t *row = uri ? pk_queue_get(C.svc->q, job) : NULL;
    if (row) {
        json_t *doc = !strcmp(which, "successUri") ? pk_results_document_of(cfg.data, row, &o)
                                                   : pk_status_info(row);
        json_t *info = pk_status_info(row);
        if (!strcmp(which, "successUri")) /* the results, and which job they are of */
            json_object_set(doc, "jobID", json_object_get(info, "jobID"));
        /* the status the event recorded, not a later one the row shows by now */
        if (strcmp(which, "successUri"))
            json_object_set_new(doc, "status", json_string(st));
        pk_hide_data_paths_json(doc, cfg.data);
        pk_absolute_links_at(doc, o.base);
        char *body = json_dumps(doc, JSON_COMPACT | JSON_REAL_PRECISION(10));
        if (body)
            enqueue(job, json_string_value(json_object_get(row, "owner")), uri, body,
                    pk_queue_now());
        json_decref(info);
        json_decref(doc);
        json_decref(row);
    }
    pk_exec_opts_free(&o);
}

static void *follow(void *arg)
{
    (void)arg;
    long long seen = pk_queue_event_seq(C.svc->q);
    for (;;) {
        pthread_mutex_lock(&C.mu);
        int quit = C.quit;
        double next = C.head ? C.head->due : 0;
        pthread_mutex_unlock(&C.mu);
        if (quit)
            return NULL;
        json_t *evs = pk_queue_status_events(C.svc->q, C.last, BATCH);
        size_t i;
        json_t *ev;
        json_array_foreach (evs, i, ev) {
            hand_on(ev);
            C.last = json_integer_value(json_object_get(ev, "id"));
        }
        if (json_array_size(evs))
            save_last();
        int more = json_array_size(evs) == BATCH;
        json_decref(evs);
        double now = pk_queue_now();
        start_due(now);
        if (more)
            continue;
        int wait_ms = next > now ? (int)((next - now) * 1000) + 1 : 1000;
        if (wait_ms > 1000)
            wait_ms = 1000;
        if (C.nflying) /* the transfers, with a look at the queue's events every 0.1 s */
            run_transfers(wait_ms < 100 ? wait_ms : 100);
        else
            seen = pk_queue_wait_event(C.svc->q, seen, wait_ms);
    }
}

int pk_callbacks_start(pk_service *svc)
{
    C.svc = svc;
    C.quit = 0;
    curl_global_init(CURL_GLOBAL_DEFAULT);
    load_last();
    if (!(C.multi = curl_multi_init()))
        return -1;
    if (pthread_create(&C.thread, NULL, follow, NULL) != 0) {
        curl_multi_cleanup(C.multi);
        C.multi = NULL;
        return -1;
    }
    C.running = 1;
    return 0;
}

void pk_callbacks_stop(void)
{
    if (!C.running)
        return;
    pthread_mutex_lock(&C.mu);
    C.quit = 1;
    pthread_mutex_unlock(&C.mu);
    pk_queue_wake_all(C.svc->q);
    pthread_join(C.thread, NULL);
    C.running = 0;
    while (C.nflying) { /* cut off: not delivered */
        delivery *d = C.flying[0]->d;
        transfer_end(C.flying[0]);
        d->next = C.head;
        C.head = d;
    }
    curl_multi_cleanup(C.multi);
    C.multi = NULL;
    while (C.head) { /* not delivered: said so */
        delivery *d = C.head;
        C.head = d->next;
        pk_log(PK_LOG_WARN, "callback not delivered: the daemon stops", "{s:s,s:s}", "job", d->job,
               "uri", d->uri);
        delivery_free(d);
    }
    C.pending = 0;
}
