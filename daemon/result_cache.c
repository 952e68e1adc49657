/* result_cache.c — contract in result_cache.h. */
#include "result_cache.h"

#include <errno.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "api/digest.h"
#include "daemon/store/job_files.h"

static char build[65];
static pthread_once_t build_once = PTHREAD_ONCE_INIT;

static void hash_build(void)
{
    if (pk_sha256_file_hex("/proc/self/exe", build) != 0)
        build[0] = 0; /* unknown build: nothing is reused */
}

static int names_a_file(json_t *v)
{
    const char *k;
    json_t *e;
    size_t i;
    if (json_is_object(v)) {
        if (json_object_get(v, "file"))
            return 1;
        json_object_foreach (v, k, e)
            if (names_a_file(e))
                return 1;
    } else if (json_is_array(v)) {
        json_array_foreach (v, i, e)
            if (names_a_file(e))
                return 1;
    }
    return 0;
}

int pk_result_cache_key(const char *process, json_t *inputs, char key[65])
{
    pthread_once(&build_once, hash_build);
    key[0] = 0;
    if (!build[0] || names_a_file(inputs))
        return -1;
    char *text = json_dumps(inputs, JSON_COMPACT | JSON_SORT_KEYS);
    char *src = NULL;
    size_t n = 0;
    FILE *f = text ? open_memstream(&src, &n) : NULL;
    if (f) {
        fprintf(f, "%s\n%s\n%s", build, process, text);
        fclose(f);
    }
    int rc = src ? pk_sha256_hex(src, n, key) : -1;
    free(src);
    free(text);
    return rc;
}

static const pk_job_file linked[] = {PK_JOB_INPUT, PK_JOB_RESULT, PK_JOB_XDMF, PK_JOB_SUMMARY};

void pk_result_cache_unlink(const char *data, const char *dst)
{
    char dir[1200], path[1300];
    if (pk_job_dir(data, dst, dir, sizeof dir) != 0)
        return;
    for (size_t i = 0; i < sizeof linked / sizeof *linked; i++)
        if (pk_job_file_path(dir, linked[i], path, sizeof path) == 0)
            unlink(path);
}

int pk_result_cache_link(const char *data, const char *src, const char *dst)
{
    char from_dir[1200], to_dir[1200], jobs[1300], from[1300], to[1300];
    if (pk_job_dir(data, src, from_dir, sizeof from_dir) != 0 ||
        pk_job_dir(data, dst, to_dir, sizeof to_dir) != 0)
        return -1;
    snprintf(jobs, sizeof jobs, "%s/jobs", data);
    mkdir(jobs, 0750);
    if (mkdir(to_dir, 0750) != 0 && errno != EEXIST)
        return -1;
    for (size_t i = 0; i < sizeof linked / sizeof *linked; i++) {
        pk_job_file_path(from_dir, linked[i], from, sizeof from);
        pk_job_file_path(to_dir, linked[i], to, sizeof to);
        /* a job without an XDMF sidecar has none to give; the rest must be there */
        if (link(from, to) != 0 && !(errno == ENOENT && linked[i] == PK_JOB_XDMF)) {
            pk_result_cache_unlink(data, dst);
            return -1;
        }
    }
    return 0;
}
