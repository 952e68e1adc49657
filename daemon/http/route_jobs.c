/* GET /jobs/{id} (ETag/If-None-Match), DELETE /jobs/{id}; the list GET /jobs
 * is route_job_list.c. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "auth.h"
#include "http.h"
#include "api/http/http_status_info.h"
#include "daemon/log.h"
#include "daemon/store/job_files.h"

enum MHD_Result route_job(pk_req *r)
{
    json_t *row = pk_job_visible(r, r->seg[1]);
    if (!row)
        return pk_reply_problem(r, PK_P_NO_SUCH_JOB, r->seg[1]);
    char etag[200];
    snprintf(etag, sizeof etag, "\"%s-%lld\"", r->seg[1],
             (long long)json_integer_value(json_object_get(row, "rev")));
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

enum MHD_Result route_job_delete(pk_req *r)
{
    char was[16];
    json_t *mine = pk_job_visible(r, r->seg[1]);
    json_decref(mine);
    if (!mine || pk_queue_dismiss(r->svc->q, r->seg[1], was) != 0)
        return pk_reply_problem(r, PK_P_NO_SUCH_JOB, r->seg[1]);
    if (!strcmp(was, "running")) {
        pk_executor_wake(r->svc->exec); /* SIGTERM to the worker (scancel) now */
    } else if (!strcmp(was, "successful") || !strcmp(was, "failed")) {
        pk_config cfg = pk_service_config(r->svc);
        pk_job_dir_remove(cfg.data, r->seg[1]); /* the row stays */
    }
    pk_log(PK_LOG_INFO, "job dismissed", "{s:s,s:s}", "job", r->seg[1], "was", was);
    json_t *row = pk_queue_get(r->svc->q, r->seg[1]);
    json_t *info = pk_status_info(row);
    json_decref(row);
    return pk_send_json(r, 200, info, NULL);
}
