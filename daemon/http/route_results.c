/* GET /jobs/{id}/results (the results document, or the bytes of one output
 * when the execute request asked for raw / one output by value) and
 * /jobs/{id}/results/{output} (one output).  The outputs are the table of
 * api/http/http_outputs.h, the same the process descriptions declare. */
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "auth.h"
#include "http.h"
#include "results_send.h"
#include "api/http/http_status_info.h"
#include "api/picture/picture.h"
#include "api/results/xdmf.h"
#include "api/digest.h"
#include "daemon/store/job_files.h"

void pk_results_opts_load(pk_req *r, const char *id, pk_exec_opts *o)
{
    pk_config cfg = pk_service_config(r->svc);
    pk_results_opts_read(cfg.data, id, o);
}

void pk_results_opts_read(const char *data, const char *id, pk_exec_opts *o)
{
    char dir[1200], path[1300];
    pk_job_dir(data, id, dir, sizeof dir);
    pk_job_file_path(dir, PK_JOB_EXEC_OPTS, path, sizeof path);
    json_t *j = access(path, R_OK) == 0 ? json_load_file(path, 0, NULL) : NULL;
    pk_exec_opts_from_json(j, o);
    json_decref(j);
}

int pk_results_opts_save(pk_req *r, const char *id, const pk_exec_opts *o)
{
    json_t *j = pk_exec_opts_json(o);
    if (!j)
        return 0;
    pk_config cfg = pk_service_config(r->svc);
    char dir[1200], path[1300];
    pk_job_dir(cfg.data, id, dir, sizeof dir);
    pk_job_file_path(dir, PK_JOB_EXEC_OPTS, path, sizeof path);
    char jobs[1300];
    snprintf(jobs, sizeof jobs, "%s/jobs", cfg.data);
    mkdir(jobs, 0750); /* the executor makes the same directories when it claims the job */
    mkdir(dir, 0750);
    int rc = json_dump_file(j, path, JSON_COMPACT) == 0 ? 0 : -1;
    json_decref(j);
    return rc;
}

/* The row of job id if visible, successful (or, with failed_ok, failed),
 * else NULL after replying with the problem. */
static json_t *finished_job(pk_req *r, json_t *row, int failed_ok, enum MHD_Result *rc)
{
    const char *id = json_string_value(json_object_get(row, "id"));
    const char *st = json_string_value(json_object_get(row, "status"));
    if (failed_ok && !strcmp(st, "failed"))
        return row;
    if (!strcmp(st, "failed")) {
        *rc = pk_send_problem_doc(r, 422, pk_failed_results_problem(row), 0);
        json_decref(row);
        return NULL;
    }
    if (strcmp(st, "successful") != 0) {
        char d[400];
        snprintf(d, sizeof d, "the job is %s: %s", st,
                 json_string_value(json_object_get(row, "message")));
        *rc = pk_send_problem(r, 404, PK_PROBLEM_RESULT_NOT_READY, "Result not ready", d,
                              json_pack("{s:s,s:s}", "jobID", id, "jobStatus", st), 0);
        json_decref(row);
        return NULL;
    }
    return row;
}

static int selected(const pk_exec_opts *o, const char *output)
{
    if (!o || !o->select)
        return 1;
    size_t i;
    json_t *v;
    json_array_foreach (o->select, i, v)
        if (!strcmp(json_string_value(v), output))
            return 1;
    return 0;
}

static void job_file(pk_req *r, const char *id, const char *name, char *path, size_t n)
{
    pk_config cfg = pk_service_config(r->svc);
    char dir[1200];
    pk_job_dir(cfg.data, id, dir, sizeof dir);
    snprintf(path, n, "%s/%s", dir, name);
}

json_t *pk_results_document_of(const char *data, json_t *row, const pk_exec_opts *o)
{
    const char *id = json_string_value(json_object_get(row, "id"));
    json_t *doc = pk_results_document(row);
    const pk_output *out;
    char dir[1200];
    pk_job_dir(data, id, dir, sizeof dir);
    for (size_t i = 0; (out = pk_output_at(i)); i++) {
        char path[1300], href[200];
        snprintf(path, sizeof path, "%s/%s", dir, out->id);
        if (out->optional && access(path, R_OK) == 0) {
            snprintf(href, sizeof href, "/jobs/%s/results/%s", id, out->id);
            json_object_set_new(
                doc, out->id,
                json_pack("{s:s,s:s,s:s}", "href", href, "type", out->type, "title", out->title));
        }
        if (!selected(o, out->id))
            json_object_del(doc, out->id);
    }
    return doc;
}

/* One output of a row that finished_job accepted (stolen). */
static enum MHD_Result send_output(pk_req *r, json_t *row, const pk_output *out)
{
    const char *id = json_string_value(json_object_get(row, "id"));
    char path[1300], name[200];
    enum MHD_Result rc;
    if (!strcmp(out->id, "summary")) {
        json_t *s = json_object_get(row, "summary");
        rc = pk_send_json(r, 200, json_is_object(s) ? json_incref(s) : json_object(), NULL);
    } else if (out->optional) {
        char hex[65];
        job_file(r, id, out->id, path, sizeof path);
        if (access(path, R_OK) != 0 || pk_sha256_file_hex(path, hex) != 0) {
            char d[200];
            snprintf(d, sizeof d,
                     "this job has no such picture (SVG packings are drawn up to %d "
                     "grains, each plot when the result has its data)",
                     PK_PICTURE_SVG_MAX_GRAINS);
            rc = pk_reply_problem(r, PK_P_NO_SUCH_OUTPUT, d);
        } else {
            rc = pk_send_file(r, path, out->type, hex, NULL); /* shown inline */
        }
    } else if (!strcmp(out->id, "xdmf")) {
        char xpath[1300], xname[200], err[512], hex[65];
        job_file(r, id, pk_job_file_name(PK_JOB_RESULT), path, sizeof path);
        job_file(r, id, pk_job_file_name(PK_JOB_XDMF), xpath, sizeof xpath);
        snprintf(name, sizeof name, "%s.h5", id);
        snprintf(xname, sizeof xname, "%s.xdmf", id);
        if (access(xpath, R_OK) != 0 && pk_xdmf_write(path, name, xpath, err, sizeof err) != 0)
            rc = pk_reply_problem(r, PK_P_INTERNAL, err);
        else if (pk_sha256_file_hex(xpath, hex) != 0)
            rc = pk_reply_problem(r, PK_P_INTERNAL, "cannot read the XDMF file");
        else
            rc = pk_send_file(r, xpath, out->type, hex, xname);
    } else {
        job_file(r, id, pk_job_file_name(PK_JOB_RESULT), path, sizeof path);
        snprintf(name, sizeof name, "%s.h5", id);
        rc = pk_send_file(r, path, out->type,
                          json_string_value(json_object_get(row, "result_sha256")), name);
    }
    json_decref(row);
    return rc;
}

enum MHD_Result pk_send_results(pk_req *r, json_t *row, const pk_exec_opts *o)
{
    enum MHD_Result rc;
    if (!(row = finished_job(r, row, 0, &rc)))
        return rc;
    if (o->serve[0])
        return send_output(r, row, pk_output_find(o->serve));
    pk_config cfg = pk_service_config(r->svc);
    json_t *doc = pk_results_document_of(cfg.data, row, o);
    json_decref(row);
    return pk_send_json(r, 200, doc, NULL);
}

enum MHD_Result route_results(pk_req *r)
{
    json_t *row = pk_job_visible(r, r->seg[1]);
    if (!row)
        return pk_reply_problem(r, PK_P_NO_SUCH_JOB, r->seg[1]);
    pk_exec_opts o;
    pk_results_opts_load(r, r->seg[1], &o);
    /* a client that takes only JSON (packd fetch) gets the document of a raw job */
    const char *accept = pk_header(r, "Accept");
    if (o.serve[0] && accept && !strstr(accept, "*/*") &&
        !strstr(accept, pk_output_find(o.serve)->type))
        o.serve[0] = 0;
    enum MHD_Result rc = pk_send_results(r, row, &o);
    pk_exec_opts_free(&o);
    return rc;
}

enum MHD_Result route_result_file(pk_req *r)
{
    const pk_output *out = pk_output_find(r->seg[3]);
    if (!out) {
        char all[600];
        pk_outputs_list(all, sizeof all);
        return pk_reply_problem(r, PK_P_NO_SUCH_OUTPUT, all);
    }
    json_t *row = pk_job_visible(r, r->seg[1]);
    if (!row)
        return pk_reply_problem(r, PK_P_NO_SUCH_JOB, r->seg[1]);
    enum MHD_Result rc;
    /* a failed job's summary (why it stopped) and partial result file stay readable */
    int file = !strcmp(out->id, "result") || !strcmp(out->id, "xdmf");
    int failed_ok = !strcmp(out->id, "summary") || (file && pk_has_partial_result(row));
    if (!(row = finished_job(r, row, failed_ok, &rc)))
        return rc;
    return send_output(r, row, out);
}
