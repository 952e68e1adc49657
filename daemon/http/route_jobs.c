/* route_jobs.c — GET /jobs, GET /jobs/{id} (ETag/If-None-Match), DELETE
 * /jobs/{id}; routes in routes.c, replies in http.h. */
#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "auth.h"
#include "http.h"
#include "api/http/http_status_info.h"
#include "daemon/log.h"
#include "daemon/store/job_files.h"

static int valid_status(const char *s)
{
    const char *all[] = {"accepted", "running", "successful", "failed", "dismissed"};
    for (size_t i = 0; i < 5; i++)
        if (!strcmp(s, all[i]))
            return 1;
    return 0;
}

enum MHD_Result route_jobs(pk_req *r)
{
    const char *status = pk_query(r, "status"), *process = pk_query(r, "processID");
    long long limit, offset;
    char d[160];
    /* offset bounded so offset + limit stays far from any overflow */
    if (pk_query_int(r, "limit", 100, 1, 1000, &limit, d, sizeof d) != 0 ||
        pk_query_int(r, "offset", 0, 0, 1000000000, &offset, d, sizeof d) != 0)
        return pk_send_problem(r, 400, PK_PROBLEM_INVALID_INPUT, "Invalid query", d, NULL, 0);
    if (status && !valid_status(status))
        return pk_send_problem(r, 400, PK_PROBLEM_INVALID_INPUT, "Invalid query",
                               "status in accepted|running|successful|failed|dismissed", NULL, 0);
    int total = 0;
    json_t *rows = pk_queue_list(r->svc->q, status, process, pk_scope(r), (int)limit, (int)offset, &total);
    json_t *jobs = json_array();
    size_t i;
    json_t *row;
    json_array_foreach(rows, i, row) json_array_append_new(jobs, pk_status_info(row));
    json_decref(rows);
    json_t *links = json_array();
    char self[400], qs[300];
    snprintf(qs, sizeof qs, "%s%s%s%s", status ? "&status=" : "", status ? status : "",
             process ? "&processID=" : "", process ? process : "");
    snprintf(self, sizeof self, "/jobs?limit=%lld&offset=%lld%s", limit, offset, qs);
    json_array_append_new(links, json_pack("{s:s,s:s,s:s}", "href", self, "rel", "self", "type", "application/json"));
    if (offset + limit < total) {
        snprintf(self, sizeof self, "/jobs?limit=%lld&offset=%lld%s", limit, offset + limit, qs);
        json_array_append_new(links, json_pack("{s:s,s:s,s:s}", "href", self, "rel", "next", "type", "application/json"));
    }
    return pk_send_json(r, 200, json_pack("{s:o,s:i,s:o}", "jobs", jobs, "numberMatched", total, "links", links), NULL);
}

enum MHD_Result route_job(pk_req *r)
{
    json_t *row = pk_job_visible(r, r->seg[1]);
    if (!row)
        return pk_send_problem(r, 404, PK_PROBLEM_NO_SUCH_JOB, "No such job", r->seg[1], NULL, 0);
    char etag[200];
    snprintf(etag, sizeof etag, "\"%s-%lld\"", r->seg[1], (long long)json_integer_value(json_object_get(row, "rev")));
    const char *inm = pk_header(r, "If-None-Match");
    if (inm && strstr(inm, etag)) {
        json_decref(row);
        struct MHD_Response *resp = MHD_create_response_from_buffer(0, "", MHD_RESPMEM_PERSISTENT);
        MHD_add_response_header(resp, "ETag", etag);
        return pk_send(r, 304, resp);
    }
    json_t *info = pk_status_info(row);
    json_decref(row);
    return pk_send_json(r, 200, info, etag);
}

/* A dismissed finished job's files go; the row stays (status "dismissed"). */
static void remove_job_files(const char *data, const char *id)
{
    char dir[1200];
    pk_job_dir(data, id, dir, sizeof dir);
    DIR *d = opendir(dir);
    if (!d)
        return;
    struct dirent *e;
    while ((e = readdir(d))) {
        char p[1500];
        if (e->d_name[0] != '.' && snprintf(p, sizeof p, "%s/%s", dir, e->d_name) < (int)sizeof p)
            unlink(p);
    }
    closedir(d);
    rmdir(dir);
}

enum MHD_Result route_job_delete(pk_req *r)
{
    char was[16];
    json_t *mine = pk_job_visible(r, r->seg[1]);
    json_decref(mine);
    if (!mine || pk_queue_dismiss(r->svc->q, r->seg[1], was) != 0)
        return pk_send_problem(r, 404, PK_PROBLEM_NO_SUCH_JOB, "No such job", r->seg[1], NULL, 0);
    if (!strcmp(was, "running")) {
        pk_supervisor_wake(r->svc->sup); /* SIGTERM to the worker now */
    } else if (!strcmp(was, "successful") || !strcmp(was, "failed")) {
        pk_config cfg = pk_service_config(r->svc);
        remove_job_files(cfg.data, r->seg[1]);
    }
    pk_log(PK_LOG_INFO, "job dismissed", "{s:s,s:s}", "job", r->seg[1], "was", was);
    json_t *row = pk_queue_get(r->svc->q, r->seg[1]);
    json_t *info = pk_status_info(row);
    json_decref(row);
    return pk_send_json(r, 200, info, NULL);
}
