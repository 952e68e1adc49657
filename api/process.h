/* process.h — the table of processes packd offers (OGC API – Processes ids).
 * One table serves `packd run`/`validate`, the daemon's /processes routes and
 * its workers: adding a process means adding one row here. */
#ifndef PK_PROCESS_H
#define PK_PROCESS_H

#include <jansson.h>
#include <stddef.h>

#include "api/inputs/check_ctx.h"
#include "api/results/h5_observables.h"
#include "api/run_ctx.h"
#include "api/schemas/json_schema.h"

typedef struct pk_process {
    const char *id; /* "pack" */
    const char *title;
    const char *description;
    const char *inputs_schema; /* file name in schemas/ */
    /* The picture kinds (api/picture/picture.h) its results may hold,
     * NULL-terminated: the pictures its description declares as outputs. */
    const char *const *pictures;
    /* Its observable list (api/results/h5_observables.h): the summary's
     * members, their datasets under /observables and their units. */
    const pk_obs_row *observables;
    /* Schema-valid inputs → the parsed job (the process's option table
     * filled, semantic checks beyond the schema: cross-field rules,
     * feasibility), released by free_job; NULL with errors appended (JSON
     * pointers relative to the inputs object).  Borrows from inputs. */
    void *(*parse)(json_t *inputs, const pk_check_ctx *ctx, pk_schema_errors *errs);
    void (*free_job)(void *job);
    /* What a parsed job implies, for `packd validate` to show before a run
     * (a new object, e.g. pack's expected grains); NULL: nothing to show. */
    json_t *(*plan)(const void *job);
    /* Run a parsed job in the run context run (run_ctx.h: threads, monitor,
     * checkpoint, author), write the result file, return a summary object
     * (new reference) in *summary carrying the verdict (job_verdict.h).  0
     * whenever a result file and a summary were written, failed verdict
     * included; -1 with err when there is no result file at all. */
    int (*run)(const void *job, const pk_run_ctx *run, const char *job_json, const char *out_path,
               json_t **summary, char *err, size_t errlen);
} pk_process;

/* NULL-terminated table. */
extern const pk_process *const pk_processes[];

const pk_process *pk_process_find(const char *id);

/* Validate inputs for a process: schema first, then (only if the schema
 * passed) the parse with its semantic checks, in the context ctx
 * (check_ctx.h).  Returns the number of errors appended; with parsed
 * non-NULL, *parsed is the parsed job on success (free with p->free_job),
 * else NULL. */
size_t pk_process_parse_inputs(const pk_process *p, json_t *inputs, const pk_check_ctx *ctx,
                               void **parsed, pk_schema_errors *errs);
size_t pk_process_validate_inputs(const pk_process *p, json_t *inputs, const pk_check_ctx *ctx,
                                  pk_schema_errors *errs);

/* A whole job file {"process", "inputs"}: envelope, then inputs.  On success
 * *proc is set (and with parsed non-NULL, *parsed as above).  Pointers in
 * errors are relative to the job file root. */
size_t pk_job_parse(json_t *job, const pk_check_ctx *ctx, const pk_process **proc, void **parsed,
                    pk_schema_errors *errs);

/* Validate, parse once and run a job (the one code path of `packd run` and
 * the daemon's workers) in the run context run (NULL: PK_RUN_CTX_DEFAULT;
 * threads < 1 count as 1).  Returns 0 when the
 * job is successful (complete or not); 2 when it failed but wrote its partial
 * result file and a summary whose "failure" says why (err holds the same
 * text); 1 on invalid input with errs filled; -1 on a runtime failure
 * without a result file, with err. */
int pk_job_run(json_t *job, const pk_run_ctx *run, const char *out_path, json_t **summary,
               pk_schema_errors *errs, char *err, size_t errlen);

#endif
