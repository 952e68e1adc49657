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

/* n decimal digits at *s; -1 when they are not all digits. */
static int digits(const char **s, int n)
{
    int v = 0;
    for (int i = 0; i < n; i++, (*s)++) {
        if (**s < '0' || **s > '9')
            return -1;
        v = v * 10 + (**s - '0');
    }
    return v;
}

static long long days_from_civil(long long y, unsigned m, unsigned d)
{
    y -= m <= 2;
    long long era = (y >= 0 ? y : y - 399) / 400;
    unsigned yoe = (unsigned)(y - era * 400);
    unsigned doy = (153 * (m > 2 ? m - 3 : m + 9) + 2) / 5 + d - 1;
    unsigned doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
    return era * 146097 + (long long)doe - 719468;
}

int pk_time_parse_rfc3339(const char *s, double *epoch, double *span)
{
    int y = digits(&s, 4);
    if (y < 0 || *s++ != '-')
        return -1;
    int mo = digits(&s, 2);
    if (mo < 1 || mo > 12 || *s++ != '-')
        return -1;
    int d = digits(&s, 2);
    static const int mdays[] = {31, 29, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
    int leap = (y % 4 == 0 && y % 100 != 0) || y % 400 == 0;
    if (d < 1 || d > mdays[mo - 1] || (mo == 2 && d == 29 && !leap))
        return -1;
    if (*s != 'T' && *s != 't' && *s != ' ')
        return -1;
    s++;
    int h = digits(&s, 2);
    if (h < 0 || h > 23 || *s++ != ':')
        return -1;
    int mi = digits(&s, 2);
    if (mi < 0 || mi > 59 || *s++ != ':')
        return -1;
    int sec = digits(&s, 2);
    if (sec < 0 || sec > 60) /* 60: a leap second, counted as the next second */
        return -1;
    double frac = 0, unit = 1;
    if (*s == '.') {
        s++;
        if (*s < '0' || *s > '9')
            return -1;
        for (; *s >= '0' && *s <= '9'; s++) {
            unit /= 10;
            frac += (*s - '0') * unit;
        }
    }
    int off = 0;
    if (*s == 'Z' || *s == 'z') {
        s++;
    } else if (*s == '+' || *s == '-' || *s == ' ') { /* ' ': a '+' form-decoded in a query */
        int sign = *s++ == '-' ? -1 : 1;
        int oh = digits(&s, 2);
        if (oh < 0 || oh > 23 || *s++ != ':')
            return -1;
        int om = digits(&s, 2);
        if (om < 0 || om > 59)
            return -1;
        off = sign * (oh * 3600 + om * 60);
    } else {
        return -1;
    }
    if (*s)
        return -1;
    *epoch = (double)(days_from_civil(y, (unsigned)mo, (unsigned)d) * 86400 + h * 3600 + mi * 60 +
                      sec - off) +
        frac;
    *span = unit;
    return 0;
}
