/* http_problem.c — RFC 7807 problem+json bodies (OGC API – Processes types).
 * Contract: api/http/http_problem.h. */
#include "http_problem.h"

static const struct {
    unsigned status;
    const char *type, *title;
} problems[PK_P_COUNT] = {
    [PK_P_BAD_REQUEST] = {400, PK_PROBLEM_GENERIC, "Bad Request"},
    [PK_P_MISDIRECTED] = {421, PK_PROBLEM_GENERIC, "Misdirected Request"},
    [PK_P_NOT_FOUND] = {404, PK_PROBLEM_GENERIC, "Not Found"},
    [PK_P_NO_SUCH_JOB] = {404, PK_PROBLEM_NO_SUCH_JOB, "No such job"},
    [PK_P_NO_SUCH_PROCESS] = {404, PK_PROBLEM_NO_SUCH_PROCESS, "No such process"},
    [PK_P_NO_SUCH_OUTPUT] = {404, PK_PROBLEM_PACKD "no-such-output", "No such output"},
    [PK_P_NO_SUCH_FILE] = {404, PK_PROBLEM_PACKD "no-such-file", "No such file"},
    [PK_P_RESULT_NOT_READY] = {404, PK_PROBLEM_RESULT_NOT_READY, "Result not ready"},
    [PK_P_CONTENT_TOO_LARGE] = {413, PK_PROBLEM_GENERIC, "Content Too Large"},
    [PK_P_UNSUPPORTED_MEDIA_TYPE] = {415, PK_PROBLEM_GENERIC, "Unsupported Media Type"},
    [PK_P_INTERNAL] = {500, PK_PROBLEM_GENERIC, "Internal Server Error"},
    [PK_P_UNAVAILABLE] = {503, PK_PROBLEM_GENERIC, "Service Unavailable"},
};

unsigned pk_problem_status(pk_problem_code code)
{
    return code >= 0 && code < PK_P_COUNT ? problems[code].status : 500;
}

json_t *pk_problem_of(pk_problem_code code, const char *detail)
{
    if (!(code >= 0 && code < PK_P_COUNT))
        code = PK_P_INTERNAL;
    return pk_problem((int)problems[code].status, problems[code].type, problems[code].title,
                      detail);
}

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
