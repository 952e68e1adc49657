/* http_time.h — timestamps as the HTTP API and the logs print them. */
#ifndef PK_HTTP_TIME_H
#define PK_HTTP_TIME_H

/* RFC 3339 UTC time with milliseconds, e.g. "2026-11-22T03:04:05.123Z";
 * epoch < 0 means now. */
void pk_time_rfc3339(double epoch, char out[64]);

#endif
