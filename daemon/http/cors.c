/* cors.c — CORS for the configured origins.  Contract: daemon/http/cors.h. */
#include "cors.h"

#include <string.h>
#include <strings.h>

/* The headers a browser client reads from the API's answers; the safelisted
 * ones (Content-Type, Content-Length, Cache-Control, …) are readable anyway. */
#define EXPOSED                                                                                    \
    "Location, Link, Preference-Applied, Idempotent-Replayed, ETag, Retry-After, "                 \
    "Content-Disposition, Content-Range, Accept-Ranges, Repr-Digest, X-Content-SHA256"
/* The request headers the API reads beyond the safelisted ones. */
#define ALLOWED_HEADERS                                                                            \
    "Authorization, Content-Type, Prefer, Idempotency-Key, If-None-Match, Range, Last-Event-ID"
/* How long a browser may keep a preflight's answer (seconds). */
#define PREFLIGHT_MAX_AGE "600"

/* An origin is "scheme://host[:port]": compared with each listed one
 * case-insensitively, ignoring blanks around the commas. */
int pk_cors_origin_allowed(const pk_config *cfg, const char *origin)
{
    if (!origin || !*origin || !cfg->cors_origins[0] || !strcmp(origin, "null"))
        return 0;
    size_t olen = strlen(origin);
    for (const char *p = cfg->cors_origins; *p;) {
        p += strspn(p, " \t,");
        size_t n = strcspn(p, ",");
        size_t m = n;
        while (m && (p[m - 1] == ' ' || p[m - 1] == '\t'))
            m--;
        while (m && p[m - 1] == '/') /* "https://lab.example/" names the same origin */
            m--;
        if ((m == 1 && *p == '*') || (m && m == olen && !strncasecmp(p, origin, m)))
            return 1;
        p += n;
    }
    return 0;
}

void pk_cors_response_headers(const pk_config *cfg, const char *origin, struct MHD_Response *resp)
{
    if (!cfg->cors_origins[0])
        return;
    MHD_add_response_header(resp, "Vary", "Origin"); /* caches keep one answer per origin */
    if (!pk_cors_origin_allowed(cfg, origin))
        return;
    MHD_add_response_header(resp, "Access-Control-Allow-Origin", origin);
    MHD_add_response_header(resp, "Access-Control-Expose-Headers", EXPOSED);
}

void pk_cors_preflight_headers(const pk_config *cfg, const char *origin, const char *allow,
                               struct MHD_Response *resp)
{
    if (!pk_cors_origin_allowed(cfg, origin))
        return;
    MHD_add_response_header(resp, "Access-Control-Allow-Methods", allow);
    MHD_add_response_header(resp, "Access-Control-Allow-Headers", ALLOWED_HEADERS);
    MHD_add_response_header(resp, "Access-Control-Max-Age", PREFLIGHT_MAX_AGE);
}
