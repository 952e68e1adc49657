/* http_process_doc.h — OGC process summaries and descriptions, read from the
 * process table (process.h) and the inputs schemas in schemas/: a new process
 * row appears in /processes with no change here. */
#ifndef PK_HTTP_PROCESS_DOC_H
#define PK_HTTP_PROCESS_DOC_H

#include <jansson.h>

#include "api/process.h"

/* {"id","title","description","version","jobControlOptions","outputTransmission","links"} */
json_t *pk_process_summary(const pk_process *p);

/* The summary plus "inputs" (one entry per top-level property of the inputs
 * schema, each with its JSON Schema), "outputs" and "inputsSchema" (the whole
 * schema file as compiled in). */
json_t *pk_process_description(const pk_process *p);

/* Server-side caps on a job's inputs, applied only where the process's own
 * schema has the field (properties.limits.properties.<name>): the value
 * becomes min(given, cap), or cap when absent. */
void pk_process_apply_caps(const pk_process *p, json_t *inputs, long max_particles,
                           double max_wall_time_s);

#endif
