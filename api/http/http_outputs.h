/* http_outputs.h — the outputs of every process as OGC API – Processes sees
 * them: one table read by the process descriptions (declared outputs), the
 * results documents and routes, and the execute request's "outputs" and
 * "response" members. */
#ifndef PK_HTTP_OUTPUTS_H
#define PK_HTTP_OUTPUTS_H

#include <jansson.h>

typedef struct pk_output {
    const char *id;   /* key in the results document, last segment of /results/{id} */
    const char *type; /* media type */
    const char *title, *description;
    int optional; /* present only for some jobs (pictures) */
} pk_output;

/* Every output, terminated by {NULL}. */
extern const pk_output pk_outputs[];

/* The output called id, or NULL. */
const pk_output *pk_output_find(const char *id);

/* What an execute request asks of its results (OGC Part 1 "response" and
 * "outputs"): serve names the one output answered as raw bytes ("" for the
 * results document), select the outputs a document lists (NULL: all). */
typedef struct pk_exec_opts {
    char serve[32];
    json_t *select; /* array of output ids, or NULL */
} pk_exec_opts;

/* From an execute request body: 0, or -1 with detail (pointer and rule) for
 * a 400.  response "raw" serves "result" (or the one output selected);
 * response "document" with exactly one output whose transmissionMode is
 * "value" serves that output's bytes. */
int pk_exec_opts_parse(json_t *body, pk_exec_opts *o, char *detail, size_t n);
/* As stored beside the job (NULL when the defaults: a full document). */
json_t *pk_exec_opts_json(const pk_exec_opts *o);
void pk_exec_opts_from_json(json_t *j, pk_exec_opts *o);
void pk_exec_opts_free(pk_exec_opts *o);

#endif
