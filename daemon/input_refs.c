/* input_refs.c — resolve an input's {"href"} links to files of the data
 * directory; contract in input_refs.h. */
#include "input_refs.h"

#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "api/inputs/input_links.h"
#include "daemon/store/job_files.h"

static int all_hex(const char *s, size_t n)
{
    for (size_t i = 0; i < n; i++)
        if (!((s[i] >= '0' && s[i] <= '9') || (s[i] >= 'a' && s[i] <= 'f')))
            return 0;
    return s[n] == 0;
}

/* The path a link stands for, or an error message. */
static int resolve_one(const char *href, const char *data, pk_queue *q, const char *owner,
                       char *path, size_t n, char *why, size_t wn)
{
    const char *files = "/files/", *jobs = "/jobs/", *tail = "/results/result";
    if (!strncmp(href, files, strlen(files))) {
        const char *id = href + strlen(files);
        json_t *f = all_hex(id, 64) ? pk_queue_get_file(q, id, owner) : NULL;
        if (!f) {
            snprintf(why, wn, "no uploaded file %s (POST /files first)", href);
            return -1;
        }
        json_decref(f);
        snprintf(path, n, "%s/files/%s", data, id);
        return 0;
    }
    size_t hl = strlen(href), tl = strlen(tail);
    if (!strncmp(href, jobs, strlen(jobs)) && hl > strlen(jobs) + tl &&
        !strcmp(href + hl - tl, tail)) {
        char id[64];
        size_t il = hl - strlen(jobs) - tl;
        if (il >= sizeof id) {
            snprintf(why, wn, "no job in %s", href);
            return -1;
        }
        memcpy(id, href + strlen(jobs), il);
        id[il] = 0;
        json_t *row = pk_queue_get(q, id);
        if (row && owner && strcmp(json_string_value(json_object_get(row, "owner")), owner) != 0) {
            json_decref(row); /* another owner's job: as if it did not exist */
            row = NULL;
        }
        const char *st = json_string_value(json_object_get(row, "status"));
        if (!row || strcmp(st, "successful") != 0) {
            snprintf(why, wn, "%s: the job %s", href,
                     row ? "has no result yet (not successful)" : "does not exist");
            json_decref(row);
            return -1;
        }
        json_decref(row);
        char dir[1200];
        pk_job_dir(data, id, dir, sizeof dir);
        pk_job_file_path(dir, PK_JOB_RESULT, path, n);
        return 0;
    }
    snprintf(why, wn, "links must be /files/<id> or /jobs/<id>/results/result (got %s)", href);
    return -1;
}

typedef struct {
    const char *data;
    pk_queue *q;
    const char *owner;
    pk_schema_errors *errs;
} resolve_ctx;

static void resolve_link(json_t *link, const char *href, const char *pointer, void *vctx)
{
    resolve_ctx *c = vctx;
    char path[1400], why[400], ptr[300];
    if (resolve_one(href, c->data, c->q, c->owner, path, sizeof path, why, sizeof why)) {
        snprintf(ptr, sizeof ptr, "%s/href", pointer);
        pk_schema_errors_add(c->errs, ptr, "href", "%s", why);
        return;
    }
    json_object_del(link, "href");
    json_object_set_new(link, "file", json_string(path));
}

size_t pk_resolve_input_refs(json_t *inputs, const char *data_dir, pk_queue *q, const char *owner,
                             pk_schema_errors *errs)
{
    size_t before = errs->n;
    resolve_ctx c = {data_dir, q, owner, errs};
    pk_input_links_each(inputs, resolve_link, &c);
    return errs->n - before;
}
