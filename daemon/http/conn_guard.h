/* conn_guard.h — deadlines and a reserve for the connection table, which
 * libmicrohttpd bounds only by an idle timeout (a client sending one byte a
 * second is never idle).  Every connection is in one phase:
 *   head      waiting for a request head (new, or kept alive after a
 *             response): closed head_timeout_s after the phase began;
 *   body      its body arriving: closed at the deadline http_server.c gives
 *             from the body's size;
 *   response  answering (files, parked SSE streams): no deadline here.
 * When the table holds more than max_connections − reserve connections, each
 * new one closes the connection waiting longest for its head (then the
 * oldest body): a flood of slow clients keeps evicting itself while a
 * client that sends its request at once is served.  Closing is a
 * shutdown(2) of the socket from here; MHD sees the end of the stream and
 * frees the connection in its own thread. */
#ifndef PK_HTTP_CONN_GUARD_H
#define PK_HTTP_CONN_GUARD_H

#include <microhttpd.h>

#include "daemon/service.h"

/* Start the deadline thread for a table of limit connections; 0 or -1. */
int pk_conn_guard_start(pk_service *svc, unsigned limit);
void pk_conn_guard_stop(void);
/* The connections above which new ones evict the slowest (limit − reserve). */
unsigned pk_conn_guard_threshold(unsigned limit);

/* MHD_OPTION_NOTIFY_CONNECTION callback (cls unused). */
void pk_conn_guard_notify(void *cls, struct MHD_Connection *c, void **socket_context,
                          enum MHD_ConnectionNotificationCode code);

/* Phase changes of connection c: its head is complete and a body of up to
 * `seconds` follows; it is answering; it waits for its next request head. */
void pk_conn_guard_body(struct MHD_Connection *c, double seconds);
void pk_conn_guard_response(struct MHD_Connection *c);
void pk_conn_guard_head(struct MHD_Connection *c);

/* Connections closed so far by a deadline and by eviction (for /metrics). */
void pk_conn_guard_counts(long long *deadline, long long *evicted);

#endif
