/* cors.h — Cross-Origin Resource Sharing (the Fetch standard), off unless
 * cors_origins is configured: a comma-separated list of origins
 * ("https://lab.example", "http://localhost:3000"; "*" = any).  A request
 * whose Origin is listed gets Access-Control-Allow-Origin with that origin
 * and the response headers a client reads (Location, Preference-Applied, …);
 * a preflight (OPTIONS with Access-Control-Request-Method) gets the methods
 * of its path and the request headers the API reads.  Credentials are bearer
 * tokens, never cookies, so Access-Control-Allow-Credentials is not sent. */
#ifndef PK_HTTP_CORS_H
#define PK_HTTP_CORS_H

#include <microhttpd.h>

#include "daemon/config.h"

/* 1 if origin (an Origin header value, may be NULL) is one cfg allows. */
int pk_cors_origin_allowed(const pk_config *cfg, const char *origin);

/* The CORS headers of any response to a request carrying origin (may be NULL). */
void pk_cors_response_headers(const pk_config *cfg, const char *origin, struct MHD_Response *resp);

/* The headers of a preflight's answer for a path whose methods are allow
 * ("GET, HEAD, DELETE"), when origin is allowed. */
void pk_cors_preflight_headers(const pk_config *cfg, const char *origin, const char *allow,
                               struct MHD_Response *resp);

#endif
