/* bench/jobs/bench_job.h — run a job file of bench/jobs/ through `packd run`'s
 * code path (pk_job_run) in a child process of its own, for bench/rsa and
 * bench/edmd.  A child per run maps fresh memory and pays its first touches
 * as a job's worker does, and its peak resident memory (ru_maxrss) is the
 * job's own.  Header-only: each bench/NAME.c is one program. */
#ifndef PK_BENCH_JOB_H
#define PK_BENCH_JOB_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "api/process.h"

typedef struct bench_job {
    json_t *sum;    /* the job's summary (new reference), NULL on failure */
    double cpu_s;   /* CPU time of the run (sizes, placement, audit, file) */
    long maxrss_kb; /* the child's peak resident memory */
    char err[256];
} bench_job;

/* $PACKD_SRC/bench/jobs/NAME.json (or ./bench/jobs/…). */
static inline void bench_job_path(const char *name, char *path, size_t size)
{
    const char *src = getenv("PACKD_SRC");
    snprintf(path, size, "%s/bench/jobs/%s.json", src && *src ? src : ".", name);
}

static inline double bench_cpu_now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* Run job file NAME with `patch` (a JSON object or NULL) merged into its
 * "inputs" recursively.  0, or -1 with r->err set. */
static inline int bench_job_run(const char *name, const char *patch, bench_job *r)
{
    memset(r, 0, sizeof *r);
    char path[1024];
    bench_job_path(name, path, sizeof path);
    int fd[2];
    fflush(stdout);
    if (pipe(fd) != 0) {
        snprintf(r->err, sizeof r->err, "pipe failed");
        return -1;
    }
    pid_t pid = fork();
    if (pid == 0) {
        close(fd[0]);
        FILE *f = fdopen(fd[1], "w");
        json_error_t e;
        json_t *job = json_load_file(path, 0, &e);
        json_t *p = patch ? json_loads(patch, 0, &e) : NULL;
        if (!f || !job || (patch && !p)) {
            if (f)
                fprintf(f, "error %s: %s\n", path, e.text);
            _exit(1);
        }
        if (p)
            json_object_update_recursive(json_object_get(job, "inputs"), p);
        char out[64], err[512];
        snprintf(out, sizeof out, "/tmp/packd-bench-%d.h5", (int)getpid());
        pk_schema_errors errs = {0};
        json_t *sum = NULL;
        double c0 = bench_cpu_now();
        int rc = pk_job_run(job, NULL, out, &sum, &errs, err, sizeof err);
        double cpu = bench_cpu_now() - c0;
        remove(out);
        struct rusage ru;
        getrusage(RUSAGE_SELF, &ru);
        if (rc == 0 && sum) {
            char *txt = json_dumps(sum, JSON_COMPACT);
            fprintf(f, "ok %.6f %ld %s\n", cpu, (long)ru.ru_maxrss, txt ? txt : "{}");
            free(txt);
        } else {
            if (errs.n)
                fprintf(f, "error invalid job: %s %s\n", errs.items[0].pointer,
                        errs.items[0].message);
            else
                fprintf(f, "error %s\n", err);
        }
        fclose(f);
        _exit(0);
    }
    close(fd[1]);
    if (pid < 0) {
        close(fd[0]);
        snprintf(r->err, sizeof r->err, "fork failed");
        return -1;
    }
    FILE *f = fdopen(fd[0], "r");
    char *line = NULL;
    size_t cap = 0;
    int rc = -1;
    if (f && getline(&line, &cap, f) > 0) {
        line[strcspn(line, "\n")] = 0;
        int off = 0;
        if (sscanf(line, "ok %lf %ld %n", &r->cpu_s, &r->maxrss_kb, &off) == 2 && off > 0) {
            json_error_t e;
            r->sum = json_loads(line + off, 0, &e);
            rc = r->sum ? 0 : -1;
        } else {
            snprintf(r->err, sizeof r->err, "%s", strncmp(line, "error ", 6) ? line : line + 6);
        }
    } else {
        snprintf(r->err, sizeof r->err, "the child wrote nothing");
    }
    free(line);
    if (f)
        fclose(f);
    else
        close(fd[0]);
    int status;
    waitpid(pid, &status, 0);
    return rc;
}

static inline double bench_num(json_t *o, const char *key)
{
    return json_number_value(json_object_get(o, key));
}

#endif
