/* http_outputs.h — the outputs of every process as OGC API – Processes sees
 * them: one table read by the process descriptions (declared outputs), the
 * results documents and routes, and the execute request's "outputs" and
 * "response" members. */
#ifndef PK_HTTP_OUTPUTS_H
#define PK_HTTP_OUTPUTS_H

#include <jansson.h>

#include "api/process.h"

typedef struct pk_output {
    const char *id;   /* key in the results document, last segment of /results/{id} */
    const char *type; /* media type */
    const char *title, *description;
    int optional;        /* present only for some jobs (pictures) */
    const char *picture; /* the picture kind (picture.h) it shows, or NULL */
} pk_output;

/* The i-th output (i from 0; NULL past the last): summary, result, xdmf,
 * then <file>.png and <file>.svg of every picture kind (picture.h). */
const pk_output *pk_output_at(size_t i);

/* The output called id, or NULL. */
const pk_output *pk_output_find(const char *id);

/* 1 when process p declares output o: the fixed ones always, a picture when
 * p lists its kind (pk_process.pictures). */
int pk_output_offered(const pk_process *p, const pk_output *o);

/* Every output id, comma-separated, into buf; returns the length. */
size_t pk_outputs_list(char *buf, size_t n);

/* What an execute request asks of its results (OGC Part 1 "response" and
 * "outputs"): serve names the one output answered as raw bytes ("" for the
 * results document), select the outputs a document lists (NULL: all). */
typedef struct pk_exec_opts {
    char serve[32];
    json_t *select;     /* array of output ids, or NULL */
    json_t *subscriber; /* {successUri, inProgressUri, failedUri} (OGC callbacks), or NULL */
    char base[256];     /* the service's URL as the client named it (links in callbacks) */
} pk_exec_opts;

/* From an execute request body: 0, or -1 with detail (pointer and rule) for
 * a 400.  response "raw" serves "result" (or the one output selected);
 * response "document" with exactly one output whose transmissionMode is
 * "value" serves that output's bytes.  subscriber: each URI given is an
 * absolute http or https URL. */
int pk_exec_opts_parse(json_t *body, pk_exec_opts *o, char *detail, size_t n);
/* As stored beside the job (NULL when the defaults: a full document). */
json_t *pk_exec_opts_json(const pk_exec_opts *o);
void pk_exec_opts_from_json(json_t *j, pk_exec_opts *o);
void pk_exec_opts_free(pk_exec_opts *o);

#endif
