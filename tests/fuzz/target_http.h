/* target_http.h — the 'http' fuzz target: whole HTTP requests into the
 * running service.  One daemon per process, started at the first input the
 * way `packd serve` starts it (queue and token store on a scratch data
 * directory, the local executor with no workers, the libmicrohttpd listener on
 * 127.0.0.1), so the request meets every layer a client's does: the HTTP
 * parser, the connection guard, Host and auth checks, the route table, the
 * handlers, the queue, the replies.
 *
 * An input is a request in a line format the harness frames:
 *   [!]METHOD PATH          ("!" first: this request with auth = on)
 *   Name: value             (headers, one a line, up to an empty line)
 *   body...                 (the rest, sent with its Content-Length)
 * CR and NUL are dropped from the head, and Content-Length,
 * Transfer-Encoding and Connection headers given by the input are left out:
 * the harness sends "Connection: close" and the body's length, so every
 * request is complete and the answer ends with the connection.  No answer
 * within 8 s, or an answer that is no HTTP status line, is a finding
 * (abort); PK_FUZZ_HTTP_ECHO=1 prints each status line.  The daemon's threads run in this process: a sanitizer report
 * in any of them ends the run.  Kept apart from targets.h: it links the
 * daemon (tests/unit and build-fuzz link daemon/ too). */
#ifndef PK_FUZZ_TARGET_HTTP_H
#define PK_FUZZ_TARGET_HTTP_H

#include <arpa/inet.h>
#include <dirent.h>
#include <errno.h>
#include <netinet/in.h>
#include <poll.h>
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "daemon/executor.h"
#include "daemon/http/http.h"
#include "daemon/log.h"
#include "daemon/service.h"

#define FUZZ_HTTP_ANSWER_S 8

static struct {
    pk_service svc;
    int port;
    char data[64];
} fuzz_http_state;

/* Remove path and what is below it (no symlink followed). */
static inline void fuzz_http_rm(const char *path)
{
    struct stat st;
    if (lstat(path, &st) == 0 && S_ISDIR(st.st_mode)) {
        DIR *d = opendir(path);
        struct dirent *e;
        while (d && (e = readdir(d)))
            if (strcmp(e->d_name, ".") && strcmp(e->d_name, "..")) {
                char sub[1200];
                if (snprintf(sub, sizeof sub, "%s/%s", path, e->d_name) < (int)sizeof sub)
                    fuzz_http_rm(sub);
            }
        if (d)
            closedir(d);
    }
    remove(path);
}

/* The scratch data directory goes at exit (the daemon's threads still run). */
static inline void fuzz_http_cleanup(void) { fuzz_http_rm(fuzz_http_state.data); }

static inline void fuzz_http_start(void)
{
    pk_service *svc = &fuzz_http_state.svc;
    char err[1200];
    snprintf(fuzz_http_state.data, sizeof fuzz_http_state.data, "/tmp/packd-fuzz-http.XXXXXX");
    if (!mkdtemp(fuzz_http_state.data)) {
        perror("mkdtemp");
        abort();
    }
    atexit(fuzz_http_cleanup);
    pthread_mutex_init(&svc->mu, NULL);
    pk_config_defaults(&svc->cfg);
    snprintf(svc->cfg.data, sizeof svc->cfg.data, "%s", fuzz_http_state.data);
    snprintf(svc->cfg.bind, sizeof svc->cfg.bind, "127.0.0.1");
    svc->cfg.port = 0;
    svc->cfg.workers = 0;
    svc->cfg.sync_wait_s = 0.2; /* a synchronous execution waits for no worker */
    svc->cfg.log_level = PK_LOG_ERROR;
    pk_log_set_level(PK_LOG_ERROR);
    char path[1200];
    snprintf(path, sizeof path, "%s/jobs", svc->cfg.data);
    mkdir(path, 0750);
    snprintf(path, sizeof path, "%s/queue.db", svc->cfg.data);
    svc->q = pk_queue_open(path, err, sizeof err);
    svc->tokens = svc->q ? pk_tokens_open(path, err, sizeof err) : NULL;
    signal(SIGPIPE, SIG_IGN);
    svc->exec =
        svc->tokens ? pk_executor_start(svc->q, "/bin/false", &svc->cfg, err, sizeof err) : NULL;
    svc->started = pk_queue_now();
    if (!svc->exec || !pk_http_start(svc, &fuzz_http_state.port, err, sizeof err)) {
        fprintf(stderr, "fuzz_http: cannot start the service: %s\n", err);
        abort();
    }
}

/* Whether a head line names a header the harness sets itself. */
static inline int fuzz_http_framing(const char *line, size_t n)
{
    static const char *const own[] = {"content-length:", "transfer-encoding:", "connection:"};
    for (size_t i = 0; i < sizeof own / sizeof *own; i++)
        if (n >= strlen(own[i]) && !strncasecmp(line, own[i], strlen(own[i])))
            return 1;
    return 0;
}

static inline void fuzz_http(const uint8_t *data, size_t size)
{
    if (!fuzz_http_state.port)
        fuzz_http_start();
    /* the head: lines up to an empty one, CR and NUL dropped */
    size_t i = 0;
    int auth_on = size > 0 && data[0] == '!';
    i += (size_t)auth_on;
    char *req = malloc(2 * size + 256);
    if (!req)
        return;
    size_t n = 0, line_start = 0;
    int first = 1;
    while (i < size) {
        size_t e = i;
        while (e < size && data[e] != '\n')
            e++;
        if (e == i && !first) { /* the empty line: the body follows */
            i = e + 1;
            break;
        }
        line_start = n;
        for (size_t k = i; k < e; k++)
            if (data[k] != '\r' && data[k] != 0)
                req[n++] = (char)data[k];
        if (!first && fuzz_http_framing(req + line_start, n - line_start))
            n = line_start;
        else
            req[n++] = '\r', req[n++] = '\n';
        first = 0;
        i = e + 1;
    }
    if (first) { /* no request line at all */
        free(req);
        return;
    }
    size_t body = i < size ? size - i : 0;
    n += (size_t)sprintf(req + n, "Connection: close\r\nContent-Length: %zu\r\n\r\n", body);
    memcpy(req + n, data + size - body, body);
    n += body;

    pthread_mutex_lock(&fuzz_http_state.svc.mu);
    fuzz_http_state.svc.cfg.auth = auth_on ? PK_AUTH_ON : PK_AUTH_AUTO;
    pthread_mutex_unlock(&fuzz_http_state.svc.mu);

    int s = socket(AF_INET, SOCK_STREAM, 0);
    struct sockaddr_in a = {.sin_family = AF_INET,
                            .sin_port = htons((uint16_t)fuzz_http_state.port)};
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (s < 0 || connect(s, (struct sockaddr *)&a, sizeof a) != 0) {
        perror("fuzz_http: connect");
        abort();
    }
    for (size_t off = 0; off < n;) { /* the daemon may answer and close before the body is in */
        ssize_t w = send(s, req + off, n - off, MSG_NOSIGNAL);
        if (w <= 0)
            break;
        off += (size_t)w;
    }
    free(req);
    char head[16] = {0}, buf[65536];
    size_t got = 0;
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    for (;;) {
        struct pollfd p = {.fd = s, .events = POLLIN};
        clock_gettime(CLOCK_MONOTONIC, &t1);
        double left = FUZZ_HTTP_ANSWER_S - (double)(t1.tv_sec - t0.tv_sec) -
            1e-9 * (double)(t1.tv_nsec - t0.tv_nsec);
        int ready = left > 0 ? poll(&p, 1, (int)(left * 1000) + 1) : 0;
        if (ready < 0 && errno == EINTR) /* libFuzzer's -timeout alarm */
            continue;
        if (ready <= 0) {
            fprintf(stderr, "fuzz_http: no complete answer within %d s\n", FUZZ_HTTP_ANSWER_S);
            if (getenv("PK_FUZZ_HTTP_HOLD")) /* leave the process to a debugger */
                sleep(600);
            abort();
        }
        ssize_t r = recv(s, buf, sizeof buf, 0);
        if (r <= 0)
            break;
        for (ssize_t k = 0; k < r && got < sizeof head - 1; k++)
            head[got++] = buf[k];
    }
    close(s);
    if (getenv("PK_FUZZ_HTTP_ECHO")) /* which answer each input got */
        fprintf(stderr, "fuzz_http: %.12s\n", got ? head : "(closed)");
    /* a connection the daemon reset without a word is fine only for a head
     * it could not parse; an answer is "HTTP/1.x NNN" */
    if (got &&
        (strncmp(head, "HTTP/1.", 7) != 0 || head[8] != ' ' || head[9] < '1' || head[9] > '5')) {
        fprintf(stderr, "fuzz_http: not an HTTP answer: %.15s\n", head);
        abort();
    }
}

#endif
