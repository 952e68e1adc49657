/* run_ctx.h — what a job's run is given besides its inputs: the deployment's
 * settings (threads, checkpointing, author) and the caller's monitor.  One
 * struct handed down by pk_job_run to process.run and placer.place, so no
 * code below reads a process-wide setting; a caller that runs a job inside
 * another (fe2's nested pack) passes a copy with its own monitor. */
#ifndef PK_RUN_CTX_H
#define PK_RUN_CTX_H

#include "core/base/progress.h"

/* Checkpoints of long runs (EDMD, homogenize): the file, the job's digest
 * stored in it (a checkpoint of another job is never resumed) and the wall
 * seconds between two saves.  path NULL = none.  A run resumes from the file
 * when it exists and its digest matches. */
typedef struct pk_run_checkpoint {
    const char *path;
    const char *digest;
    double interval_s;
} pk_run_checkpoint;

typedef struct pk_run_ctx {
    /* the parallel sections' threads (core/base/par.h), ≥ 1: the results are
     * the same bits for any number */
    int threads;
    pk_monitor *mon; /* progress, cancel and wall time; NULL = none */
    pk_run_checkpoint checkpoint;
    const char *author; /* the result's /h5md/author name; NULL or "" = unknown */
} pk_run_ctx;

/* What a run gets when its caller states nothing: 1 thread, no monitor, no
 * checkpoint, author unknown. */
#define PK_RUN_CTX_DEFAULT                                                                         \
    ((pk_run_ctx){.threads = 1, .checkpoint = {.interval_s = 30}, .author = NULL})

#endif
