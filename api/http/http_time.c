/* http_time.c — RFC 3339 UTC timestamps of the HTTP API and the logs.
 * Contract: api/http/http_time.h. */
#include "http_time.h"

#include <stdio.h>
#include <time.h>

void pk_time_rfc3339(double epoch, char out[64])
{
    struct timespec ts;
    if (epoch < 0) {
        clock_gettime(CLOCK_REALTIME, &ts);
    } else {
        ts.tv_sec = (time_t)epoch;
        ts.tv_nsec = (long)((epoch - (double)ts.tv_sec) * 1e9);
    }
    struct tm tm;
    gmtime_r(&ts.tv_sec, &tm);
    snprintf(out, 64, "%04d-%02d-%02dT%02d:%02d:%02d.%03dZ", tm.tm_year + 1900, tm.tm_mon + 1,
             tm.tm_mday, tm.tm_hour, tm.tm_min, tm.tm_sec, (int)(ts.tv_nsec / 1000000) % 1000);
}
