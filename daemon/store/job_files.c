/* job_files.c — names and paths of a job directory's files; contract in job_files.h. */
#include "job_files.h"

#include <dirent.h>
#include <stdio.h>
#include <unistd.h>

const char *pk_job_file_name(pk_job_file f)
{
    switch (f) {
    case PK_JOB_INPUT: return "job.json";
    case PK_JOB_RESULT: return "result.h5";
    case PK_JOB_XDMF: return "result.xdmf";
    case PK_JOB_SUMMARY: return "summary.json";
    case PK_JOB_LOG: return "worker.log";
    case PK_JOB_LOCK: return "worker.lock";
    case PK_JOB_CHECKPOINT: return "checkpoint.h5";
    case PK_JOB_EXEC_OPTS: return "execute.json";
    case PK_JOB_SLURM_SCRIPT: return "slurm.sh";
    case PK_JOB_SLURM_OUT: return "slurm.out";
    case PK_JOB_PROGRESS: return "progress.jsonl";
    case PK_JOB_EXIT: return "exit_status";
    }
    return "";
}

static int fits(int k, size_t n) { return k >= 0 && (size_t)k < n ? 0 : -1; }

int pk_job_dir(const char *data, const char *id, char *out, size_t n)
{
    return fits(snprintf(out, n, "%s/jobs/%s", data, id), n);
}

int pk_job_file_path(const char *dir, pk_job_file f, char *out, size_t n)
{
    return fits(snprintf(out, n, "%s/%s", dir, pk_job_file_name(f)), n);
}

void pk_job_dir_remove(const char *data, const char *id)
{
    char dir[1200];
    if (pk_job_dir(data, id, dir, sizeof dir) != 0)
        return;
    DIR *d = opendir(dir);
    if (!d)
        return;
    struct dirent *e;
    while ((e = readdir(d))) {
        char p[1500];
        if (e->d_name[0] != '.' && snprintf(p, sizeof p, "%s/%s", dir, e->d_name) < (int)sizeof p)
            unlink(p);
    }
    closedir(d);
    rmdir(dir);
}
