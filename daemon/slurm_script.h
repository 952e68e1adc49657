/* slurm_script.h — the batch script of one packd job on Slurm
 * (DATA/jobs/<id>/slurm.sh).  Its #SBATCH lines: job name packd-<id>,
 * one task with `threads` CPUs, --mem, --time from the job's wall-time
 * limit, --requeue, SIGTERM 60 s before the time limit, partition, account,
 * QOS; output to slurm.out in the job directory.  The script
 *   - exits 96 at once when the job directory is not visible on the node
 *     (the daemon then names the node),
 *   - starts progress.jsonl with {"attempt": SLURM_RESTART_COUNT + 1, "node"},
 *   - runs `srun packd run job.json -o result.h5 --progress-file progress.jsonl
 *     --checkpoint checkpoint.h5 ...` (cancel and signals reach the worker),
 *   - writes exit_status "<status> <attempt> <node>" by rename at the end. */
#ifndef PK_SLURM_SCRIPT_H
#define PK_SLURM_SCRIPT_H

#include <stddef.h>

#include "config.h"

enum { PK_SLURM_NO_DIR = 96 }; /* exit status: job directory not visible on the node */

typedef struct pk_slurm_job {
    const char *id, *dir, *author; /* author: pk_worker_author, "" unknown */
    const char *packd;             /* packd on the nodes */
    int threads;
    double wall_s; /* the job's wall-time limit (its limits, capped by the operator's) */
    double checkpoint_interval_s;
} pk_slurm_job;

/* The --time of a job in whole minutes: its wall time, the minute the
 * worker gets after SIGTERM to save, rounded up. */
long pk_slurm_minutes(double wall_s);

/* Write the script; 0, or -1 with why. */
int pk_slurm_script_write(const pk_slurm_job *j, const pk_config *c, char *path, size_t pathlen,
                          char *why, size_t n);

#endif
