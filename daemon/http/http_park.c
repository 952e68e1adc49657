/* http_park.c — parked SSE connections and the one waker thread.
 * Contract: daemon/http/http_park.h. */
#include "http_park.h"

#include <pthread.h>
#include <stdlib.h>

#include "daemon/log.h"
#include "daemon/store/queue.h"

struct pk_parked {
    struct MHD_Connection *conn;
    int suspended; /* MHD_suspend_connection called, not yet resumed */
    double wake_at;
    pk_parked *prev, *next;
};

static struct {
    pthread_mutex_t mu; /* guards everything below and every pk_parked */
    pk_parked *head;
    pk_service *svc;
    pthread_t thread;
    int running, quit;
} P = {.mu = PTHREAD_MUTEX_INITIALIZER};

static void resume(pk_parked *p)
{
    p->suspended = 0;
    MHD_resume_connection(p->conn);
}

static void *waker(void *arg)
{
    (void)arg;
    pk_queue *q = P.svc->q;
    long long seen = pk_queue_event_seq(q);
    for (;;) {
        /* Keep-alive deadlines are whole seconds apart: a 1 s tick suffices. */
        long long seq = pk_queue_wait_event(q, seen, 1000);
        double now = pk_queue_now();
        int all = seq != seen || __atomic_load_n(&P.svc->stopping, __ATOMIC_RELAXED);
        pthread_mutex_lock(&P.mu);
        all |= P.quit;
        for (pk_parked *p = P.head; p; p = p->next)
            if (p->suspended && (all || now >= p->wake_at))
                resume(p);
        int quit = P.quit;
        pthread_mutex_unlock(&P.mu);
        if (quit)
            return NULL;
        seen = seq;
    }
}

int pk_park_start(pk_service *svc)
{
    P.svc = svc;
    P.quit = 0;
    if (pthread_create(&P.thread, NULL, waker, NULL) != 0)
        return -1;
    P.running = 1;
    return 0;
}

void pk_park_stop(void)
{
    if (!P.running)
        return;
    pthread_mutex_lock(&P.mu);
    P.quit = 1;
    pthread_mutex_unlock(&P.mu);
    pk_queue_wake_all(P.svc->q);
    pthread_join(P.thread, NULL);
    P.running = 0;
}

pk_parked *pk_park_register(struct MHD_Connection *c)
{
    pk_parked *p = calloc(1, sizeof *p);
    if (!p)
        return NULL;
    p->conn = c;
    pthread_mutex_lock(&P.mu);
    p->next = P.head;
    if (P.head)
        P.head->prev = p;
    P.head = p;
    pthread_mutex_unlock(&P.mu);
    return p;
}

void pk_park_unregister(pk_parked *p)
{
    if (!p)
        return;
    pthread_mutex_lock(&P.mu);
    if (p->prev)
        p->prev->next = p->next;
    else
        P.head = p->next;
    if (p->next)
        p->next->prev = p->prev;
    pthread_mutex_unlock(&P.mu);
    free(p);
}

int pk_park(pk_parked *p, long long seen, double wake_at)
{
    pthread_mutex_lock(&P.mu);
    int rc;
    if (P.quit || !P.running || __atomic_load_n(&P.svc->stopping, __ATOMIC_RELAXED))
        rc = -1;
    else if (pk_queue_event_seq(P.svc->q) != seen)
        rc = 0;
    else {
        p->suspended = 1;
        p->wake_at = wake_at;
        MHD_suspend_connection(p->conn);
        rc = 1;
    }
    pthread_mutex_unlock(&P.mu);
    return rc;
}
