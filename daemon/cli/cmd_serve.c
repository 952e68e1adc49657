/* cmd_serve.c — `packd serve`: the job service (docs/service.md).
 * Life cycle: configuration -> data directory lock -> queue (migrations,
 * recovery of jobs a dead daemon left running) -> executor thread -> HTTP
 * threads; the main thread then only waits for signals:
 *   SIGHUP           reload the configuration (all but bind/port/data)
 *   SIGTERM, SIGINT  refuse new jobs, give running ones grace_s, re-queue the
 *                    rest, stop. */
#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include "daemon/http/auth.h"
#include "cli.h"
#include "daemon/config.h"
#include "daemon/http/http.h"
#include "daemon/log.h"
#include "daemon/store/queue.h"
#include "daemon/sd_notify.h"
#include "daemon/executor.h"

static int usage(FILE *f)
{
    fprintf(
        f,
        "usage: packd serve [--config FILE] [--KEY VALUE]...\n"
        "Settings, lowest precedence first: defaults, config file (--config or $PACKD_CONFIG),\n"
        "environment PACKD_<KEY>, flags.  Keys (see deploy/packd.conf.example):\n");
    pk_config_print_keys(f);
    return f == stderr ? 64 : 0;
}

void cmd_serve_help(const char *name, FILE *f)
{
    (void)name;
    usage(f);
}

static int ensure_dir(const char *path)
{
    return mkdir(path, 0750) == 0 || errno == EEXIST ? 0 : -1;
}

/* Say plainly whether tokens are required, and why (at start and on reload). */
static void log_auth(pk_service *svc)
{
    pk_config cfg = pk_service_config(svc);
    const char *why;
    int on = pk_auth_required(&cfg, &why);
    pk_log(on ? PK_LOG_INFO : PK_LOG_WARN, on ? "auth is on" : "auth is off", "{s:s,s:s,s:s}",
           "why", why, "bind", cfg.bind, "trusted_proxy",
           cfg.trusted_proxy[0] ? cfg.trusted_proxy : "none");
    if (on && pk_tokens_count(svc->tokens) == 0)
        pk_log(PK_LOG_WARN, "no tokens yet: every request but the public ones gets 401", "{s:s}",
               "hint", "packd token add NAME --admin --data DATA");
}

static void reload(pk_service *svc, int argc, char **argv)
{
    pk_config next;
    char err[1200];
    if (pk_config_from_args(&next, argc, argv, err, sizeof err) != 0) {
        pk_log(PK_LOG_ERROR, "reload failed; keeping the configuration", "{s:s}", "error", err);
        return;
    }
    pthread_mutex_lock(&svc->mu);
    if (strcmp(next.bind, svc->cfg.bind) || next.port != svc->cfg.port ||
        strcmp(next.data, svc->cfg.data))
        pk_log(PK_LOG_WARN, "bind, port and data need a restart; kept", NULL);
    snprintf(next.bind, sizeof next.bind, "%s", svc->cfg.bind);
    next.port = svc->cfg.port;
    snprintf(next.data, sizeof next.data, "%s", svc->cfg.data);
    svc->cfg = next;
    pthread_mutex_unlock(&svc->mu);
    pk_log_set_level(next.log_level);
    if (next.executor != svc->cfg.executor)
        pk_log(PK_LOG_WARN, "executor needs a restart; kept", NULL);
    next.executor = svc->cfg.executor;
    pk_executor_configure(svc->exec, &next);
    log_auth(svc);
    pk_log(PK_LOG_INFO, "configuration reloaded", "{s:s,s:i,s:s}", "file", next.config_file,
           "workers", next.workers, "log_level", pk_log_level_name(next.log_level));
}

int cmd_serve(int argc, char **argv)
{
    static pk_service svc; /* shared with the HTTP and executor threads */
    char err[1200];
    int rc = pk_config_from_args(&svc.cfg, argc, argv, err, sizeof err);
    if (rc == 1)
        return usage(stdout);
    if (rc != 0) {
        fprintf(stderr, "packd serve: %s\n", err);
        return usage(stderr);
    }
    /* Every file the daemon and its workers create (queue database and its
     * WAL, job.json, results, logs, uploads) is 0640 at most, directories
     * 0750: a lab server's other accounts read none of it.  The workers
     * inherit the mask. */
    umask(027);
    pthread_mutex_init(&svc.mu, NULL);
    pk_log_set_level(svc.cfg.log_level);
    svc.started = pk_queue_now();

    char path[1200];
    snprintf(path, sizeof path, "%s/jobs", svc.cfg.data);
    if (ensure_dir(svc.cfg.data) != 0 || ensure_dir(path) != 0) {
        pk_log(PK_LOG_ERROR, "cannot create the data directory", "{s:s,s:s}", "data", svc.cfg.data,
               "error", strerror(errno));
        return 2;
    }
    /* One daemon per data directory: the queue's claims assume a single executor. */
    snprintf(path, sizeof path, "%s/packd.lock", svc.cfg.data);
    int lock = open(path, O_RDWR | O_CREAT | O_CLOEXEC, 0640);
    if (lock < 0 || flock(lock, LOCK_EX | LOCK_NB) != 0) {
        pk_log(PK_LOG_ERROR, "another packd serve uses this data directory", "{s:s}", "data",
               svc.cfg.data);
        return 2;
    }
    char exe[1024];
    ssize_t n = readlink("/proc/self/exe", exe, sizeof exe - 1);
    if (n <= 0) {
        pk_log(PK_LOG_ERROR, "cannot find the packd binary (/proc/self/exe)", NULL);
        return 2;
    }
    exe[n] = 0;
    snprintf(path, sizeof path, "%s/queue.db", svc.cfg.data);
    svc.q = pk_queue_open(path, err, sizeof err);
    if (!svc.q) {
        pk_log(PK_LOG_ERROR, "cannot open the queue database", "{s:s}", "error", err);
        return 2;
    }
    svc.tokens = pk_tokens_open(path, err, sizeof err);
    if (!svc.tokens) {
        pk_log(PK_LOG_ERROR, "cannot open the token store", "{s:s}", "error", err);
        pk_queue_close(svc.q);
        return 2;
    }
    /* Signals go to this thread only (sigwait below); threads inherit the mask. */
    sigset_t set;
    sigemptyset(&set);
    sigaddset(&set, SIGTERM);
    sigaddset(&set, SIGINT);
    sigaddset(&set, SIGHUP);
    pthread_sigmask(SIG_BLOCK, &set, NULL);
    signal(SIGPIPE, SIG_IGN);

    svc.exec = pk_executor_start(svc.q, exe, &svc.cfg, err, sizeof err);
    int port = 0;
    struct MHD_Daemon *http = svc.exec ? pk_http_start(&svc, &port, err, sizeof err) : NULL;
    if (!http) {
        pk_log(PK_LOG_ERROR, "cannot start", "{s:s}", "error", err);
        pk_executor_stop(svc.exec, 0);
        pk_executor_free(svc.exec);
        pk_tokens_close(svc.tokens);
        pk_queue_close(svc.q);
        return 2;
    }
    pk_log(PK_LOG_INFO, "listening", "{s:s,s:i,s:s,s:s,s:i,s:s,s:i}", "bind", svc.cfg.bind, "port",
           port, "data", svc.cfg.data, "executor", pk_executor_name(svc.exec), "workers",
           svc.cfg.workers, "version", PACKD_VERSION, "pid", (int)getpid());
    log_auth(&svc);
    pk_sd_notify("READY=1"); /* Type=notify: systemd starts dependants now */

    for (;;) {
        int sig = 0;
        if (sigwait(&set, &sig) != 0)
            continue;
        if (sig == SIGHUP) {
            pk_sd_notify("RELOADING=1");
            reload(&svc, argc, argv);
            pk_sd_notify("READY=1");
            continue;
        }
        break;
    }
    pk_config cfg = pk_service_config(&svc);
    pk_sd_notify("STOPPING=1");
    __atomic_store_n(&svc.draining, 1, __ATOMIC_RELAXED);
    pk_log(PK_LOG_INFO, "stopping: running jobs get the grace period", "{s:f,s:i}", "grace_s",
           cfg.grace_s, "running", pk_executor_busy(svc.exec));
    pk_executor_stop(svc.exec, cfg.grace_s);
    __atomic_store_n(&svc.stopping, 1, __ATOMIC_RELAXED);
    pk_queue_wake_all(svc.q);
    pk_http_stop(http);
    pk_executor_free(svc.exec);
    pk_tokens_close(svc.tokens);
    pk_queue_close(svc.q);
    close(lock);
    pk_log(PK_LOG_INFO, "stopped", NULL);
    return 0;
}
