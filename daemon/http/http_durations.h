/* http_durations.h — packd_http_request_duration_seconds of /metrics: the
 * time from a request's complete head to its response queued (a body
 * streamed after it, an SSE stream, is not counted), by method, route
 * template (never the raw path: "/jobs/{jobId}") and status code.  Requests
 * that match no route count under route="unmatched", method="other", so the
 * label values stay a fixed, small set whatever the clients send. */
#ifndef PK_HTTP_DURATIONS_H
#define PK_HTTP_DURATIONS_H

#include "http.h"
#include "text_buf.h"

/* Count one response: rt the route the request matched (NULL: none). */
void pk_http_duration_observe(const pk_route *rt, unsigned code, double seconds);

/* The histogram's HELP, TYPE and a series per (method, route, code) seen. */
void pk_http_durations_expose(pk_text_buf *b);

#endif
