/* http_status_info.c — OGC statusInfo and results documents from a job row.
 * Contract: api/http/http_status_info.h. */
#include "http_status_info.h"

#include <stdio.h>
#include <string.h>

#include "http_problem.h"
#include "http_time.h"

static void set_time(json_t *o, const char *key, json_t *row, const char *col)
{
    json_t *v = json_object_get(row, col);
    if (json_is_number(v)) {
        char t[64];
        pk_time_rfc3339(json_number_value(v), t);
        json_object_set_new(o, key, json_string(t));
    }
}

static json_t *mklink(const char *href, const char *rel, const char *type, const char *title)
{
    json_t *l = json_pack("{s:s,s:s}", "href", href, "rel", rel);
    if (type)
        json_object_set_new(l, "type", json_string(type));
    if (title)
        json_object_set_new(l, "title", json_string(title));
    return l;
}

json_t *pk_status_info(json_t *row)
{
    const char *id = json_string_value(json_object_get(row, "id"));
    const char *status = json_string_value(json_object_get(row, "status"));
    json_t *s =
        json_pack("{s:s,s:O,s:s,s:s,s:O,s:O}", "jobID", id, "processID",
                  json_object_get(row, "process"), "type", "process", "status", status, "message",
                  json_object_get(row, "message"), "progress", json_object_get(row, "progress"));
    set_time(s, "created", row, "created");
    set_time(s, "started", row, "started");
    set_time(s, "finished", row, "finished");
    set_time(s, "updated", row, "updated");
    char href[128];
    json_t *links = json_array();
    snprintf(href, sizeof href, "/jobs/%s", id);
    json_array_append_new(links, mklink(href, "self", "application/json", "this job"));
    snprintf(href, sizeof href, "/jobs/%s/events", id);
    json_array_append_new(links,
                          mklink(href, "monitor", "text/event-stream", "live status and progress"));
    if (!strcmp(status, "successful")) {
        snprintf(href, sizeof href, "/jobs/%s/results", id);
        json_array_append_new(links,
                              mklink(href, "http://www.opengis.net/def/rel/ogc/1.0/results",
                                     "application/json", "results"));
    } else if (pk_has_partial_result(row)) {
        snprintf(href, sizeof href, "/jobs/%s/results/result", id);
        json_array_append_new(links,
                              mklink(href, "partial-result", PK_RESULT_MEDIA_TYPE,
                                     "the failed job's partial result file"));
    }
    json_object_set_new(s, "links", links);
    /* the verdict (job_verdict.h): complete, warnings, failure */
    json_t *summary = json_object_get(row, "summary");
    static const char *const verdict[] = {"complete", "warnings", "failure"};
    for (size_t i = 0; i < sizeof verdict / sizeof *verdict; i++) {
        json_t *v = json_object_get(summary, verdict[i]);
        if (v)
            json_object_set(s, verdict[i], v);
    }
    return s;
}

int pk_has_partial_result(json_t *row)
{
    const char *status = json_string_value(json_object_get(row, "status"));
    return status && !strcmp(status, "failed") &&
        json_is_string(json_object_get(row, "result_sha256"));
}

json_t *pk_failed_results_problem(json_t *row)
{
    const char *id = json_string_value(json_object_get(row, "id"));
    json_t *summary = json_object_get(row, "summary");
    json_t *doc = json_pack("{s:s,s:s,s:i,s:O,s:s,s:s}", "type", PK_PROBLEM_JOB_FAILED, "title",
                            "Job failed", "status", 422, "detail", json_object_get(row, "message"),
                            "jobID", id, "jobStatus", "failed");
    if (json_is_object(summary))
        json_object_set(doc, "summary", summary);
    if (pk_has_partial_result(row)) {
        char href[128];
        snprintf(href, sizeof href, "/jobs/%s/results/result", id);
        json_object_set_new(doc, "partial_result",
                            json_pack("{s:s,s:s,s:O,s:O}", "href", href, "type",
                                      PK_RESULT_MEDIA_TYPE, "size",
                                      json_object_get(row, "result_size"), "sha256",
                                      json_object_get(row, "result_sha256")));
    }
    return doc;
}

json_t *pk_results_document(json_t *row)
{
    const char *id = json_string_value(json_object_get(row, "id"));
    char href[128];
    snprintf(href, sizeof href, "/jobs/%s/results/result", id);
    char xdmf[128];
    snprintf(xdmf, sizeof xdmf, "/jobs/%s/results/xdmf", id);
    json_t *summary = json_object_get(row, "summary");
    return json_pack(
        "{s:{s:o},s:{s:s,s:s,s:O,s:O},s:{s:s,s:s}}", "summary", "value",
        json_is_object(summary) ? json_incref(summary) : json_object(), "result", "href", href,
        "type", PK_RESULT_MEDIA_TYPE, "size", json_object_get(row, "result_size"), "sha256",
        json_object_get(row, "result_sha256"), "xdmf", "href", xdmf, "type", "application/xml");
}
