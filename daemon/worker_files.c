/* worker_files.c — the job directory shared by the daemon and its workers;
 * contract in worker_files.h. */
#include "worker_files.h"

#include <arpa/inet.h>
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "api/digest.h"
#include "daemon/store/job_files.h"

const char *pk_worker_author(json_t *job)
{
    const char *own = json_string_value(json_object_get(job, "owner"));
    unsigned char addr[sizeof(struct in6_addr)];
    /* auth.c names a client without a token by its address ("unknown" when it has none) */
    if (!own || !strcmp(own, "unknown") || inet_pton(AF_INET, own, addr) == 1 ||
        inet_pton(AF_INET6, own, addr) == 1)
        return "";
    return own;
}

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

void pk_worker_remove_tmp(const char *dir)
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

int pk_worker_prepare(const char *dir, json_t *job, char *why, size_t n)
{
    char path[1300];
    if (mkdirs(dir) != 0) {
        snprintf(why, n, "cannot create the job directory: %s", strerror(errno));
        return -1;
    }
    pk_worker_remove_tmp(dir);
    pk_job_file_path(dir, PK_JOB_RESULT, path, sizeof path);
    unlink(path);
    pk_job_file_path(dir, PK_JOB_INPUT, path, sizeof path);
    json_t *file = json_pack("{s:O,s:O}", "process", json_object_get(job, "process"), "inputs",
                             json_object_get(job, "inputs"));
    int rc = file ? write_job_file(path, file) : -1;
    int saved = errno;
    json_decref(file);
    if (rc != 0)
        snprintf(why, n, "cannot write the job file: %s", strerror(saved));
    return rc;
}

int pk_worker_percent(json_t *p)
{
    double f = json_number_value(json_object_get(p, "fraction"));
    int percent = f >= 0 ? (int)(f * 100.0) : 0;
    percent = percent < 0 ? 0 : percent > 99 ? 99 : percent; /* 100 = successful */
    json_object_set_new(p, "progress", json_integer(percent));
    return percent;
}

void pk_worker_outcome_read(const char *dir, int code, pk_worker_outcome *o)
{
    char path[1300];
    memset(o, 0, sizeof *o);
    pk_job_file_path(dir, PK_JOB_SUMMARY, path, sizeof path);
    json_t *sum = json_load_file(path, 0, NULL);
    o->summary = sum ? json_dumps(sum, JSON_COMPACT | JSON_REAL_PRECISION(10)) : NULL;
    o->status = code == 0 ? "successful" : "failed";
    json_t *w = json_object_get(sum, "warnings");
    if (code != 0)
        snprintf(o->message, sizeof o->message, "failed: %s",
                 json_is_string(json_object_get(sum, "failure"))
                     ? json_string_value(json_object_get(sum, "failure"))
                     : "the job's own checks failed");
    else if (json_array_size(w))
        snprintf(o->message, sizeof o->message, "finished with %zu warning%s: %s",
                 json_array_size(w), json_array_size(w) > 1 ? "s" : "",
                 json_string_value(json_array_get(w, 0)));
    else
        snprintf(o->message, sizeof o->message, "finished");
    json_decref(sum);
    struct stat st;
    pk_job_file_path(dir, PK_JOB_RESULT, path, sizeof path);
    if (pk_sha256_file_hex(path, o->sha256) == 0 && stat(path, &st) == 0) {
        o->size = (long long)st.st_size;
    } else {
        o->sha256[0] = 0;
        o->status = "failed";
        snprintf(o->message, sizeof o->message, "the worker wrote no result file");
    }
}

void pk_worker_last_line(const char *path, char *out, size_t n)
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
