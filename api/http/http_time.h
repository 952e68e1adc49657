/* http_time.h — timestamps as the HTTP API and the logs print them. */
#ifndef PK_HTTP_TIME_H
#define PK_HTTP_TIME_H

/* RFC 3339 UTC time with milliseconds, e.g. "2026-11-22T03:04:05.123Z";
 * epoch < 0 means now. */
void pk_time_rfc3339(double epoch, char out[64]);

/* An RFC 3339 (section 5.6) date-time -> seconds since the epoch, and the
 * span it names: 10^-d for d fraction digits given (1 s without a fraction),
 * so "…T10:00:00Z" covers the second and "…T10:00:00.123Z" the millisecond
 * that statusInfo prints.  0, or -1 when s is not a date-time. */
int pk_time_parse_rfc3339(const char *s, double *epoch, double *span);

#endif
