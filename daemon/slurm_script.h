/* slurm_script.h — the batch script of one packd job on Slurm
 * (DATA/jobs/<id>/slurm.sh).  Its #SBATCH lines: job name packd-<id>,
 * `ranks` tasks of `threads` CPUs each, the memory (--mem, per rank as
 * --mem-per-cpu when there are several), --time from the job's wall-time
 * limit, --requeue, SIGTERM 60 s before the time limit, partition, account,
 * QOS; output to slurm.out in the job directory.  The script
 *   - exits 96 at once when the job directory is not visible on the node
 *     (the daemon then names the node),
 *   - starts progress.jsonl with {"attempt": SLURM_RESTART_COUNT + 1, "node"},
 *     and marks the attempt's start in worker.log ("packd: attempt <k> on <node>"),
 *   - runs `srun packd run job.json -o result.h5 --progress-file progress.jsonl
 *     --checkpoint checkpoint.h5 ...` (cancel and signals reach the worker),
 *     as `ranks` MPI ranks (srun --mpi=<slurm_mpi>) when there are several,
 *   - writes exit_status "<status> <attempt> <node>" by rename at the end. */
#ifndef PK_SLURM_SCRIPT_H
#define PK_SLURM_SCRIPT_H

#include <jansson.h>
#include <stddef.h>

#include "config.h"

/* worker.log: "packd: attempt <k> on <node>" where an attempt begins */
#define PK_SLURM_ATTEMPT_MARK "packd: attempt"

enum { PK_SLURM_NO_DIR = 96 }; /* exit status: job directory not visible on the node */

typedef struct pk_slurm_job {
    const char *id, *dir, *author; /* author: pk_worker_author, "" unknown */
    const char *packd;             /* packd on the nodes */
    int threads;                   /* CPUs of each task */
    int ranks;                     /* tasks: an fe2 job's inputs.parallel.mpi_ranks, else 1 */
    double wall_s; /* the job's wall-time limit (its limits, capped by the operator's) */
    double checkpoint_interval_s;
} pk_slurm_job;

enum { PK_SLURM_MAX_RANKS = 64 }; /* fe2's schema: inputs.parallel.mpi_ranks <= 64 */

/* What a queued job {process, inputs} asks of Slurm: its wall time
 * (inputs.limits.wall_time_s, capped by cap, cap without one) and its tasks
 * (an fe2 job's inputs.parallel.mpi_ranks, 1 for every other job). */
double pk_slurm_job_wall(json_t *job, double cap);
int pk_slurm_job_ranks(json_t *job);

/* The --time of a job in whole minutes: its wall time, the minute the
 * worker gets after SIGTERM to save, rounded up. */
long pk_slurm_minutes(double wall_s);

/* Write the script; 0, or -1 with why. */
int pk_slurm_script_write(const pk_slurm_job *j, const pk_config *c, char *path, size_t pathlen,
                          char *why, size_t n);

/* The first task srun reports as ended badly in the last attempt of log
 * (the script's worker.log, where srun's stderr goes: "srun: error: <node>:
 * task <k>: <how>"): its rank k, with "<node>: task <k>: <how>" in what; -1
 * if none. */
int pk_slurm_first_bad_task(const char *log, char *what, size_t n);

#endif
