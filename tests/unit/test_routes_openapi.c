/* test_routes_openapi.c — every route of the daemon (daemon/http/routes.c)
 * is described in the OpenAPI document it serves at /api
 * (schemas/openapi.json), with the same method; and every path of the
 * document is a route: a client generated from /api reaches everything. */
#include <jansson.h>
#include <stdio.h>
#include <string.h>

#include "api/schemas/schemas_embedded.h"
#include "check.h"
#include "daemon/http/http.h"

/* "/jobs/{jobId}/results" becomes the router's pattern, a star for each {…} segment */
static void to_pattern(const char *path, char *out, size_t len)
{
    size_t k = 0;
    for (const char *p = path; *p && k + 1 < len; p++) {
        if (*p == '{') {
            out[k++] = '*';
            while (*p && *p != '}')
                p++;
            if (!*p)
                break;
        } else {
            out[k++] = *p;
        }
    }
    out[k] = '\0';
}

static void lower(const char *s, char *out, size_t len)
{
    size_t k = 0;
    for (; s[k] && k + 1 < len; k++)
        out[k] = (char)(s[k] >= 'A' && s[k] <= 'Z' ? s[k] + 32 : s[k]);
    out[k] = '\0';
}

static json_t *paths(void)
{
    const char *text = pk_schema_text("openapi.json");
    json_t *doc = text ? json_loads(text, 0, NULL) : NULL;
    json_t *p = json_incref(json_object_get(doc, "paths"));
    json_decref(doc);
    return p;
}

static void test_every_route_documented(void)
{
    json_t *ps = paths();
    CHECK(json_is_object(ps));
    for (const pk_route *r = pk_routes; r->method; r++) {
        int found = 0;
        const char *path;
        json_t *item;
        json_object_foreach (ps, path, item) {
            char pat[256], m[16];
            to_pattern(path, pat, sizeof pat);
            lower(r->method, m, sizeof m);
            if (!strcmp(pat, r->pattern) && json_object_get(item, m))
                found = 1;
        }
        CHECK_MSG(found, "route %s %s is not in schemas/openapi.json", r->method, r->pattern);
    }
    json_decref(ps);
}

static void test_every_path_routed(void)
{
    json_t *ps = paths();
    const char *path;
    json_t *item;
    json_object_foreach (ps, path, item) {
        char pat[256];
        to_pattern(path, pat, sizeof pat);
        const char *method;
        json_t *op;
        json_object_foreach (item, method, op) {
            if (strcmp(method, "get") && strcmp(method, "post") && strcmp(method, "delete") &&
                strcmp(method, "put") && strcmp(method, "patch"))
                continue; /* "parameters", "summary": not operations */
            int found = 0;
            for (const pk_route *r = pk_routes; r->method; r++) {
                char m[16];
                lower(r->method, m, sizeof m);
                if (!strcmp(pat, r->pattern) && !strcmp(m, method))
                    found = 1;
            }
            CHECK_MSG(found, "%s %s is documented but not routed", method, path);
        }
    }
    json_decref(ps);
}

int main(void)
{
    RUN(test_every_route_documented);
    RUN(test_every_path_routed);
    return check_summary();
}
