/* executor_slurm.c — the Slurm back end: each job is one sbatch job named
 * packd-<id> (its script: slurm_script.h) on a filesystem the nodes share.
 *
 * One thread runs a poll cycle every POLL_S (sooner when woken):
 *   1. claim accepted jobs (up to slurm_max_jobs held), write their job
 *      directory and script;
 *   2. ONE `squeue` for every packd-* job: a claimed job Slurm already has
 *      (a daemon died between sbatch and recording it) is adopted by name,
 *      the others are submitted with sbatch;
 *   3. each held job's Slurm state -> its status and message, progress from
 *      the last line of progress.jsonl, the end from exit_status, summary
 *      and result digest (scontrol, then sacct, when there is no exit_status);
 *      dismissed jobs get scancel;
 *   4. ONE queue transaction (pk_queue_sync) for all of it.
 * The queue's executor_ref ('slurm:<job id>') marks the jobs Slurm holds:
 * they are never claimed again, and a restarted daemon finds them there.
 * An unreachable controller leaves every job as it is (claimed ones go back
 * to accepted) and the back end degraded until a command answers again.
 * Jobs with limits.wall_time_s <= slurm_local_below_s run on a local back
 * end beside this one. */
#include "executor.h"

#include <fcntl.h>
#include <math.h>
#include <pthread.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "log.h"
#include "slurm_cmd.h"
#include "slurm_script.h"
#include "worker_files.h"
#include "daemon/store/job_files.h"

#define POLL_S 1.0         /* one squeue a second: a progress or state change shows within it */
#define CMD_TIMEOUT_S 20.0 /* a client command that hangs this long counts as unreachable */
#define MAX_SUBMIT 64      /* sbatch calls per cycle: a cycle stays under a few seconds */
#define SQUEUE_BYTES (4 << 20)

typedef struct slurm_exec {
    pk_executor base;
    pk_queue *q;
    pk_executor *local; /* short jobs (slurm_local_below_s) */
    char exe[1024];
    pthread_t thread;
    pthread_mutex_t mu; /* cfg, degraded, why, held_running, cycles, cycle_s */
    pk_config cfg;
    int stopping, degraded, held_running, held;
    long long cycles;
    double cycle_s;
    char why[300];
    int wake[2];
    char *squeue_out;
} slurm_exec;

/* One line of squeue: "packd-<id>|<job id>|<state>|<reason>|<nodes>". */
typedef struct sq_entry {
    char id[37], jid[24], state[32], reason[64], nodes[128];
} sq_entry;

typedef struct sq_list {
    sq_entry *v;
    size_t n;
} sq_list;

/* dst = src cut to n - 1 bytes */
static void copy(char *dst, size_t n, const char *src)
{
    size_t l = strlen(src);
    l = l < n ? l : n - 1;
    memcpy(dst, src, l);
    dst[l] = 0;
}

static void set_health(slurm_exec *s, int ok, const char *why)
{
    pthread_mutex_lock(&s->mu);
    if (ok && s->degraded)
        pk_log(PK_LOG_INFO, "slurm controller answers again", NULL);
    else if (!ok && !s->degraded)
        pk_log(PK_LOG_WARN, "slurm executor degraded", "{s:s}", "reason", why);
    s->degraded = !ok;
    copy(s->why, sizeof s->why, ok ? "" : why);
    pthread_mutex_unlock(&s->mu);
}

static void first_line(const char *text, char *out, size_t n)
{
    copy(out, n, text);
    out[strcspn(out, "\n")] = 0;
}

/* ONE squeue for all packd jobs; 0, or -1 (unreachable: health set). */
static int list_jobs(slurm_exec *s, sq_list *l)
{
    const char *argv[] = {"squeue", "-h", "-t", "all", "-o", "%j|%i|%T|%r|%N", NULL};
    int rc = pk_slurm_cmd(argv, s->squeue_out, SQUEUE_BYTES, CMD_TIMEOUT_S);
    if (rc != 0) {
        char why[300], line[200];
        first_line(s->squeue_out, line, sizeof line);
        snprintf(why, sizeof why, "squeue failed (%s): %s",
                 rc < 0 ? "no answer" : "the controller is unreachable", line);
        set_health(s, 0, why);
        return -1;
    }
    set_health(s, 1, NULL);
    l->n = 0;
    size_t cap = 0;
    for (char *line = strtok(s->squeue_out, "\n"); line; line = strtok(NULL, "\n")) {
        if (strncmp(line, "packd-", 6) != 0)
            continue;
        sq_entry e;
        memset(&e, 0, sizeof e);
        char *f[5] = {0};
        int k = 0;
        for (char *p = line; k < 5 && p; k++) {
            f[k] = p;
            p = strchr(p, '|');
            if (p)
                *p++ = 0;
        }
        if (k < 5 || strlen(f[0] + 6) != 36)
            continue;
        snprintf(e.id, sizeof e.id, "%s", f[0] + 6);
        snprintf(e.jid, sizeof e.jid, "%s", f[1]);
        snprintf(e.state, sizeof e.state, "%s", f[2]);
        snprintf(e.reason, sizeof e.reason, "%s", f[3]);
        snprintf(e.nodes, sizeof e.nodes, "%s", f[4]);
        if (l->n == cap) {
            cap = cap ? 2 * cap : 64;
            sq_entry *v = realloc(l->v, cap * sizeof *v);
            if (!v)
                return -1;
            l->v = v;
        }
        l->v[l->n++] = e;
    }
    return 0;
}

/* The newest Slurm job of a packd job (a requeued job keeps its id). */
static const sq_entry *find(const sq_list *l, const char *id)
{
    const sq_entry *best = NULL;
    for (size_t i = 0; i < l->n; i++)
        if (!strcmp(l->v[i].id, id) && (!best || atol(l->v[i].jid) > atol(best->jid)))
            best = &l->v[i];
    return best;
}

static int state_is(const char *state, const char *const *set)
{
    for (int i = 0; set[i]; i++)
        if (!strcmp(state, set[i]))
            return 1;
    return 0;
}

static const char *const queued_states[] = {
    "PENDING",       "REQUEUED",     "REQUEUE_HOLD", "REQUEUE_FED",
    "RESV_DEL_HOLD", "SPECIAL_EXIT", "CONFIGURING",  NULL};
static const char *const ended_states[] = {"COMPLETED", "FAILED",    "TIMEOUT",   "OUT_OF_MEMORY",
                                           "NODE_FAIL", "CANCELLED", "BOOT_FAIL", "DEADLINE",
                                           "PREEMPTED", "REVOKED",   NULL};

static json_t *change(const char *id, const char *op)
{
    return json_pack("{s:s,s:s}", "id", id, "op", op);
}

/* sbatch one claimed job: its change (held, requeued or failed). */
static json_t *submit(slurm_exec *s, json_t *job, const pk_config *c)
{
    const char *id = json_string_value(json_object_get(job, "id"));
    char dir[1200], why[1400], script[1300];
    pk_job_dir(c->data, id, dir, sizeof dir);
    pk_slurm_job sj = {.id = id,
                       .dir = dir,
                       .author = pk_worker_author(job),
                       .packd = c->slurm_packd[0] ? c->slurm_packd : s->exe,
                       .threads = c->job_threads,
                       .ranks = pk_slurm_job_ranks(job),
                       .wall_s = pk_slurm_job_wall(job, c->max_wall_time_s),
                       .checkpoint_interval_s = c->checkpoint_interval_s};
    json_t *ch;
    char path[1300];
    pk_job_file_path(dir, PK_JOB_EXIT, path, sizeof path);
    unlink(path);
    pk_job_file_path(dir, PK_JOB_PROGRESS, path, sizeof path);
    unlink(path);
    if (pk_worker_prepare(dir, job, why, sizeof why) != 0 ||
        pk_slurm_script_write(&sj, c, script, sizeof script, why, sizeof why) != 0) {
        ch = change(id, "finish");
        json_object_set_new(ch, "message", json_string(why));
        return ch;
    }
    /* sbatch --parsable [operator options] script */
    char opts[sizeof c->slurm_options];
    snprintf(opts, sizeof opts, "%s", c->slurm_options);
    const char *argv[64] = {"sbatch", "--parsable"};
    int k = 2;
    for (char *t = strtok(opts, " \t"); t && k < 62; t = strtok(NULL, " \t"))
        argv[k++] = t;
    argv[k++] = script;
    argv[k] = NULL;
    char out[2048], line[512];
    int rc = pk_slurm_cmd(argv, out, sizeof out, CMD_TIMEOUT_S);
    first_line(out, line, sizeof line);
    long jid = rc == 0 ? atol(line) : 0;
    if (jid > 0) {
        char ref[64], msg[128];
        snprintf(ref, sizeof ref, "slurm:%ld", jid);
        snprintf(msg, sizeof msg, "queued on Slurm: submitted as job %ld", jid);
        ch = change(id, "queued");
        json_object_set_new(ch, "ref", json_string(ref));
        json_object_set_new(ch, "message", json_string(msg));
        pk_log(PK_LOG_INFO, "submitted to slurm", "{s:s,s:i}", "job", id, "slurm_job", (int)jid);
        return ch;
    }
    if (rc < 0 || pk_slurm_unreachable(out)) { /* try again when the controller answers */
        snprintf(why, sizeof why, "sbatch failed (the controller is unreachable): %s", line);
        set_health(s, 0, why);
        ch = change(id, "requeue");
        snprintf(why, sizeof why, "accepted; waiting for the Slurm controller: %s", line);
        json_object_set_new(ch, "message", json_string(why));
        return ch;
    }
    snprintf(why, sizeof why, "Slurm refused the job: %s", line);
    ch = change(id, "finish");
    json_object_set_new(ch, "message", json_string(why));
    pk_log(PK_LOG_WARN, "sbatch refused a job", "{s:s,s:s}", "job", id, "error", out);
    return ch;
}

/* The first and last lines of progress.jsonl: the attempt/node line the
 * script writes, and the worker's latest progress (NULL if none). */
static json_t *read_progress(const char *dir, int *attempt, char *node, size_t nn)
{
    char path[1300], buf[16384];
    pk_job_file_path(dir, PK_JOB_PROGRESS, path, sizeof path);
    FILE *f = fopen(path, "r");
    if (!f)
        return NULL;
    json_t *head = NULL, *last = NULL;
    if (fgets(buf, sizeof buf, f))
        head = json_loads(buf, 0, NULL);
    *attempt = (int)json_integer_value(json_object_get(head, "attempt"));
    if (json_is_string(json_object_get(head, "node")))
        snprintf(node, nn, "%s", json_string_value(json_object_get(head, "node")));
    json_decref(head);
    /* only the tail matters: the newest complete line */
    fseek(f, 0, SEEK_END);
    long size = ftell(f), from = size > (long)sizeof buf - 1 ? size - (long)sizeof buf + 1 : 0;
    fseek(f, from, SEEK_SET);
    size_t n = fread(buf, 1, sizeof buf - 1, f);
    fclose(f);
    buf[n] = 0;
    while (n > 0 && buf[n - 1] != '\n') /* a line still being written */
        buf[--n] = 0;
    if (n > 0)
        buf[--n] = 0;
    char *start = strrchr(buf, '\n');
    last = json_loads(start ? start + 1 : buf, 0, NULL);
    if (!json_is_object(last) || json_object_get(last, "attempt")) {
        json_decref(last);
        return NULL;
    }
    pk_worker_percent(last);
    return last;
}

/* key=value of `scontrol show job -o` or a sacct -P field; "" if absent. */
static void field(const char *text, const char *key, char *out, size_t n)
{
    out[0] = 0;
    size_t kl = strlen(key);
    for (const char *p = text; (p = strstr(p, key)); p += kl)
        if ((p == text || p[-1] == ' ') && p[kl] == '=') {
            p += kl + 1;
            size_t l = strcspn(p, " \n");
            snprintf(out, n, "%.*s", (int)(l < n ? l : n - 1), p);
            return;
        }
}

/* The end of a Slurm job with no exit_status in its directory: ask Slurm
 * (scontrol while it remembers the job, else sacct over the jobcomp or
 * accounting records).  exit: the batch script's status or -1. */
static void ask_slurm(const char *jid, char *state, size_t sn, char *node, size_t nn, int *exit,
                      char *reason, size_t rn)
{
    char out[8192], code[32] = "";
    *exit = -1;
    const char *sc[] = {"scontrol", "show", "job", "-o", jid, NULL};
    if (pk_slurm_cmd(sc, out, sizeof out, CMD_TIMEOUT_S) == 0) {
        field(out, "JobState", state, sn);
        field(out, "NodeList", node, nn);
        field(out, "ExitCode", code, sizeof code);
        field(out, "Reason", reason, rn);
    } else {
        const char *sa[] = {"sacct", "-c", "-n", "-P", "-j", jid, "-o", "State,ExitCode,NodeList",
                            NULL};
        if (pk_slurm_cmd(sa, out, sizeof out, CMD_TIMEOUT_S) != 0)
            out[0] = 0;
        char *bar = strchr(out, '|');
        if (bar) {
            *bar = 0;
            if (snprintf(state, sn, "%s", out) >= (int)sn) /* a state name: cut is fine */
                state[sn - 1] = 0;
            char *bar2 = strchr(bar + 1, '|');
            if (bar2) {
                *bar2 = 0;
                first_line(bar2 + 1, node, nn);
            }
            snprintf(code, sizeof code, "%s", bar + 1);
        }
    }
    if (code[0])
        *exit = atoi(code);
}

/* The change that ends a held job whose Slurm job is over (or gone). */
static json_t *ended(json_t *job, const char *jid, const sq_entry *e, const pk_config *c)
{
    const char *id = json_string_value(json_object_get(job, "id"));
    char dir[1200], path[1300], msg[4096], tail[1024] = "";
    pk_job_dir(c->data, id, dir, sizeof dir);
    json_t *ch = change(id, "finish");
    char ref[64];
    snprintf(ref, sizeof ref, "slurm:%s:ended", jid);
    json_object_set_new(ch, "ref", json_string(ref));
    pk_job_file_path(dir, PK_JOB_EXIT, path, sizeof path);
    FILE *f = fopen(path, "r");
    int code = -1, attempt = 0;
    char node[128] = "";
    if (f) {
        if (fscanf(f, "%d %d %127s", &code, &attempt, node) < 1)
            code = -1;
        fclose(f);
    }
    if (code == 0 || code == 3) {
        pk_worker_outcome o;
        pk_worker_outcome_read(dir, code, &o);
        json_object_set_new(ch, "status", json_string(o.status));
        json_object_set_new(ch, "message", json_string(o.message));
        if (o.summary)
            json_object_set_new(ch, "summary", json_string(o.summary));
        if (o.sha256[0]) {
            json_object_set_new(ch, "sha256", json_string(o.sha256));
            json_object_set_new(ch, "size", json_integer(o.size));
        }
        free(o.summary);
        return ch;
    }
    pk_worker_remove_tmp(dir); /* what a killed worker was writing */
    char state[32] = "", reason[128] = "", slurm_node[128] = "";
    snprintf(state, sizeof state, "%s", e ? e->state : "");
    if (!node[0] && e)
        snprintf(node, sizeof node, "%s", e->nodes);
    int slurm_exit = -1;
    if (code < 0) { /* no exit record: the script did not run to its end */
        ask_slurm(jid, state, sizeof state, slurm_node, sizeof slurm_node, &slurm_exit, reason,
                  sizeof reason);
        if (!node[0])
            snprintf(node, sizeof node, "%s", slurm_node);
    }
    char log[1300], what[1024];
    int ranks = pk_slurm_job_ranks(job), lost;
    pk_job_file_path(dir, PK_JOB_LOG, log, sizeof log);
    pk_worker_last_line(log, tail, sizeof tail);
    if (!strncmp(tail, PK_SLURM_ATTEMPT_MARK, strlen(PK_SLURM_ATTEMPT_MARK)))
        tail[0] = 0; /* the worker said nothing */
    pk_job_file_path(dir, PK_JOB_PROGRESS, path, sizeof path);
    int started = access(path, F_OK) == 0; /* the script's first line is there */
    if (slurm_exit == PK_SLURM_NO_DIR || code == PK_SLURM_NO_DIR ||
        (!started && !strcmp(reason, "JobLaunchFailure")))
        snprintf(msg, sizeof msg,
                 "failed: the job directory %s is not visible on node %s (Slurm job %s, "
                 "%s%s%s; it must be on a filesystem the nodes share)",
                 dir, node[0] ? node : "(unknown)", jid, state[0] ? state : "ended",
                 reason[0] ? ", " : "", reason);
    else if (code > 0 && ranks > 1 && (lost = pk_slurm_first_bad_task(log, what, sizeof what)) >= 0)
        /* under srun the lost rank takes the step down (SIGKILL after KillWait) before
         * rank 0 can always write its own report (exit 3, above) */
        snprintf(msg, sizeof msg,
                 "failed: MPI rank %d of %d was lost (srun: %s); Slurm ended the job's other "
                 "ranks (exit status %d on node %s, no result kept)",
                 lost, ranks, what, code, node);
    else if (code > 0)
        snprintf(msg, sizeof msg, "worker exited with status %d on node %s%s%s", code, node,
                 tail[0] ? ": " : "", tail);
    else
        snprintf(msg, sizeof msg, "Slurm job %s ended %s%s%s on node %s without an exit record%s%s",
                 jid, state[0] ? state : "(forgotten by Slurm)", reason[0] ? ", reason " : "",
                 reason, node[0] ? node : "(none)", tail[0] ? ": " : "", tail);
    json_object_set_new(ch, "status", json_string("failed"));
    json_object_set_new(ch, "message", json_string(msg));
    return ch;
}

static void scancel(const char *jid)
{
    const char *argv[] = {"scancel", jid, NULL};
    char out[512];
    pk_slurm_cmd(argv, out, sizeof out, CMD_TIMEOUT_S);
}

/* The change of a held job that Slurm still has (queued or running). */
static json_t *follow(json_t *job, const char *jid, const sq_entry *e, const pk_config *c)
{
    const char *id = json_string_value(json_object_get(job, "id"));
    char dir[1200], msg[512], node[128] = "";
    pk_job_dir(c->data, id, dir, sizeof dir);
    int attempt = 0;
    json_t *progress = read_progress(dir, &attempt, node, sizeof node);
    if (attempt > c->max_attempts) {
        scancel(jid);
        json_decref(progress);
        json_t *ch = change(id, "finish");
        char ref[64];
        snprintf(ref, sizeof ref, "slurm:%s:ended", jid);
        snprintf(msg, sizeof msg,
                 "failed: started %d times by Slurm (requeued after node failures or"
                 " preemption); max_attempts is %d",
                 attempt, c->max_attempts);
        json_object_set_new(ch, "ref", json_string(ref));
        json_object_set_new(ch, "status", json_string("failed"));
        json_object_set_new(ch, "message", json_string(msg));
        return ch;
    }
    int queued = state_is(e->state, queued_states);
    json_t *ch = change(id, queued ? "queued" : "running");
    if (queued && attempt > 0)
        snprintf(msg, sizeof msg, "queued on Slurm: %s (requeued after attempt %d, job %s)",
                 e->reason, attempt, jid);
    else if (queued)
        snprintf(msg, sizeof msg, "queued on Slurm: %s (job %s)", e->reason, jid);
    else
        snprintf(msg, sizeof msg, "running on Slurm node %s (job %s, attempt %d)%s%s",
                 e->nodes[0] ? e->nodes : node, jid, attempt > 0 ? attempt : 1,
                 strcmp(e->state, "RUNNING") ? ": " : "",
                 strcmp(e->state, "RUNNING") ? e->state : "");
    json_object_set_new(ch, "message", json_string(msg));
    if (attempt > 0 && !queued)
        json_object_set_new(ch, "attempts", json_integer(attempt));
    if (progress && !queued)
        json_object_set_new(ch, "progress", progress);
    else
        json_decref(progress);
    return ch;
}

static void cycle(slurm_exec *s)
{
    pthread_mutex_lock(&s->mu);
    pk_config c = s->cfg;
    int degraded = s->degraded;
    pthread_mutex_unlock(&s->mu);
    json_t *held = pk_queue_held_jobs(s->q, "slurm");
    json_t *claimed = json_array(), *changes = json_array();
    int room = c.slurm_max_jobs - (int)json_array_size(held);
    for (int i = 0; i < room && i < MAX_SUBMIT && !degraded; i++) {
        json_t *job = pk_queue_claim_by_wall(
            s->q, c.slurm_local_below_s > 0 ? PK_CLAIM_LONG : PK_CLAIM_ANY, c.slurm_local_below_s);
        if (!job)
            break;
        json_array_append_new(claimed, job);
    }
    sq_list l = {0};
    size_t i;
    json_t *job;
    if (!json_array_size(held) && !json_array_size(claimed) && !degraded)
        goto out;
    if (list_jobs(s, &l) != 0) { /* nothing is known: claimed jobs wait */
        json_array_foreach (claimed, i, job) {
            json_t *ch = change(json_string_value(json_object_get(job, "id")), "requeue");
            json_object_set_new(ch, "message",
                                json_string("accepted; waiting for the Slurm controller"));
            json_array_append_new(changes, ch);
        }
        goto out;
    }
    json_array_foreach (claimed, i, job) {
        const char *id = json_string_value(json_object_get(job, "id"));
        const sq_entry *e = find(&l, id);
        if (e && !state_is(e->state, ended_states)) { /* submitted before a daemon death */
            json_t *ch = change(id, "queued");
            char ref[64], msg[128];
            snprintf(ref, sizeof ref, "slurm:%s", e->jid);
            snprintf(msg, sizeof msg, "queued on Slurm: adopted job %s", e->jid);
            json_object_set_new(ch, "ref", json_string(ref));
            json_object_set_new(ch, "message", json_string(msg));
            json_array_append_new(changes, ch);
            pk_log(PK_LOG_INFO, "adopted slurm job", "{s:s,s:s}", "job", id, "slurm_job", e->jid);
        } else {
            json_array_append_new(changes, submit(s, job, &c));
        }
    }
    int running = 0;
    json_array_foreach (held, i, job) {
        const char *id = json_string_value(json_object_get(job, "id"));
        const char *status = json_string_value(json_object_get(job, "status"));
        const char *jid = json_string_value(json_object_get(job, "executor_ref")) + 6;
        const sq_entry *e = find(&l, id);
        int over = !e || state_is(e->state, ended_states);
        if (!strcmp(status, "dismissed")) {
            if (!over) {
                scancel(e->jid);
                continue;
            }
            json_t *ch = change(id, "finish");
            char ref[64], dir[1200], path[1300];
            snprintf(ref, sizeof ref, "slurm:%s:ended", jid);
            json_object_set_new(ch, "ref", json_string(ref));
            json_array_append_new(changes, ch);
            pk_job_dir(c.data, id, dir, sizeof dir); /* nobody will download it */
            pk_worker_remove_tmp(dir);
            pk_job_file_path(dir, PK_JOB_RESULT, path, sizeof path);
            unlink(path);
            continue;
        }
        if (over) {
            json_t *ch = ended(job, e ? e->jid : jid, e, &c);
            pk_log(PK_LOG_INFO, "slurm job ended", "{s:s,s:s,s:O}", "job", id, "slurm_job",
                   e ? e->jid : jid, "status", json_object_get(ch, "status"));
            json_array_append_new(changes, ch);
            continue;
        }
        running += !state_is(e->state, queued_states);
        json_array_append_new(changes, follow(job, e->jid, e, &c));
    }
    pthread_mutex_lock(&s->mu);
    s->held_running = running;
    pthread_mutex_unlock(&s->mu);
out:
    pk_queue_sync(s->q, changes);
    free(l.v);
    json_decref(changes);
    json_decref(claimed);
    json_decref(held);
}

static void *loop(void *arg)
{
    slurm_exec *s = arg;
    for (;;) {
        pthread_mutex_lock(&s->mu);
        int stopping = s->stopping;
        pthread_mutex_unlock(&s->mu);
        if (stopping)
            break;
        double t0 = pk_queue_now();
        cycle(s);
        pthread_mutex_lock(&s->mu);
        s->cycles++;
        s->cycle_s += pk_queue_now() - t0;
        pthread_mutex_unlock(&s->mu);
        struct pollfd pf = {s->wake[0], POLLIN, 0};
        if (poll(&pf, 1, (int)(POLL_S * 1000)) > 0) {
            char buf[64];
            while (read(s->wake[0], buf, sizeof buf) > 0)
                ;
        }
    }
    return NULL;
}

static void configure(pk_executor *e, const pk_config *c)
{
    slurm_exec *s = (slurm_exec *)e;
    pthread_mutex_lock(&s->mu);
    s->cfg = *c;
    pthread_mutex_unlock(&s->mu);
    pk_executor_configure(s->local, c);
    e->ops->wake(e);
}

static void wake(pk_executor *e)
{
    slurm_exec *s = (slurm_exec *)e;
    ssize_t r = write(s->wake[1], "w", 1);
    (void)r;
    pk_executor_wake(s->local);
}

static int busy(pk_executor *e)
{
    slurm_exec *s = (slurm_exec *)e;
    pthread_mutex_lock(&s->mu);
    int n = s->held_running;
    pthread_mutex_unlock(&s->mu);
    return n + pk_executor_busy(s->local);
}

static int capacity(pk_executor *e)
{
    slurm_exec *s = (slurm_exec *)e;
    pthread_mutex_lock(&s->mu);
    int n = s->cfg.slurm_max_jobs;
    pthread_mutex_unlock(&s->mu);
    return n + pk_executor_capacity(s->local);
}

static int healthy(pk_executor *e, char *why, size_t n)
{
    slurm_exec *s = (slurm_exec *)e;
    pthread_mutex_lock(&s->mu);
    int ok = !s->degraded;
    snprintf(why, n, "%s", s->why);
    pthread_mutex_unlock(&s->mu);
    return ok;
}

/* Ends of the Slurm jobs are written by the poll cycle, which reads them
 * again from the job directory until they are; the local workers keep theirs. */
static int unrecorded(pk_executor *e) { return pk_executor_unrecorded(((slurm_exec *)e)->local); }

static void poll_stats(pk_executor *e, long long *cycles, double *seconds)
{
    slurm_exec *s = (slurm_exec *)e;
    pthread_mutex_lock(&s->mu);
    *cycles = s->cycles;
    *seconds = s->cycle_s;
    pthread_mutex_unlock(&s->mu);
}

/* Jobs on Slurm keep running: a restarted daemon adopts them. */
static void stop(pk_executor *e, double grace_s)
{
    slurm_exec *s = (slurm_exec *)e;
    pthread_mutex_lock(&s->mu);
    int was = s->stopping;
    s->stopping = 1;
    pthread_mutex_unlock(&s->mu);
    if (was)
        return;
    wake(e);
    pthread_join(s->thread, NULL);
    pk_executor_stop(s->local, grace_s);
}

static void destroy(pk_executor *e)
{
    slurm_exec *s = (slurm_exec *)e;
    pk_executor_free(s->local);
    close(s->wake[0]);
    close(s->wake[1]);
    pthread_mutex_destroy(&s->mu);
    free(s->squeue_out);
    free(s);
}

static const pk_executor_ops slurm_ops = {"slurm", configure, wake,    busy,       capacity,
                                          healthy, stop,      destroy, poll_stats, unrecorded};

pk_executor *pk_executor_slurm_start(pk_queue *q, const char *exe, const pk_config *c, char *err,
                                     size_t errlen)
{
    slurm_exec *s = calloc(1, sizeof *s);
    if (s)
        s->squeue_out = malloc(SQUEUE_BYTES);
    if (!s || !s->squeue_out) {
        free(s);
        snprintf(err, errlen, "out of memory");
        return NULL;
    }
    s->base.ops = &slurm_ops;
    s->q = q;
    s->cfg = *c;
    snprintf(s->exe, sizeof s->exe, "%s", exe);
    pthread_mutex_init(&s->mu, NULL);
    int p[2];
    if (pipe(p) != 0) {
        snprintf(err, errlen, "cannot make a pipe");
        free(s->squeue_out);
        free(s);
        return NULL;
    }
    for (int k = 0; k < 2; k++) {
        fcntl(p[k], F_SETFD, FD_CLOEXEC);
        fcntl(p[k], F_SETFL, fcntl(p[k], F_GETFL) | O_NONBLOCK);
        s->wake[k] = p[k];
    }
    s->local = pk_executor_local_start(q, exe, c, 1);
    if (!s->local || pthread_create(&s->thread, NULL, loop, s) != 0) {
        snprintf(err, errlen, "cannot start the executor threads");
        pk_executor_stop(s->local, 0);
        s->local ? destroy(&s->base) : (void)0;
        return NULL;
    }
    return &s->base;
}
