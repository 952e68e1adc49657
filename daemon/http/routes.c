/* routes.c — the one route table of the HTTP API (docs/service.md, schemas/openapi.json).
 * The last column says who may call a route when auth is on: the service
 * documents and /healthz are public, /metrics (every owner's counts) needs
 * an admin token, everything else a token; owners are checked in the
 * handlers' lookups (auth.c). */
#include "http.h"
#include "route_dashboard.h"

const pk_route pk_routes[] = {
    {"GET", "/", route_landing, PK_PUBLIC},
    {"GET", "/conformance", route_conformance, PK_PUBLIC},
    {"GET", "/api", route_api, PK_PUBLIC},
    {"GET", "/processes", route_processes, PK_USER},
    {"GET", "/processes/*", route_process, PK_USER},
    {"POST", "/processes/*/execution", route_execute, PK_USER},
    {"GET", "/jobs", route_jobs, PK_USER},
    {"GET", "/jobs/*", route_job, PK_USER},
    {"DELETE", "/jobs/*", route_job_delete, PK_USER},
    {"GET", "/jobs/*/events", route_events, PK_USER},
    {"GET", "/jobs/*/results", route_results, PK_USER},
    {"GET", "/jobs/*/results/*", route_result_file, PK_USER},
    {"POST", "/files", route_files_post, PK_USER},
    {"GET", "/files/*", route_file_get, PK_USER},
    {"GET", "/metrics", route_metrics, PK_ADMIN},
    {"GET", "/healthz", route_healthz, PK_PUBLIC},
    /* the browser dashboard: its page is / for a browser (route_landing) */
    {"GET", "/dashboard/examples", route_dashboard_examples, PK_PUBLIC},
    {"GET", "/dashboard/queue", route_dashboard_queue, PK_USER},
    {"GET", "/dashboard/me", route_dashboard_me, PK_USER},
    {"GET", "/dashboard/*", route_dashboard_asset, PK_PUBLIC},
    {"GET", "/dashboard/jobs/*/inputs", route_dashboard_inputs, PK_USER},
    {"GET", "/dashboard/jobs/*/units", route_dashboard_units, PK_USER},
    {NULL, NULL, NULL, PK_PUBLIC},
};
