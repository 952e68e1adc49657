/* process.h — the table of processes packd offers (OGC API – Processes ids).
 * One table serves `packd run`/`validate`, the daemon's /processes routes and
 * its workers: adding a process means adding one row here. */
#ifndef PK_PROCESS_H
#define PK_PROCESS_H

#include <jansson.h>
#include <stddef.h>

#include "api/inputs/check_ctx.h"
#include "api/schemas/json_schema.h"
#include "core/base/progress.h"

typedef struct pk_process {
    const char *id;             /* "pack" */
    const char *title;
    const char *description;
    const char *inputs_schema;  /* file name in schemas/ */
    /* Semantic checks beyond the schema (cross-field rules, feasibility).
     * Appends errors with JSON pointers relative to the inputs object. */
    void (*check)(json_t *inputs, const pk_check_ctx *ctx, pk_schema_errors *errs);
    /* Run validated inputs, write the result file, return a summary object
     * (new reference) in *summary carrying the verdict (job_verdict.h).
     * 0 whenever a result file and a summary were written, failed verdict
     * included; -1 with err when there is no result file at all. */
    int (*run)(json_t *inputs, const char *job_json, const char *out_path, pk_monitor *mon,
               json_t **summary, char *err, size_t errlen);
} pk_process;

/* NULL-terminated table. */
extern const pk_process *const pk_processes[];

const pk_process *pk_process_find(const char *id);

/* Validate inputs for a process: schema first, then (only if the schema
 * passed) the semantic checks, in the context ctx (check_ctx.h).  Returns
 * the number of errors appended. */
size_t pk_process_validate_inputs(const pk_process *p, json_t *inputs, const pk_check_ctx *ctx,
                                  pk_schema_errors *errs);

/* A whole job file {"process", "inputs"}: envelope, then inputs.  On success
 * *proc is set.  Pointers in errors are relative to the job file root. */
size_t pk_job_validate(json_t *job, const pk_check_ctx *ctx, const pk_process **proc,
                       pk_schema_errors *errs);

/* Threads of a job's parallel sections (core/base/par.h), for the jobs run by
 * this process from now on (default 1).  The results are the same bits
 * for any number: a deployment setting, not a job input. */
void pk_job_set_threads(int n);
int pk_job_threads(void);

/* Checkpoints of long runs (EDMD): the file, the job's digest stored in it
 * (a checkpoint of another job is never resumed) and the wall seconds
 * between two saves; path NULL = none (default).  A run resumes from the
 * file when it exists and its digest matches. */
void pk_job_set_checkpoint(const char *path, const char *digest, double interval_s);
const char *pk_job_checkpoint(const char **digest, double *interval_s);

/* Validate and run a job (the one code path of `packd run` and the daemon's
 * workers).  Returns 0 when the job is successful (complete or not); 2 when
 * it failed but wrote its partial result file and a summary whose "failure"
 * says why (err holds the same text); 1 on invalid input with errs filled;
 * -1 on a runtime failure without a result file, with err. */
int pk_job_run(json_t *job, const char *out_path, pk_monitor *mon, json_t **summary,
               pk_schema_errors *errs, char *err, size_t errlen);

#endif
