/* test_http_time.c — RFC 3339 date-times as the job list's datetime takes
 * them (api/http/http_time.h): the instant, the span its precision names,
 * offsets, and what is refused. */
#include <math.h>
#include <string.h>

#include "check.h"
#include "api/http/http_time.h"

static void test_parse(void)
{
    double t, span;
    CHECK(pk_time_parse_rfc3339("1970-01-01T00:00:00Z", &t, &span) == 0 && t == 0 && span == 1);
    CHECK(pk_time_parse_rfc3339("2026-11-22T03:04:05.123Z", &t, &span) == 0);
    CHECK_NEAR(t, 1795316645.123, 1e-6);
    CHECK_NEAR(span, 1e-3, 1e-15);
    /* the same instant with an offset, lower-case separators */
    double u;
    CHECK(pk_time_parse_rfc3339("2026-11-22t05:04:05.123+02:00", &u, &span) == 0 &&
          fabs(u - t) < 1e-6);
    CHECK(pk_time_parse_rfc3339("2026-11-22T05:04:05.123 02:00", &u, &span) == 0 &&
          fabs(u - t) < 1e-6);
    CHECK(pk_time_parse_rfc3339("2024-02-29T12:00:00-00:30", &u, &span) == 0);
    CHECK_NEAR(u, 1709208000 + 1800, 1e-6); /* 12:00 at -00:30 is 12:30 UTC */
    /* what statusInfo prints parses back to the millisecond it names */
    char s[64];
    pk_time_rfc3339(1795316645.1234, s);
    CHECK(pk_time_parse_rfc3339(s, &u, &span) == 0 && u <= 1795316645.1234 &&
          1795316645.1234 < u + span);
}

static void test_refused(void)
{
    const char *bad[] = {"",
                         "2026-11-22",
                         "2026-11-22T03:04:05",
                         "2026-13-01T00:00:00Z",
                         "2025-02-29T00:00:00Z",
                         "2026-11-22T24:00:00Z",
                         "2026-11-22T03:04:05.Z",
                         "2026-11-22T03:04:05Zx",
                         "2026-11-22T03:04:05+2:00",
                         "..",
                         "now"};
    double t, span;
    for (size_t i = 0; i < sizeof bad / sizeof *bad; i++)
        CHECK_MSG(pk_time_parse_rfc3339(bad[i], &t, &span) == -1, "accepted '%s'", bad[i]);
}

int main(void)
{
    RUN(test_parse);
    RUN(test_refused);
    return check_summary();
}
