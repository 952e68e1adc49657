/* test_slurm_script.c — daemon/slurm_script.c: what a job asks of Slurm
 * (tasks from an fe2 job's mpi_ranks, time from its wall limit) and the
 * lines of the batch script for one task and for MPI ranks: --ntasks,
 * --cpus-per-task, memory per node or per rank, --time, srun's --mpi; the
 * lost rank read back from srun's report. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "check.h"
#include "daemon/config.h"
#include "daemon/slurm_script.h"

static char dir[] = "/tmp/pk_slurm_script_XXXXXX";

/* The script of job j under config c, read whole (free it); NULL on failure. */
static char *script_of(const pk_slurm_job *j, const pk_config *c)
{
    char path[256], why[256];
    if (pk_slurm_script_write(j, c, path, sizeof path, why, sizeof why) != 0) {
        fprintf(stderr, "  pk_slurm_script_write: %s\n", why);
        return NULL;
    }
    FILE *f = fopen(path, "r");
    char *text = calloc(1, 16384);
    if (f && text)
        text[fread(text, 1, 16383, f)] = 0;
    if (f)
        fclose(f);
    return text;
}

/* line is one whole line of text */
static int has_line(const char *text, const char *line)
{
    size_t n = strlen(line);
    for (const char *p = text; (p = strstr(p, line)); p += n)
        if ((p == text || p[-1] == '\n') && (p[n] == '\n' || !p[n]))
            return 1;
    return 0;
}

/* the line starting with prefix, or NULL */
static const char *line_of(const char *text, const char *prefix)
{
    size_t n = strlen(prefix);
    for (const char *p = text; p && *p; p = strchr(p, '\n') ? strchr(p, '\n') + 1 : NULL)
        if (!strncmp(p, prefix, n))
            return p;
    return NULL;
}

static json_t *job_of(const char *text)
{
    json_t *j = json_loads(text, 0, NULL);
    CHECK(j != NULL);
    return j;
}

static void test_job_asks(void)
{
    json_t *fe2 = job_of("{\"process\": \"fe2\", \"inputs\": {\"parallel\": {\"mpi_ranks\": 3},"
                         " \"limits\": {\"wall_time_s\": 90}}}");
    json_t *fe2_default = job_of("{\"process\": \"fe2\", \"inputs\": {}}");
    /* only fe2 spreads over ranks: another process's field would start copies */
    json_t *pack =
        job_of("{\"process\": \"pack\", \"inputs\": {\"parallel\": {\"mpi_ranks\": 3}}}");
    CHECK(pk_slurm_job_ranks(fe2) == 3);
    CHECK(pk_slurm_job_ranks(fe2_default) == 1);
    CHECK(pk_slurm_job_ranks(pack) == 1);
    CHECK(pk_slurm_job_wall(fe2, 86400) == 90);
    CHECK(pk_slurm_job_wall(fe2, 60) == 60);               /* the operator's cap */
    CHECK(pk_slurm_job_wall(fe2_default, 86400) == 86400); /* none: the cap */
    CHECK(pk_slurm_minutes(90) == 3);                      /* 90 s + the 60 s TERM margin */
    json_decref(fe2);
    json_decref(fe2_default);
    json_decref(pack);
}

/* A job of `ranks` tasks of 2 threads each under /opt/packd, its wall limit
 * wall_s, and the defaults' config with slurm_mem_mb mem. */
static pk_slurm_job job_with(const char *id, int ranks, double wall_s, pk_config *c, int mem)
{
    pk_config_defaults(c);
    c->slurm_mem_mb = mem;
    return (pk_slurm_job){.id = id,
                          .dir = dir,
                          .author = "lab",
                          .packd = "/opt/packd",
                          .threads = 2,
                          .ranks = ranks,
                          .wall_s = wall_s,
                          .checkpoint_interval_s = 30};
}

static void test_one_task(void)
{
    pk_config c;
    pk_slurm_job j = job_with("one", 1, 90, &c, 1000);
    char *s = script_of(&j, &c);
    CHECK(s != NULL);
    if (!s)
        return;
    CHECK(has_line(s, "#SBATCH --ntasks=1") && has_line(s, "#SBATCH --cpus-per-task=2"));
    CHECK(has_line(s, "#SBATCH --time=3") && has_line(s, "#SBATCH --mem=1000"));
    CHECK(!strstr(s, "--mem-per-cpu") && !strstr(s, "--mpi"));
    CHECK(has_line(s, "echo \"" PK_SLURM_ATTEMPT_MARK " $attempt on $node\" >> worker.log"));
    const char *srun = line_of(s, "srun ");
    CHECK(srun &&
          !strncmp(srun,
                   "srun --ntasks=1 --cpus-per-task=2 --kill-on-bad-exit=1 "
                   "'/opt/packd' run job.json",
                   strlen("srun --ntasks=1 --cpus-per-task=2 --kill-on-bad-exit=1 "
                          "'/opt/packd' run job.json")));
    free(s);
}

static void test_ranks(void)
{
    pk_config c;
    pk_slurm_job j = job_with("ranks", 3, 600, &c, 1001);
    char *s = script_of(&j, &c);
    CHECK(s != NULL);
    if (!s)
        return;
    CHECK(has_line(s, "#SBATCH --ntasks=3") && has_line(s, "#SBATCH --cpus-per-task=2"));
    /* 1001 MB per rank over its 2 CPUs, rounded up; --mem would be per node */
    CHECK(has_line(s, "#SBATCH --mem-per-cpu=501") && !line_of(s, "#SBATCH --mem="));
    CHECK(has_line(s, "#SBATCH --time=11"));
    const char *srun = line_of(s, "srun ");
    CHECK(srun &&
          !strncmp(srun,
                   "srun --ntasks=3 --cpus-per-task=2 --mpi='pmix' "
                   "--kill-on-bad-exit=1 '/opt/packd' run job.json",
                   strlen("srun --ntasks=3 --cpus-per-task=2 --mpi='pmix' "
                          "--kill-on-bad-exit=1 '/opt/packd' run job.json")));
    CHECK(srun && strstr(srun, " --threads 2 "));
    free(s);
    /* the operator's plugin, quoted for sh */
    snprintf(c.slurm_mpi, sizeof c.slurm_mpi, "pmix_v4");
    s = script_of(&j, &c);
    CHECK(s && strstr(s, "srun --ntasks=3 --cpus-per-task=2 --mpi='pmix_v4' "));
    free(s);
}

/* srun's stderr (worker.log) when rank 1 of 2 was killed -9 and Slurm's PMIx
 * plugin ended the step, as measured on the one-node test cluster */
static void test_lost_rank_named(void)
{
    char log[128], what[256];
    snprintf(log, sizeof log, "%s/worker.log", dir);
    FILE *f = fopen(log, "w");
    CHECK(f != NULL);
    if (!f)
        return;
    fputs("[vm:17064] Read -1, expected 6624, errno = 3\n"
          "srun: error: vm: task 1: Killed\n"
          "srun: launch/slurm: _step_signal: Terminating StepId=5.0\n"
          "slurmstepd-vm: error: *** STEP 5.0 ON vm CANCELLED AT 2026-12-07T15:56:11 ***\n"
          "srun: Job step aborted: Waiting up to 4 seconds for job step to finish.\n"
          "srun: error: vm: task 0: Killed\n",
          f);
    fclose(f);
    CHECK(pk_slurm_first_bad_task(log, what, sizeof what) == 1);
    CHECK(!strcmp(what, "vm: task 1: Killed"));
    /* an earlier attempt's report (preempted: srun's tasks terminated) is not this one's */
    f = fopen(log, "w");
    if (f) {
        fputs("packd: attempt 1 on vm\nsrun: error: vm: task 0: Terminated\n"
              "packd: attempt 2 on vm\nsrun: error: vm: task 1: Killed\n"
              "srun: error: vm: task 0: Killed\n",
              f);
        fclose(f);
    }
    CHECK(pk_slurm_first_bad_task(log, what, sizeof what) == 1);
    f = fopen(log, "a");
    if (f) {
        fputs("packd: attempt 3 on vm\npackd run: failed: cannot read job.json\n", f);
        fclose(f);
    }
    CHECK(pk_slurm_first_bad_task(log, what, sizeof what) == -1);
    /* several tasks in one report name no single lost rank; no log: none */
    f = fopen(log, "w");
    if (f) {
        fputs("packd run: failed: cannot open job.json\nsrun: error: vm: tasks 0-1: Killed\n", f);
        fclose(f);
    }
    CHECK(pk_slurm_first_bad_task(log, what, sizeof what) == -1);
    unlink(log);
    CHECK(pk_slurm_first_bad_task(log, what, sizeof what) == -1);
}

int main(void)
{
    if (!mkdtemp(dir))
        return 1;
    RUN(test_job_asks);
    RUN(test_one_task);
    RUN(test_ranks);
    RUN(test_lost_rank_named);
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    if (system(cmd) != 0)
        fprintf(stderr, "could not remove %s\n", dir);
    return check_summary();
}
