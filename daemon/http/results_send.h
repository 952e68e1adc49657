/* results_send.h — the answer to a finished job's results, shared by
 * GET /jobs/{id}/results and a synchronous execute (Prefer: respond-sync). */
#ifndef PK_RESULTS_SEND_H
#define PK_RESULTS_SEND_H

#include "http.h"
#include "api/http/http_outputs.h"

/* The execute options stored beside job id (defaults when none were given). */
void pk_results_opts_load(pk_req *r, const char *id, pk_exec_opts *o);
/* The same from the data directory data. */
void pk_results_opts_read(const char *data, const char *id, pk_exec_opts *o);
/* Store them (only when not the defaults); 0 or -1. */
int pk_results_opts_save(pk_req *r, const char *id, const pk_exec_opts *o);

/* A job row that is final: successful → the results document (its outputs
 * as o selects) or the one output o serves as bytes; failed → 422
 * job-failed; otherwise 404 result-not-ready. */
enum MHD_Result pk_send_results(pk_req *r, json_t *row, const pk_exec_opts *o);

/* The results document of a successful job row (links relative to the
 * service): summary, result, xdmf and the pictures in its directory under
 * data, as o selects. */
json_t *pk_results_document_of(const char *data, json_t *row, const pk_exec_opts *o);

#endif
