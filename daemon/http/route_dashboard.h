/* route_dashboard.h — the browser dashboard (docs/service.md, "Dashboard"):
 * its page at / for a browser, its assets and the examples it offers. */
#ifndef PK_ROUTE_DASHBOARD_H
#define PK_ROUTE_DASHBOARD_H

#include "http.h"

/* The request's Accept prefers text/html to application/json (a browser);
 * a tie, a wildcard-only or a missing Accept keeps JSON. */
int pk_prefers_html(pk_req *r);
/* The dashboard's page (web/index.html). */
enum MHD_Result pk_send_dashboard_page(pk_req *r);
/* The interactive API page (web/api.html: Swagger UI over GET /api). */
enum MHD_Result pk_send_api_page(pk_req *r);

enum MHD_Result route_dashboard_asset(pk_req *r);    /* GET /dashboard/{file} */
enum MHD_Result route_dashboard_examples(pk_req *r); /* GET /dashboard/examples */
enum MHD_Result route_dashboard_inputs(pk_req *r);   /* GET /dashboard/jobs/{id}/inputs */
enum MHD_Result route_dashboard_queue(pk_req *r);    /* GET /dashboard/queue */
enum MHD_Result route_dashboard_me(pk_req *r);       /* GET /dashboard/me */
enum MHD_Result route_dashboard_units(pk_req *r);    /* GET /dashboard/jobs/{id}/units */

#endif
