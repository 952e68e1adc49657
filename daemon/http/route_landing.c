/* GET /, /conformance, /api — what the service is and which standards it follows.
 * A browser asking for / gets the dashboard instead, for /api (or /api?f=html)
 * the interactive API page, the landing page's service-doc (route_dashboard.c). */
#include <string.h>

#include "html_page.h"
#include "http.h"
#include "route_dashboard.h"
#include "api/schemas/schemas_embedded.h"

static json_t *mklink(const char *href, const char *rel, const char *type, const char *title)
{
    return json_pack("{s:s,s:s,s:s,s:s}", "href", href, "rel", rel, "type", type, "title", title);
}

enum MHD_Result route_landing(pk_req *r)
{
    if (pk_prefers_html(r)) /* a browser: the dashboard */
        return pk_send_dashboard_page(r);
    json_t *links = json_array();
    json_array_append_new(links, mklink("/", "self", "application/json", "this document"));
    json_array_append_new(links,
                          mklink("/api", "service-desc",
                                 "application/vnd.oai.openapi+json;version=3.0",
                                 "the API definition (OpenAPI 3.0)"));
    json_array_append_new(links,
                          mklink("/api?f=html", "service-doc", "text/html",
                                 "the API documentation (interactive: Swagger UI)"));
    json_array_append_new(links,
                          mklink("/conformance",
                                 "http://www.opengis.net/def/rel/ogc/1.0/conformance",
                                 "application/json", "conformance classes implemented"));
    json_array_append_new(links,
                          mklink("/processes", "http://www.opengis.net/def/rel/ogc/1.0/processes",
                                 "application/json", "processes"));
    json_array_append_new(links,
                          mklink("/jobs", "http://www.opengis.net/def/rel/ogc/1.0/job-list",
                                 "application/json", "jobs"));
    return pk_send_json(
        r, 200,
        json_pack("{s:s,s:s,s:s,s:o}", "title", "packd job service", "description",
                  "Dense random packings of grains from grading curves (OGC API - Processes)",
                  "version", PACKD_VERSION, "links", links),
        NULL);
}

enum MHD_Result route_conformance(pk_req *r)
{
    const char *base = "http://www.opengis.net/spec/ogcapi-processes-1/1.0/conf/";
    const char *classes[] = {
        "core", "json", "oas30", "job-list", "dismiss", "callback", "ogc-process-description"};
    json_t *a = json_array();
    for (size_t i = 0; i < sizeof classes / sizeof *classes; i++) {
        char uri[160];
        snprintf(uri, sizeof uri, "%s%s", base, classes[i]);
        json_array_append_new(a, json_string(uri));
    }
    return pk_send_json(r, 200, json_pack("{s:o}", "conformsTo", a), NULL);
}

enum MHD_Result route_api(pk_req *r)
{
    int html = pk_wants_html(r);
    if (html < 0)
        return pk_send_bad_format(r);
    if (html)
        return pk_send_api_page(r);
    const char *doc = pk_schema_text("openapi.json"); /* schemas/openapi.json, served as is */
    if (!doc)
        return pk_reply_problem(r, PK_P_INTERNAL, "openapi.json is not compiled in");
    return pk_send_text(r, 200, "application/vnd.oai.openapi+json;version=3.0", doc);
}
