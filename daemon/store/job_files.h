/* job_files.h — the files of a job's directory DATA/jobs/<id>, named in one
 * place: the executor writes them, the routes serve them, links resolve
 * to them, a dismissal deletes them.  (The pictures a worker draws there
 * are named by api/picture/picture.h.) */
#ifndef PK_JOB_FILES_H
#define PK_JOB_FILES_H

#include <stddef.h>

typedef enum pk_job_file {
    PK_JOB_INPUT,      /* job.json: {process, inputs} as the worker reads it */
    PK_JOB_RESULT,     /* result.h5: the result (or a failed job's partial result) */
    PK_JOB_XDMF,       /* result.xdmf: its XDMF description, written on first request */
    PK_JOB_SUMMARY,    /* summary.json: the worker's stdout, its summary document */
    PK_JOB_LOG,        /* worker.log: the worker's stderr */
    PK_JOB_LOCK,       /* worker.lock: flock'd by the worker while it lives */
    PK_JOB_CHECKPOINT, /* checkpoint.h5: kept across attempts, a re-queued job resumes from it */
    PK_JOB_EXEC_OPTS, /* execute.json: the request's response/outputs, only when not the defaults */
    PK_JOB_SLURM_SCRIPT, /* slurm.sh: the batch script submitted to Slurm */
    PK_JOB_SLURM_OUT,    /* slurm.out: the batch script's own output */
    PK_JOB_PROGRESS, /* progress.jsonl: a Slurm job's progress lines (packd run --progress-file) */
    PK_JOB_EXIT, /* exit_status: "<status> <attempt> <node>" the batch script writes at its end */
} pk_job_file;

/* The file's name inside the job directory, e.g. "result.h5". */
const char *pk_job_file_name(pk_job_file f);

/* The directory of a job's files: DATA/jobs/<id>.  0, or -1 if it does not
 * fit in n bytes. */
int pk_job_dir(const char *data, const char *id, char *out, size_t n);

/* dir/<name of f>.  0, or -1 if it does not fit in n bytes. */
int pk_job_file_path(const char *dir, pk_job_file f, char *out, size_t n);

/* Remove DATA/jobs/<id> and the files in it (a dismissed job's). */
void pk_job_dir_remove(const char *data, const char *id);

#endif
