/* supervisor.c — the worker processes: claim a job, fork and exec `packd run`
 * in its directory, relay progress, enforce wall time and cancels, record the
 * end; contract in supervisor.h. */
#include "supervisor.h"

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
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "log.h"
#include "api/digest.h"
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
} slot;

struct pk_supervisor {
    pk_queue *q;
    char exe[1024], data[1024];
    pthread_t thread;
    pthread_mutex_t mu;
    int workers;
    double max_wall_time_s;
    int job_threads; /* --threads of each worker */
    double checkpoint_interval_s;
    int stopping;
    double grace_deadline;
    int wake[2];
    int busy;
    slot slots[MAX_SLOTS];
};

static int mkdirs(const char *path)
{
    char tmp[1200];
    snprintf(tmp, sizeof tmp, "%s", path);
    for (char *p = tmp + 1; *p; p++)
        if (*p == '/') {
            *p = 0;
            if (mkdir(tmp, 0750) != 0 && errno != EEXIST)
                return -1;
            *p = '/';
        }
    return mkdir(tmp, 0750) != 0 && errno != EEXIST ? -1 : 0;
}

/* Leftover temporary result files of an interrupted run. */
static void remove_tmp_files(const char *dir)
{
    DIR *d = opendir(dir);
    if (!d)
        return;
    struct dirent *e;
    while ((e = readdir(d)))
        if (strstr(e->d_name, ".tmp")) {
            char p[1400];
            if (snprintf(p, sizeof p, "%s/%s", dir, e->d_name) < (int)sizeof p)
                unlink(p);
        }
    closedir(d);
}

/* job.json by temp file and rename: 0, or -1 with errno (no temp file left). */
static int write_job_file(const char *path, json_t *job)
{
    char tmp[1300];
    if (snprintf(tmp, sizeof tmp, "%s.tmp", path) >= (int)sizeof tmp) {
        errno = ENAMETOOLONG;
        return -1;
    }
    char *text = json_dumps(job, JSON_INDENT(2) | JSON_SORT_KEYS);
    if (!text) {
        errno = ENOMEM;
        return -1;
    }
    size_t n = strlen(text), off = 0;
    int fd = open(tmp, O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0640), rc = fd < 0 ? -1 : 0;
    while (rc == 0 && off < n) {
        ssize_t w = write(fd, text + off, n - off);
        if (w > 0)
            off += (size_t)w;
        else if (!(w < 0 && errno == EINTR))
            rc = -1;
    }
    int saved = errno;
    if (fd >= 0 && close(fd) != 0 && rc == 0) {
        rc = -1;
        saved = errno;
    }
    free(text);
    if (rc == 0 && rename(tmp, path) != 0) {
        rc = -1;
        saved = errno;
    }
    if (rc != 0) {
        unlink(tmp);
        errno = saved;
    }
    return rc;
}

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

static int launch(pk_supervisor *s, slot *sl, json_t *job)
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
    if (mkdirs(dir) != 0) {
        snprintf(why, sizeof why, "cannot create the job directory: %s", strerror(errno));
        pk_queue_finish(s->q, id, "failed", why, NULL, NULL, 0);
        return -1;
    }
    remove_tmp_files(dir);
    unlink(out_path);
    json_t *file = json_pack("{s:O,s:O}", "process", json_object_get(job, "process"), "inputs",
                             json_object_get(job, "inputs"));
    int wrote = write_job_file(job_path, file);
    int wrote_errno = errno;
    json_decref(file);
    char threads[16], interval[32], owner[128];
    /* the job's owner is its result's /h5md/author */
    const char *own = json_string_value(json_object_get(job, "owner"));
    snprintf(owner, sizeof owner, "%s", own ? own : "packd");
    pthread_mutex_lock(&s->mu);
    snprintf(threads, sizeof threads, "%d", s->job_threads);
    snprintf(interval, sizeof interval, "%g",
             s->checkpoint_interval_s > 0 ? s->checkpoint_interval_s : 30);
    pthread_mutex_unlock(&s->mu);
    int p[2];
    if (wrote != 0 || cloexec_pipe(p, 0) != 0) {
        snprintf(why, sizeof why, "cannot write the job file: %s",
                 strerror(wrote != 0 ? wrote_errno : errno));
        pk_queue_finish(s->q, id, "failed", why, NULL, NULL, 0);
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

static void relay_line(pk_supervisor *s, slot *sl, const char *line)
{
    json_t *p = json_loads(line, 0, NULL);
    if (!json_is_object(p)) {
        json_decref(p);
        return;
    }
    double f = json_number_value(json_object_get(p, "fraction"));
    int percent = f >= 0 ? (int)(f * 100.0) : 0;
    percent = percent < 0 ? 0 : percent > 99 ? 99 : percent; /* 100 = successful */
    json_object_set_new(p, "progress", json_integer(percent));
    pk_queue_progress(s->q, sl->id, percent, p);
    json_decref(p);
}

static void drain(pk_supervisor *s, slot *sl)
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

/* Last non-empty line of the worker's stderr, for `message`. */
static void last_log_line(const char *path, char *out, size_t n)
{
    out[0] = 0;
    FILE *f = fopen(path, "r");
    if (!f)
        return;
    char line[1024];
    while (fgets(line, sizeof line, f)) {
        line[strcspn(line, "\n")] = 0;
        if (line[0])
            snprintf(out, n, "%s", line);
    }
    fclose(f);
}

static void finished(pk_supervisor *s, slot *sl, int wstatus)
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
        pk_job_file_path(dir, PK_JOB_SUMMARY, path, sizeof path);
        json_t *sum = json_load_file(path, 0, NULL);
        char *text = sum ? json_dumps(sum, JSON_COMPACT | JSON_REAL_PRECISION(10)) : NULL;
        const char *status = code == 0 ? "successful" : "failed";
        json_t *w = json_object_get(sum, "warnings");
        if (code == 3)
            snprintf(msg, sizeof msg, "failed: %s",
                     json_is_string(json_object_get(sum, "failure"))
                         ? json_string_value(json_object_get(sum, "failure"))
                         : "the job's own checks failed");
        else if (json_array_size(w))
            snprintf(msg, sizeof msg, "finished with %zu warning%s: %s", json_array_size(w),
                     json_array_size(w) > 1 ? "s" : "", json_string_value(json_array_get(w, 0)));
        else
            snprintf(msg, sizeof msg, "finished");
        json_decref(sum);
        char hex[65];
        struct stat st;
        pk_job_file_path(dir, PK_JOB_RESULT, path, sizeof path);
        if (pk_sha256_file_hex(path, hex) == 0 && stat(path, &st) == 0)
            ended = pk_queue_finish(s->q, sl->id, status, msg, text, hex, (long long)st.st_size);
        else
            ended = pk_queue_finish(s->q, sl->id, "failed", "the worker wrote no result file", text,
                                    NULL, 0);
        free(text);
    } else {
        pk_job_file_path(dir, PK_JOB_LOG, path, sizeof path);
        last_log_line(path, tail, sizeof tail);
        if (sl->killed_for_time)
            snprintf(msg, sizeof msg, "worker killed: wall time exceeded");
        else if (WIFSIGNALED(wstatus))
            snprintf(msg, sizeof msg, "worker killed by signal %d (%s)", WTERMSIG(wstatus),
                     strsignal(WTERMSIG(wstatus)));
        else
            snprintf(msg, sizeof msg, "worker exited with status %d%s%s", WEXITSTATUS(wstatus),
                     tail[0] ? ": " : "", tail);
        ended = pk_queue_finish(s->q, sl->id, "failed", msg, NULL, NULL, 0);
    }
    if (!strcmp(ended, "dismissed")) { /* nobody will download it */
        remove_tmp_files(dir);
        pk_job_file_path(dir, PK_JOB_RESULT, path, sizeof path);
        unlink(path);
    }
    pk_log(ended[0] == 'f' ? PK_LOG_WARN : PK_LOG_INFO, "worker ended", "{s:s,s:i,s:s,s:i,s:f}",
           "job", sl->id, "pid", (int)sl->pid, "status", ended, "wait_status", wstatus, "seconds",
           pk_queue_now() - sl->started);
    sl->pid = 0;
    __atomic_sub_fetch(&s->busy, 1, __ATOMIC_RELAXED);
}

static void send_cancels(pk_supervisor *s)
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

static void enforce_wall_time(pk_supervisor *s, double max_wall)
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
    pk_supervisor *s = arg;
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
            if (s->slots[k].pid)
                continue;
            json_t *job = pk_queue_claim(s->q);
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
        send_cancels(s);
        enforce_wall_time(s, max_wall);
    }
    return NULL;
}

pk_supervisor *pk_supervisor_start(pk_queue *q, const char *exe, const char *data, int workers,
                                   double max_wall_time_s, int job_threads)
{
    pk_supervisor *s = calloc(1, sizeof *s);
    if (!s)
        return NULL;
    s->q = q;
    snprintf(s->exe, sizeof s->exe, "%s", exe);
    snprintf(s->data, sizeof s->data, "%s", data);
    s->workers = workers > MAX_SLOTS ? MAX_SLOTS : workers;
    s->max_wall_time_s = max_wall_time_s;
    s->job_threads = job_threads;
    pthread_mutex_init(&s->mu, NULL);
    if (cloexec_pipe(s->wake, 1) != 0 || pthread_create(&s->thread, NULL, loop, s) != 0) {
        free(s);
        return NULL;
    }
    return s;
}

void pk_supervisor_configure(pk_supervisor *s, int workers, double max_wall_time_s, int job_threads)
{
    pthread_mutex_lock(&s->mu);
    s->workers = workers > MAX_SLOTS ? MAX_SLOTS : workers;
    s->max_wall_time_s = max_wall_time_s;
    s->job_threads = job_threads;
    pthread_mutex_unlock(&s->mu);
    pk_supervisor_wake(s);
}

void pk_supervisor_set_checkpoint_interval(pk_supervisor *s, double seconds)
{
    pthread_mutex_lock(&s->mu);
    s->checkpoint_interval_s = seconds;
    pthread_mutex_unlock(&s->mu);
}

void pk_supervisor_wake(pk_supervisor *s)
{
    if (s) {
        ssize_t r = write(s->wake[1], "w", 1);
        (void)r;
    }
}

int pk_supervisor_busy(const pk_supervisor *s)
{
    return __atomic_load_n(&s->busy, __ATOMIC_RELAXED);
}

int pk_supervisor_capacity(const pk_supervisor *s)
{
    pk_supervisor *m = (pk_supervisor *)s;
    pthread_mutex_lock(&m->mu);
    int w = m->workers;
    pthread_mutex_unlock(&m->mu);
    return w;
}

void pk_supervisor_stop(pk_supervisor *s, double grace_s)
{
    if (!s)
        return;
    pthread_mutex_lock(&s->mu);
    s->stopping = 1;
    s->grace_deadline = pk_queue_now() + grace_s;
    pthread_mutex_unlock(&s->mu);
    pk_supervisor_wake(s);
    pthread_join(s->thread, NULL);
}

void pk_supervisor_free(pk_supervisor *s)
{
    if (!s)
        return;
    close(s->wake[0]);
    close(s->wake[1]);
    pthread_mutex_destroy(&s->mu);
    free(s);
}
