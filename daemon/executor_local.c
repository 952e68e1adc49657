/* executor_local.c — the local back end: claim a job, fork and exec
 * `packd run` in its directory, relay progress, enforce wall time and
 * cancels, record the end.
 *
 * One thread claims accepted jobs from the queue while fewer than `workers`
 * run, and starts each as a child process: fork/exec of this same binary,
 *   packd run DATA/jobs/<id>/job.json -o DATA/jobs/<id>/result.h5 --progress-fd 3 --threads T
 * with stdout -> summary.json, stderr -> worker.log.  The child
 *   - dies with the daemon (PR_SET_PDEATHSIG = SIGKILL, checked against a race),
 *   - holds an exclusive flock on DATA/jobs/<id>/worker.lock for its whole life,
 *     so a second worker of the same job (e.g. after a daemon restart while the
 *     old child is still being killed) waits until the first is gone.
 * The thread relays progress lines to the queue (-> SSE), reaps children
 * (a crash fails only that job, with the signal in `message`), hashes the
 * result (SHA-256) and sends SIGTERM to workers of dismissed jobs — which
 * the worker turns into the core's cancel flag — within 0.2 s of the request.
 * Contract: executor.h. */
#include "executor.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <pthread.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "data_paths.h"
#include "job_end.h"
#include "log.h"
#include "worker_files.h"
#include "daemon/store/job_files.h"

#define MAX_SLOTS 1024
#define POLL_MS 200 /* cancel requests are seen within this (+ the worker's tick) */
/* A cancelled worker stops placing within a second (the core's cancel flag)
 * but then saves what it placed; the daemon discards that file, so a worker
 * still alive this long after SIGTERM gets SIGKILL. */
#define KILL_AFTER_TERM_S 2
#define WALL_MARGIN_S 30 /* hard stop this long after the job's own wall-time limit */

typedef struct slot {
    pid_t pid; /* 0 = free */
    char id[37];
    int fd; /* progress pipe (read end) */
    char line[8192];
    size_t nline;
    double started, term_sent;
    int killed_for_time;
    pk_job_end end; /* pending: the slot holds an end the queue has not recorded */
} slot;

typedef struct local_exec {
    pk_executor base;
    pk_queue *q;
    int short_only; /* beside slurm: only jobs with limits.wall_time_s <= local_below_s */
    double local_below_s;
    char exe[1024], data[1024];
    pthread_t thread;
    pthread_mutex_t mu;
    int workers;
    double max_wall_time_s;
    int job_threads; /* --threads of each worker */
    int worker_nice; /* setpriority of each worker */
    double checkpoint_interval_s;
    int stopping;
    double grace_deadline;
    int wake[2];
    int busy;       /* slots with a worker or a pending end */
    int unrecorded; /* slots with a pending end */
    slot slots[MAX_SLOTS];
} local_exec;

/* pipe2(O_CLOEXEC) without _GNU_SOURCE. */
static int cloexec_pipe(int p[2], int nonblock)
{
    if (pipe(p) != 0)
        return -1;
    for (int i = 0; i < 2; i++) {
        fcntl(p[i], F_SETFD, FD_CLOEXEC);
        if (nonblock)
            fcntl(p[i], F_SETFL, fcntl(p[i], F_GETFL) | O_NONBLOCK);
    }
    return 0;
}

static void set_nonblock(int fd) { fcntl(fd, F_SETFL, fcntl(fd, F_GETFL) | O_NONBLOCK); }

/* A slot's end recorded: the worker's files of a dismissed job go, the slot
 * is free. */
static void end_recorded(local_exec *s, slot *sl, const char *ended)
{
    if (!strcmp(ended, "dismissed")) { /* nobody will download it */
        char dir[1200], path[1300];
        pk_job_dir(s->data, sl->id, dir, sizeof dir);
        pk_worker_remove_tmp(dir);
        pk_job_file_path(dir, PK_JOB_RESULT, path, sizeof path);
        unlink(path);
    }
    __atomic_sub_fetch(&s->busy, 1, __ATOMIC_RELAXED);
}

/* Record a slot's end (the slot counts as busy); kept pending while the
 * queue cannot write it.  Returns what the job ended with, or NULL. */
static const char *end_slot(local_exec *s, slot *sl, const char *status, const char *msg,
                            const char *summary, const char *sha256, long long size)
{
    /* what clients read (status, SSE, problems) names no path of the data directory */
    char *m = pk_hide_data_paths(msg, s->data), *sum = pk_hide_data_paths(summary, s->data);
    const char *ended = pk_job_end_record(&sl->end, s->q, sl->id, status, m ? m : msg,
                                          sum ? sum : summary, sha256, size);
    free(m);
    free(sum);
    if (ended)
        end_recorded(s, sl, ended);
    else
        __atomic_add_fetch(&s->unrecorded, 1, __ATOMIC_RELAXED);
    return ended;
}

/* A claimed job that could not start fails (its end pending if need be). */
static void launch_failed(local_exec *s, slot *sl, const char *id, const char *why)
{
    memset(sl, 0, sizeof *sl);
    snprintf(sl->id, sizeof sl->id, "%s", id);
    __atomic_add_fetch(&s->busy, 1, __ATOMIC_RELAXED);
    end_slot(s, sl, "failed", why, NULL, NULL, 0);
}

static int launch(local_exec *s, slot *sl, json_t *job)
{
    const char *id = json_string_value(json_object_get(job, "id"));
    char dir[1200], job_path[1300], out_path[1300], sum_path[1300], log_path[1300], lock_path[1300],
        ckpt_path[1300];
    pk_job_dir(s->data, id, dir, sizeof dir);
    pk_job_file_path(dir, PK_JOB_INPUT, job_path, sizeof job_path);
    pk_job_file_path(dir, PK_JOB_RESULT, out_path, sizeof out_path);
    pk_job_file_path(dir, PK_JOB_SUMMARY, sum_path, sizeof sum_path);
    pk_job_file_path(dir, PK_JOB_LOG, log_path, sizeof log_path);
    pk_job_file_path(dir, PK_JOB_LOCK, lock_path, sizeof lock_path);
    pk_job_file_path(dir, PK_JOB_CHECKPOINT, ckpt_path, sizeof ckpt_path);
    char why[1400];
    if (pk_worker_prepare(dir, job, why, sizeof why) != 0) {
        launch_failed(s, sl, id, why);
        return -1;
    }
    char threads[16], interval[32], owner[128];
    snprintf(owner, sizeof owner, "%s", pk_worker_author(job));
    pthread_mutex_lock(&s->mu);
    snprintf(threads, sizeof threads, "%d", s->job_threads);
    int niceness = s->worker_nice;
    snprintf(interval, sizeof interval, "%g",
             s->checkpoint_interval_s > 0 ? s->checkpoint_interval_s : 30);
    pthread_mutex_unlock(&s->mu);
    int p[2];
    if (cloexec_pipe(p, 0) != 0) {
        snprintf(why, sizeof why, "cannot make a pipe: %s", strerror(errno));
        launch_failed(s, sl, id, why);
        return -1;
    }
    pid_t parent = getpid();
    pid_t pid = fork();
    if (pid == 0) { /* child: async-signal-safe calls only until exec */
        if (prctl(PR_SET_PDEATHSIG, SIGKILL) != 0 || getppid() != parent)
            _exit(125);
        sigset_t none;
        sigemptyset(&none);
        sigprocmask(SIG_SETMASK, &none, NULL);
        signal(SIGPIPE, SIG_DFL);
        if (niceness > 0 && setpriority(PRIO_PROCESS, 0, niceness) != 0)
            _exit(125);
        int lk = open(lock_path, O_RDWR | O_CREAT, 0640);
        if (lk < 0 || flock(lk, LOCK_EX) != 0) /* inherited by the exec'd worker */
            _exit(125);
        if (lk <= 3) {
            int hi = fcntl(lk, F_DUPFD, 10);
            if (hi < 0)
                _exit(125);
            close(lk);
        }
        int so = open(sum_path, O_WRONLY | O_CREAT | O_TRUNC, 0640);
        int se = open(log_path, O_WRONLY | O_CREAT | O_APPEND, 0640);
        int dn = open("/dev/null", O_RDONLY);
        if (so < 0 || se < 0 || dn < 0 || dup2(dn, 0) < 0 || dup2(so, 1) < 0 || dup2(se, 2) < 0 ||
            dup2(p[1], 3) < 0)
            _exit(125);
        execl(s->exe, "packd", "run", job_path, "-o", out_path, "--progress-fd", "3", "--threads",
              threads, "--pictures", dir, "--checkpoint", ckpt_path, "--checkpoint-interval",
              interval, "--author", owner, (char *)NULL);
        _exit(127);
    }
    close(p[1]);
    if (pid < 0) {
        close(p[0]);
        pk_queue_requeue(s->q, id, "re-queued: fork failed");
        return -1;
    }
    set_nonblock(p[0]);
    memset(sl, 0, sizeof *sl);
    sl->pid = pid;
    sl->fd = p[0];
    snprintf(sl->id, sizeof sl->id, "%s", id);
    sl->started = pk_queue_now();
    pk_queue_set_worker(s->q, id, pid);
    pk_log(PK_LOG_INFO, "worker started", "{s:s,s:i,s:I}", "job", id, "pid", (int)pid, "attempt",
           json_integer_value(json_object_get(job, "attempts")));
    return 0;
}

static void relay_line(local_exec *s, slot *sl, const char *line)
{
    json_t *p = json_loads(line, 0, NULL);
    if (!json_is_object(p)) {
        json_decref(p);
        return;
    }
    int percent = pk_worker_percent(p);
    pk_queue_progress(s->q, sl->id, percent, p);
    json_decref(p);
}

static void drain(local_exec *s, slot *sl)
{
    for (;;) {
        ssize_t n = read(sl->fd, sl->line + sl->nline, sizeof sl->line - 1 - sl->nline);
        if (n <= 0)
            return;
        sl->nline += (size_t)n;
        sl->line[sl->nline] = 0;
        char *start = sl->line, *nl;
        while ((nl = strchr(start, '\n'))) {
            *nl = 0;
            relay_line(s, sl, start);
            start = nl + 1;
        }
        sl->nline -= (size_t)(start - sl->line);
        memmove(sl->line, start, sl->nline);
        if (sl->nline == sizeof sl->line - 1) /* an absurd line: drop it */
            sl->nline = 0;
    }
}

static void finished(local_exec *s, slot *sl, int wstatus)
{
    drain(s, sl);
    close(sl->fd);
    char dir[1200], path[1300], msg[1200], tail[1024];
    pk_job_dir(s->data, sl->id, dir, sizeof dir);
    const char *ended;
    /* exit 0: successful; exit 3: failed with a partial result file whose
     * summary says why (docs/job-format.md, "Status") */
    int code = WIFEXITED(wstatus) ? WEXITSTATUS(wstatus) : -1;
    if (code == 0 || code == 3) {
        pk_worker_outcome o;
        pk_worker_outcome_read(dir, code, &o);
        ended =
            end_slot(s, sl, o.status, o.message, o.summary, o.sha256[0] ? o.sha256 : NULL, o.size);
        free(o.summary);
    } else {
        pk_job_file_path(dir, PK_JOB_LOG, path, sizeof path);
        pk_worker_last_line(path, tail, sizeof tail);
        if (sl->killed_for_time)
            snprintf(msg, sizeof msg, "worker killed: wall time exceeded");
        else if (WIFSIGNALED(wstatus))
            snprintf(msg, sizeof msg, "worker killed by signal %d (%s)", WTERMSIG(wstatus),
                     strsignal(WTERMSIG(wstatus)));
        else
            snprintf(msg, sizeof msg, "worker exited with status %d%s%s", WEXITSTATUS(wstatus),
                     tail[0] ? ": " : "", tail);
        ended = end_slot(s, sl, "failed", msg, NULL, NULL, 0);
    }
    pk_log(!ended || ended[0] == 'f' ? PK_LOG_WARN : PK_LOG_INFO, "worker ended",
           "{s:s,s:i,s:s,s:i,s:f}", "job", sl->id, "pid", (int)sl->pid, "status",
           ended ? ended : "not recorded yet", "wait_status", wstatus, "seconds",
           pk_queue_now() - sl->started);
    sl->pid = 0;
}

/* Pending ends whose second has come are written again. */
static void retry_ends(local_exec *s)
{
    double now = pk_queue_now();
    for (int k = 0; k < MAX_SLOTS && __atomic_load_n(&s->unrecorded, __ATOMIC_RELAXED); k++) {
        slot *sl = &s->slots[k];
        const char *ended = pk_job_end_retry(&sl->end, s->q, now);
        if (ended) {
            __atomic_sub_fetch(&s->unrecorded, 1, __ATOMIC_RELAXED);
            end_recorded(s, sl, ended);
        }
    }
}

static void send_cancels(local_exec *s)
{
    json_t *req = pk_queue_cancel_requests(s->q);
    size_t i;
    json_t *r;
    double now = pk_queue_now();
    json_array_foreach (req, i, r) {
        const char *id = json_string_value(json_object_get(r, "id"));
        for (int k = 0; k < MAX_SLOTS; k++) {
            slot *sl = &s->slots[k];
            if (!sl->pid || strcmp(sl->id, id) != 0)
                continue;
            if (sl->term_sent == 0) {
                kill(sl->pid, SIGTERM);
                sl->term_sent = now;
                pk_log(PK_LOG_INFO, "cancelling worker", "{s:s,s:i}", "job", id, "pid",
                       (int)sl->pid);
            } else if (now - sl->term_sent > KILL_AFTER_TERM_S) {
                kill(sl->pid, SIGKILL);
            }
        }
    }
    json_decref(req);
}

static void enforce_wall_time(local_exec *s, double max_wall)
{
    double now = pk_queue_now();
    for (int k = 0; k < MAX_SLOTS; k++) {
        slot *sl = &s->slots[k];
        if (sl->pid && !sl->killed_for_time && now - sl->started > max_wall + WALL_MARGIN_S) {
            sl->killed_for_time = 1;
            kill(sl->pid, SIGKILL);
        }
    }
}

static void *loop(void *arg)
{
    local_exec *s = arg;
    struct pollfd pfd[MAX_SLOTS + 1];
    int map[MAX_SLOTS + 1];
    for (;;) {
        pthread_mutex_lock(&s->mu);
        int workers = s->workers, stopping = s->stopping;
        double max_wall = s->max_wall_time_s, deadline = s->grace_deadline;
        pthread_mutex_unlock(&s->mu);
        int busy = __atomic_load_n(&s->busy, __ATOMIC_RELAXED);
        if (stopping && busy == 0)
            break;
        if (stopping && pk_queue_now() > deadline) {
            for (int k = 0; k < MAX_SLOTS; k++) {
                slot *sl = &s->slots[k];
                if (sl->end.pending) {
                    pk_log(PK_LOG_ERROR,
                           "job end not recorded at shutdown: re-queued at the next start",
                           "{s:s,s:s}", "job", sl->id, "status", sl->end.status);
                    pk_job_end_drop(&sl->end);
                    __atomic_sub_fetch(&s->unrecorded, 1, __ATOMIC_RELAXED);
                    __atomic_sub_fetch(&s->busy, 1, __ATOMIC_RELAXED);
                }
                if (!sl->pid)
                    continue;
                kill(sl->pid, SIGKILL);
                waitpid(sl->pid, NULL, 0);
                close(sl->fd);
                pk_queue_requeue(s->q, sl->id,
                                 "re-queued: the daemon stopped before the job finished");
                pk_log(PK_LOG_WARN, "job re-queued at shutdown", "{s:s}", "job", sl->id);
                sl->pid = 0;
                __atomic_sub_fetch(&s->busy, 1, __ATOMIC_RELAXED);
            }
            break;
        }
        /* claim while there is room */
        for (int k = 0; !stopping && busy < workers && k < MAX_SLOTS; k++) {
            if (s->slots[k].pid || s->slots[k].end.pending)
                continue;
            json_t *job = pk_queue_claim_by_wall(
                s->q, s->short_only ? PK_CLAIM_SHORT : PK_CLAIM_ANY, s->local_below_s);
            if (!job)
                break;
            if (launch(s, &s->slots[k], job) == 0)
                busy = (int)__atomic_add_fetch(&s->busy, 1, __ATOMIC_RELAXED);
            json_decref(job);
        }
        int n = 0;
        pfd[n].fd = s->wake[0];
        pfd[n].events = POLLIN;
        map[n++] = -1;
        for (int k = 0; k < MAX_SLOTS; k++)
            if (s->slots[k].pid) {
                pfd[n].fd = s->slots[k].fd;
                pfd[n].events = POLLIN;
                map[n++] = k;
            }
        poll(pfd, (nfds_t)n, POLL_MS);
        if (pfd[0].revents & POLLIN) {
            char buf[64];
            while (read(s->wake[0], buf, sizeof buf) > 0)
                ;
        }
        for (int i = 1; i < n; i++)
            if (pfd[i].revents)
                drain(s, &s->slots[map[i]]);
        for (int k = 0; k < MAX_SLOTS; k++) {
            slot *sl = &s->slots[k];
            int ws;
            if (sl->pid && waitpid(sl->pid, &ws, WNOHANG) == sl->pid)
                finished(s, sl, ws);
        }
        retry_ends(s);
        send_cancels(s);
        enforce_wall_time(s, max_wall);
    }
    return NULL;
}

static void configure(pk_executor *e, const pk_config *c)
{
    local_exec *s = (local_exec *)e;
    pthread_mutex_lock(&s->mu);
    s->workers = c->workers > MAX_SLOTS ? MAX_SLOTS : c->workers;
    s->max_wall_time_s = c->max_wall_time_s;
    s->job_threads = c->job_threads;
    s->worker_nice = c->worker_nice;
    s->checkpoint_interval_s = c->checkpoint_interval_s;
    s->local_below_s = c->slurm_local_below_s;
    pthread_mutex_unlock(&s->mu);
    e->ops->wake(e);
}

static void wake(pk_executor *e)
{
    ssize_t r = write(((local_exec *)e)->wake[1], "w", 1);
    (void)r;
}

static int busy(pk_executor *e)
{
    return __atomic_load_n(&((local_exec *)e)->busy, __ATOMIC_RELAXED);
}

static int capacity(pk_executor *e)
{
    local_exec *s = (local_exec *)e;
    pthread_mutex_lock(&s->mu);
    int w = s->workers;
    pthread_mutex_unlock(&s->mu);
    return w;
}

static int healthy(pk_executor *e, char *why, size_t n) { return 1; }

static int unrecorded(pk_executor *e)
{
    return __atomic_load_n(&((local_exec *)e)->unrecorded, __ATOMIC_RELAXED);
}

static void stop(pk_executor *e, double grace_s)
{
    local_exec *s = (local_exec *)e;
    pthread_mutex_lock(&s->mu);
    if (s->stopping) {
        pthread_mutex_unlock(&s->mu);
        return;
    }
    s->stopping = 1;
    s->grace_deadline = pk_queue_now() + grace_s;
    pthread_mutex_unlock(&s->mu);
    wake(e);
    pthread_join(s->thread, NULL);
}

static void destroy(pk_executor *e)
{
    local_exec *s = (local_exec *)e;
    close(s->wake[0]);
    close(s->wake[1]);
    pthread_mutex_destroy(&s->mu);
    free(s);
}

static const pk_executor_ops local_ops = {"local", configure, wake,    busy, capacity,
                                          healthy, stop,      destroy, NULL, unrecorded};

pk_executor *pk_executor_local_start(pk_queue *q, const char *exe, const pk_config *c,
                                     int short_only)
{
    local_exec *s = calloc(1, sizeof *s);
    if (!s)
        return NULL;
    s->base.ops = &local_ops;
    s->q = q;
    s->short_only = short_only;
    snprintf(s->exe, sizeof s->exe, "%s", exe);
    snprintf(s->data, sizeof s->data, "%s", c->data);
    pthread_mutex_init(&s->mu, NULL);
    if (cloexec_pipe(s->wake, 1) != 0) {
        free(s);
        return NULL;
    }
    configure(&s->base, c);
    if (pthread_create(&s->thread, NULL, loop, s) != 0) {
        destroy(&s->base);
        return NULL;
    }
    return &s->base;
}
