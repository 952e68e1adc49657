/* routes.c — the one route table of the HTTP API (docs/service.md, schemas/openapi.json). */
#include "http.h"

const pk_route pk_routes[] = {
    {"GET", "/", route_landing},
    {"GET", "/conformance", route_conformance},
    {"GET", "/api", route_api},
    {"GET", "/processes", route_processes},
    {"GET", "/processes/*", route_process},
    {"POST", "/processes/*/execution", route_execute},
    {"GET", "/jobs", route_jobs},
    {"GET", "/jobs/*", route_job},
    {"DELETE", "/jobs/*", route_job_delete},
    {"GET", "/jobs/*/events", route_events},
    {"GET", "/jobs/*/results", route_results},
    {"GET", "/jobs/*/results/*", route_result_file},
    {"POST", "/files", route_files_post},
    {"GET", "/files/*", route_file_get},
    {"GET", "/metrics", route_metrics},
    {"GET", "/healthz", route_healthz},
    {NULL, NULL, NULL},
};
