/* conn_guard.c — connection deadlines and the table's reserve.
 * Contract: daemon/http/conn_guard.h. */
#include "conn_guard.h"

#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <sys/socket.h>
#include <time.h>

#include "daemon/log.h"

enum phase { HEAD, BODY, RESPONSE };

typedef struct slot {
    int fd;
    int used, closing;
    enum phase phase;
    double since, deadline; /* monotonic seconds */
    struct slot *next_free;
} slot;

static struct {
    pk_service *svc;
    pthread_mutex_t mu;
    pthread_cond_t cv;
    pthread_t thread;
    int running;
    slot *slots, *free_list;
    unsigned nslots, open, closing, threshold;
    long long by_deadline, evicted;
} G = {.mu = PTHREAD_MUTEX_INITIALIZER, .cv = PTHREAD_COND_INITIALIZER};

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Rule: a reserve of 1/16 of the table (at least 8) stays for clients
 * that send their request at once; 4096 → 3840. */
unsigned pk_conn_guard_threshold(unsigned limit)
{
    unsigned reserve = limit / 16 > 8 ? limit / 16 : 8;
    return limit > 2 * reserve ? limit - reserve : limit / 2;
}

/* Under G.mu: end s's connection (MHD frees it when it reads the end). */
static void close_slot(slot *s)
{
    s->closing = 1;
    s->deadline = INFINITY;
    G.closing++;
    shutdown(s->fd, SHUT_RDWR);
}

/* Under G.mu: the connection waiting longest for its head, else the
 * oldest body; NULL when every other one is answering. */
static slot *slowest(const slot *except)
{
    slot *best = NULL;
    for (unsigned i = 0; i < G.nslots; i++) {
        slot *s = &G.slots[i];
        if (!s->used || s->closing || s == except || s->phase == RESPONSE)
            continue;
        if (!best || s->phase < best->phase || (s->phase == best->phase && s->since < best->since))
            best = s;
    }
    return best;
}

static double head_timeout(void)
{
    pk_config cfg = pk_service_config(G.svc);
    return cfg.head_timeout_s;
}

static void set_phase(slot *s, enum phase p, double seconds)
{
    double t = now();
    pthread_mutex_lock(&G.mu);
    if (s->used && !s->closing) {
        s->phase = p;
        s->since = t;
        s->deadline = seconds > 0 ? t + seconds : INFINITY;
    }
    pthread_mutex_unlock(&G.mu);
}

static slot *slot_of(struct MHD_Connection *c)
{
    const union MHD_ConnectionInfo *ci =
        MHD_get_connection_info(c, MHD_CONNECTION_INFO_SOCKET_CONTEXT);
    return ci ? ci->socket_context : NULL;
}

void pk_conn_guard_notify(void *cls, struct MHD_Connection *c, void **socket_context,
                          enum MHD_ConnectionNotificationCode code)
{
    (void)cls;
    if (code == MHD_CONNECTION_NOTIFY_CLOSED) {
        slot *s = *socket_context;
        if (!s)
            return;
        pthread_mutex_lock(&G.mu);
        G.open--;
        if (s->closing)
            G.closing--;
        s->used = s->closing = 0;
        s->next_free = G.free_list;
        G.free_list = s;
        pthread_mutex_unlock(&G.mu);
        *socket_context = NULL;
        return;
    }
    const union MHD_ConnectionInfo *ci =
        MHD_get_connection_info(c, MHD_CONNECTION_INFO_CONNECTION_FD);
    double t = now(), head = head_timeout();
    pthread_mutex_lock(&G.mu);
    slot *s = G.free_list;
    if (s && ci) {
        G.free_list = s->next_free;
        *s = (slot){.fd = ci->connect_fd, .used = 1, .phase = HEAD, .since = t,
                    .deadline = t + head};
        G.open++;
        *socket_context = s;
        if (G.open - G.closing > G.threshold) {
            slot *victim = slowest(s);
            if (victim) {
                close_slot(victim);
                G.evicted++;
            }
        }
    }
    pthread_mutex_unlock(&G.mu);
}

void pk_conn_guard_body(struct MHD_Connection *c, double seconds)
{
    slot *s = slot_of(c);
    if (s)
        set_phase(s, BODY, seconds);
}

void pk_conn_guard_response(struct MHD_Connection *c)
{
    slot *s = slot_of(c);
    if (s)
        set_phase(s, RESPONSE, 0);
}

void pk_conn_guard_head(struct MHD_Connection *c)
{
    slot *s = slot_of(c);
    if (s)
        set_phase(s, HEAD, head_timeout());
}

void pk_conn_guard_counts(long long *deadline, long long *evicted)
{
    pthread_mutex_lock(&G.mu);
    *deadline = G.by_deadline;
    *evicted = G.evicted;
    pthread_mutex_unlock(&G.mu);
}

/* Every 0.25 s: close the connections past their deadline; a log line at
 * most every 10 s says how many were closed since the last one. */
static void *deadlines(void *arg)
{
    (void)arg;
    long long logged_deadline = 0, logged_evicted = 0;
    double next_log = now() + 10;
    pthread_mutex_lock(&G.mu);
    while (G.running) {
        double t = now();
        for (unsigned i = 0; i < G.nslots; i++) {
            slot *s = &G.slots[i];
            if (s->used && !s->closing && s->deadline <= t) {
                close_slot(s);
                G.by_deadline++;
            }
        }
        if (t >= next_log && (G.by_deadline != logged_deadline || G.evicted != logged_evicted)) {
            pk_log(PK_LOG_WARN, "slow connections closed", "{s:I,s:I,s:i}", "head_or_body_deadline",
                   (json_int_t)(G.by_deadline - logged_deadline), "evicted_near_limit",
                   (json_int_t)(G.evicted - logged_evicted), "open", (int)G.open);
            logged_deadline = G.by_deadline;
            logged_evicted = G.evicted;
            next_log = t + 10;
        }
        struct timespec ts;
        clock_gettime(CLOCK_REALTIME, &ts);
        ts.tv_nsec += 250000000L;
        if (ts.tv_nsec >= 1000000000L) {
            ts.tv_sec++;
            ts.tv_nsec -= 1000000000L;
        }
        pthread_cond_timedwait(&G.cv, &G.mu, &ts);
    }
    pthread_mutex_unlock(&G.mu);
    return NULL;
}

int pk_conn_guard_start(pk_service *svc, unsigned limit)
{
    G.svc = svc;
    G.nslots = limit + 16; /* MHD admits at most limit */
    G.slots = calloc(G.nslots, sizeof *G.slots);
    if (!G.slots)
        return -1;
    G.free_list = NULL;
    for (unsigned i = G.nslots; i-- > 0;) {
        G.slots[i].next_free = G.free_list;
        G.free_list = &G.slots[i];
    }
    G.open = G.closing = 0;
    G.threshold = pk_conn_guard_threshold(limit);
    G.running = 1;
    if (pthread_create(&G.thread, NULL, deadlines, NULL) != 0) {
        G.running = 0;
        free(G.slots);
        G.slots = NULL;
        return -1;
    }
    return 0;
}

void pk_conn_guard_stop(void)
{
    pthread_mutex_lock(&G.mu);
    if (!G.running) {
        pthread_mutex_unlock(&G.mu);
        return;
    }
    G.running = 0;
    pthread_cond_signal(&G.cv);
    pthread_mutex_unlock(&G.mu);
    pthread_join(G.thread, NULL);
    /* the slots stay: MHD_stop_daemon still reports each connection closed */
}
