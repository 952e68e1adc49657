/* route_results.c — GET /jobs/{id}/results (document) and
 * /jobs/{id}/results/{output} (file); routes in routes.c, replies in http.h. */
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "auth.h"
#include "http.h"
#include "api/http/http_status_info.h"
#include "api/picture/picture.h"
#include "daemon/store/digest.h"
#include "daemon/store/job_files.h"
#include "api/results/xdmf.h"

/* The pictures a worker draws beside the result (api/picture/picture.h). */
static const struct {
    const char *file, *type, *title;
} pictures[] = {
    {"picture.png", "image/png", "the packing"},
    {"picture.svg", "image/svg+xml", "the packing"},
    {"grading.png", "image/png", "the grading curve, target and achieved"},
    {"grading.svg", "image/svg+xml", "the grading curve, target and achieved"},
};

/* The row of a successful job (or, with partial_ok, of a failed job that
 * kept its partial result file), or NULL after replying with the problem:
 * a failed job's results answer why it failed. */
static json_t *successful_job(pk_req *r, int partial_ok, enum MHD_Result *rc)
{
    json_t *row = pk_job_visible(r, r->seg[1]);
    if (!row) {
        *rc = pk_send_problem(r, 404, PK_PROBLEM_NO_SUCH_JOB, "No such job", r->seg[1], NULL, 0);
        return NULL;
    }
    const char *st = json_string_value(json_object_get(row, "status"));
    if (partial_ok && pk_has_partial_result(row))
        return row;
    if (!strcmp(st, "failed")) {
        *rc = pk_send_problem_doc(r, 422, pk_failed_results_problem(row), 0);
        json_decref(row);
        return NULL;
    }
    if (strcmp(st, "successful") != 0) {
        char d[400];
        snprintf(d, sizeof d, "the job is %s: %s", st, json_string_value(json_object_get(row, "message")));
        *rc = pk_send_problem(r, 404, PK_PROBLEM_RESULT_NOT_READY, "Result not ready", d,
                              json_pack("{s:s,s:s}", "jobID", r->seg[1], "jobStatus", st), 0);
        json_decref(row);
        return NULL;
    }
    return row;
}

enum MHD_Result route_results(pk_req *r)
{
    enum MHD_Result rc;
    json_t *row = successful_job(r, 0, &rc);
    if (!row)
        return rc;
    json_t *doc = pk_results_document(row);
    json_decref(row);
    pk_config cfg = pk_service_config(r->svc);
    char dir[1200], path[1300], href[200];
    pk_job_dir(cfg.data, r->seg[1], dir, sizeof dir);
    for (size_t i = 0; i < sizeof pictures / sizeof *pictures; i++) {
        snprintf(path, sizeof path, "%s/%s", dir, pictures[i].file);
        if (access(path, R_OK) != 0)
            continue;
        snprintf(href, sizeof href, "/jobs/%s/results/%s", r->seg[1], pictures[i].file);
        json_object_set_new(doc, pictures[i].file,
                            json_pack("{s:s,s:s,s:s}", "href", href, "type", pictures[i].type,
                                      "title", pictures[i].title));
    }
    return pk_send_json(r, 200, doc, NULL);
}

/* Outputs: "result" (the HDF5 file) and "xdmf" (its XDMF 3 description for
 * ParaView, made on first request; it names the HDF5 file as the download's
 * file name "<id>.h5", so both saved side by side open together). */
enum MHD_Result route_result_file(pk_req *r)
{
    int want_xdmf = strcmp(r->seg[3], "xdmf") == 0, picture = -1;
    for (size_t i = 0; i < sizeof pictures / sizeof *pictures; i++)
        if (!strcmp(r->seg[3], pictures[i].file))
            picture = (int)i;
    if (strcmp(r->seg[3], "result") != 0 && !want_xdmf && picture < 0)
        return pk_send_problem(r, 404, PK_PROBLEM_PACKD "no-such-output", "No such output",
                               "outputs: result, xdmf, picture.png, picture.svg, grading.png, "
                               "grading.svg", NULL, 0);
    enum MHD_Result rc;
    json_t *row = successful_job(r, picture < 0, &rc);
    if (!row)
        return rc;
    pk_config cfg = pk_service_config(r->svc);
    char dir[1200], path[1300], name[200];
    pk_job_dir(cfg.data, r->seg[1], dir, sizeof dir);
    if (picture >= 0) {
        char hex[65];
        snprintf(path, sizeof path, "%s/%s", dir, pictures[picture].file);
        json_decref(row);
        if (access(path, R_OK) != 0 || pk_sha256_file_hex(path, hex) != 0) {
            char d[200];
            snprintf(d, sizeof d, "this job has no such picture (SVG packings are drawn up to %d "
                     "grains, grading curves for pack results)", PK_PICTURE_SVG_MAX_GRAINS);
            return pk_send_problem(r, 404, PK_PROBLEM_PACKD "no-such-output", "No such output", d,
                                   NULL, 0);
        }
        return pk_send_file(r, path, pictures[picture].type, hex, NULL); /* shown inline */
    }
    pk_job_file_path(dir, PK_JOB_RESULT, path, sizeof path);
    snprintf(name, sizeof name, "%s.h5", r->seg[1]);
    if (want_xdmf) {
        char xpath[1300], xname[200], err[512];
        pk_job_file_path(dir, PK_JOB_XDMF, xpath, sizeof xpath);
        snprintf(xname, sizeof xname, "%s.xdmf", r->seg[1]);
        if (access(xpath, R_OK) != 0 && pk_xdmf_write(path, name, xpath, err, sizeof err) != 0) {
            json_decref(row);
            return pk_send_problem(r, 500, PK_PROBLEM_GENERIC, "Internal Server Error", err, NULL, 0);
        }
        char hex[65];
        if (pk_sha256_file_hex(xpath, hex) != 0) {
            json_decref(row);
            return pk_send_problem(r, 500, PK_PROBLEM_GENERIC, "Internal Server Error",
                                   "cannot read the XDMF file", NULL, 0);
        }
        rc = pk_send_file(r, xpath, "application/xml", hex, xname);
        json_decref(row);
        return rc;
    }
    rc = pk_send_file(r, path, PK_RESULT_MEDIA_TYPE,
                      json_string_value(json_object_get(row, "result_sha256")), name);
    json_decref(row);
    return rc;
}
