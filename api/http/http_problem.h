/* http_problem.h — RFC 7807 application/problem+json bodies with the OGC API
 * – Processes exception types, and invalid-input problems listing the JSON
 * pointer and rule of every bad field. */
#ifndef PK_HTTP_PROBLEM_H
#define PK_HTTP_PROBLEM_H

#include <jansson.h>

#include "api/schemas/json_schema.h"

#define PK_OGC_EXC "http://www.opengis.net/def/exceptions/ogcapi-processes-1/1.0/"
#define PK_PROBLEM_NO_SUCH_JOB PK_OGC_EXC "no-such-job"
#define PK_PROBLEM_NO_SUCH_PROCESS PK_OGC_EXC "no-such-process"
#define PK_PROBLEM_RESULT_NOT_READY PK_OGC_EXC "result-not-ready"
#define PK_PROBLEM_JOB_FAILED "urn:packd:problem:job-failed"
#define PK_PROBLEM_INVALID_INPUT                                                                   \
    "http://www.opengis.net/def/exceptions/ogcapi-common-1/1.0/invalid-parameter-value"
/* packd's own types, for conditions the standards do not name */
#define PK_PROBLEM_PACKD "urn:packd:problem:"
#define PK_PROBLEM_GENERIC "about:blank" /* the HTTP status says it all */

/* The problems the service answers with, each one row of a table
 * (http_problem.c) that decides its status, type and title: a route names
 * the code and the detail only (the pattern of TALER_MHD_reply_with_ec). */
typedef enum pk_problem_code {
    PK_P_BAD_REQUEST,
    PK_P_MISDIRECTED,
    PK_P_NOT_FOUND,
    PK_P_NO_SUCH_JOB,
    PK_P_NO_SUCH_PROCESS,
    PK_P_NO_SUCH_OUTPUT,
    PK_P_NO_SUCH_FILE,
    PK_P_RESULT_NOT_READY,
    PK_P_CONTENT_TOO_LARGE,
    PK_P_UNSUPPORTED_MEDIA_TYPE,
    PK_P_INTERNAL,
    PK_P_UNAVAILABLE,
    PK_P_COUNT
} pk_problem_code;

/* The HTTP status of code. */
unsigned pk_problem_status(pk_problem_code code);

/* The document of code: {"type","title","status","detail"} (detail omitted
 * when NULL). */
json_t *pk_problem_of(pk_problem_code code, const char *detail);

/* {"type","title","status","detail"} (detail omitted when NULL). */
json_t *pk_problem(int status, const char *type, const char *title, const char *detail);

/* 422 invalid-parameter-value with "errors": [{"pointer","rule","message"}];
 * pointers are relative to the request body (e.g. "/inputs/phi/value"). */
json_t *pk_problem_invalid(int status, const char *detail, const pk_schema_errors *errs);

#endif
