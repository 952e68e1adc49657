/* http_problem.c — RFC 7807 problem+json bodies (OGC API – Processes types).
 * Contract: api/http/http_problem.h. */
#include "http_problem.h"

json_t *pk_problem(int status, const char *type, const char *title, const char *detail)
{
    json_t *p = json_pack("{s:s,s:s,s:i}", "type", type, "title", title, "status", status);
    if (detail)
        json_object_set_new(p, "detail", json_string(detail));
    return p;
}

json_t *pk_problem_invalid(int status, const char *detail, const pk_schema_errors *errs)
{
    json_t *p = pk_problem(status, PK_PROBLEM_INVALID_INPUT, "Invalid inputs", detail);
    json_object_set_new(p, "errors", pk_schema_errors_json(errs));
    return p;
}
