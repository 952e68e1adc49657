/* input_hint.c — the pack job that makes a missing RVE.  Contract:
 * daemon/cli/input_hint.h. */
#include "input_hint.h"

#include <dirent.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static const json_t *at_pointer(const json_t *j, const char *pointer)
{
    char buf[256];
    snprintf(buf, sizeof buf, "%s", pointer);
    char *save = NULL;
    for (char *key = strtok_r(buf, "/", &save); j && key; key = strtok_r(NULL, "/", &save))
        j = json_object_get(j, key);
    return j;
}

static int by_name(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

/* The *.json files of dir that are pack jobs, sorted; their count. */
static size_t pack_jobs(const char *dir, char ***out)
{
    *out = NULL;
    DIR *d = opendir(dir);
    if (!d)
        return 0;
    size_t n = 0;
    struct dirent *e;
    while ((e = readdir(d))) {
        size_t len = strlen(e->d_name);
        if (len < 6 || strcmp(e->d_name + len - 5, ".json") != 0)
            continue;
        char path[4096];
        if (snprintf(path, sizeof path, "%s/%s", dir, e->d_name) >= (int)sizeof path)
            continue;
        json_t *job = json_load_file(path, 0, NULL);
        const char *process = json_string_value(json_object_get(job, "process"));
        int pack = process && !strcmp(process, "pack");
        json_decref(job);
        if (!pack)
            continue;
        char **grown = realloc(*out, (n + 1) * sizeof *grown);
        if (!grown)
            break;
        *out = grown;
        if ((grown[n] = strdup(e->d_name)))
            n++;
    }
    closedir(d);
    if (n)
        qsort(*out, n, sizeof **out, by_name);
    return n;
}

void cli_hint_missing_inputs(FILE *f, const char *job_path, const json_t *job,
                             const pk_schema_errors *errs)
{
    for (size_t i = 0; i < errs->n; i++) {
        const pk_schema_error *e = &errs->items[i];
        size_t len = strlen(e->pointer);
        if (strcmp(e->rule, "rve") != 0 || len < 9 || strcmp(e->pointer + len - 9, "/rve/file"))
            continue;
        const char *file = json_string_value(at_pointer(job, e->pointer));
        if (!file || access(file, F_OK) == 0)
            continue; /* there, but unreadable: the error says why */
        char dir[4096] = ".";
        const char *slash = strrchr(job_path, '/');
        if (slash)
            snprintf(dir, sizeof dir, "%.*s", (int)(slash - job_path), job_path);
        char **names = NULL;
        size_t n = strcmp(job_path, "-") ? pack_jobs(*dir ? dir : "/", &names) : 0;
        const char *prefix = slash ? dir : "", *sep = slash ? "/" : "";
        if (n == 1)
            fprintf(f,
                    "packd: %s is the result of a pack job: run %s%s%s first: packd run "
                    "%s%s%s -o %s\n",
                    file, prefix, sep, names[0], prefix, sep, names[0], file);
        else if (n > 1) {
            fprintf(f, "packd: %s is the result of a pack job", file);
            for (size_t k = 0; k < n; k++)
                fprintf(f, "%s%s%s%s", k ? ", " : " (one of ", prefix, sep, names[k]);
            fprintf(f, "): run it first: packd run PACK_JOB.json -o %s\n", file);
        }
        for (size_t k = 0; k < n; k++)
            free(names[k]);
        free(names);
    }
}
