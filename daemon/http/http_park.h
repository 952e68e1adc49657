/* http_park.h — responses that wait for the queue (SSE streams) without
 * holding a thread.  A content reader with nothing to send parks its
 * connection (MHD_suspend_connection) and returns 0; one waker thread resumes
 * parked connections when the queue's event sequence moves, when a
 * connection's wake time passes (keep-alive), and when the service stops.
 *
 * The lost-wake-up rule: the reader reads pk_queue_event_seq() before it
 * looks for work and passes that value to pk_park(), which refuses to park
 * when the sequence has moved since; the waker resumes every parked
 * connection after each move it sees. */
#ifndef PK_HTTP_PARK_H
#define PK_HTTP_PARK_H

#include <microhttpd.h>

#include "daemon/service.h"

typedef struct pk_parked pk_parked;

/* Start the waker thread; 0 or -1. */
int pk_park_start(pk_service *svc);
/* Resume every parked connection, refuse new parks, join the waker.  Call
 * before MHD_stop_daemon (MHD must not be stopped with suspended connections). */
void pk_park_stop(void);

/* A response of connection c that may park (NULL when out of memory). */
pk_parked *pk_park_register(struct MHD_Connection *c);
/* From the response's free callback: c is gone. */
void pk_park_unregister(pk_parked *p);

/* From the content reader with nothing to send, `seen` being the event
 * sequence read before looking: 1 parked (return 0 to MHD), 0 look again
 * (something may have arrived), -1 the service stops (end the stream).
 * The connection is woken at wake_at (pk_queue_now() clock) at the latest. */
int pk_park(pk_parked *p, long long seen, double wake_at);

#endif
