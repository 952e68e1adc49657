/* http_query.c — integer query parameters with a range: the one parser of
 * every route.  Contract: pk_query_int in daemon/http/http.h. */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>

#include "http.h"

int pk_query_int(pk_req *r, const char *name, long long def, long long min, long long max,
                 long long *out, char *detail, size_t n)
{
    const char *s = pk_query(r, name);
    *out = def;
    if (!s)
        return 0;
    char *end;
    errno = 0;
    long long v = strtoll(s, &end, 10);
    if (end == s || *end || errno == ERANGE || v < min || v > max) {
        snprintf(detail, n, "query parameter %s must be an integer in %lld..%lld", name, min, max);
        return -1;
    }
    *out = v;
    return 0;
}
