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

/* {"type","title","status","detail"} (detail omitted when NULL). */
json_t *pk_problem(int status, const char *type, const char *title, const char *detail);

/* 422 invalid-parameter-value with "errors": [{"pointer","rule","message"}];
 * pointers are relative to the request body (e.g. "/inputs/phi/value"). */
json_t *pk_problem_invalid(int status, const char *detail, const pk_schema_errors *errs);

#endif
