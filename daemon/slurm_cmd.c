/* slurm_cmd.c — Slurm client commands without a shell; contract in slurm_cmd.h. */
#include "slurm_cmd.h"

#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <string.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

static double mono(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + ts.tv_nsec * 1e-9;
}

int pk_slurm_cmd(const char *const argv[], char *out, size_t n, double timeout_s)
{
    out[0] = 0;
    int p[2];
    if (pipe(p) != 0)
        return -1;
    fcntl(p[0], F_SETFD, FD_CLOEXEC);
    pid_t pid = fork();
    if (pid == 0) { /* async-signal-safe calls only until exec */
        int dn = open("/dev/null", O_RDONLY);
        if (dn < 0 || dup2(dn, 0) < 0 || dup2(p[1], 1) < 0 || dup2(p[1], 2) < 0)
            _exit(127);
        sigset_t none;
        sigemptyset(&none);
        sigprocmask(SIG_SETMASK, &none, NULL);
        execvp(argv[0], (char *const *)argv);
        _exit(127);
    }
    close(p[1]);
    if (pid < 0) {
        close(p[0]);
        return -1;
    }
    size_t len = 0;
    double deadline = mono() + timeout_s;
    int killed = 0;
    for (;;) {
        int left = (int)((deadline - mono()) * 1000);
        if (left <= 0) {
            kill(pid, SIGKILL);
            killed = 1;
            break;
        }
        struct pollfd pf = {p[0], POLLIN, 0};
        int r = poll(&pf, 1, left);
        if (r < 0 && errno == EINTR)
            continue;
        if (r <= 0)
            continue;
        char buf[4096];
        ssize_t k = read(p[0], buf, sizeof buf);
        if (k <= 0)
            break;
        size_t room = n - 1 - len, take = (size_t)k < room ? (size_t)k : room;
        memcpy(out + len, buf, take);
        len += take;
    }
    out[len] = 0;
    close(p[0]);
    int ws;
    while (waitpid(pid, &ws, 0) < 0 && errno == EINTR)
        ;
    if (killed || !WIFEXITED(ws))
        return -1;
    return WEXITSTATUS(ws);
}

int pk_slurm_unreachable(const char *t)
{
    static const char *const signs[] = {"Unable to contact slurm controller",
                                        "Socket timed out",
                                        "Connection refused",
                                        "Transport endpoint is not connected",
                                        "slurm_load_jobs error",
                                        "Zero Bytes were transmitted",
                                        NULL};
    for (int i = 0; signs[i]; i++)
        if (strstr(t, signs[i]))
            return 1;
    return 0;
}
