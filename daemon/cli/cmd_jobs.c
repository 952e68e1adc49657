/* cmd_jobs.c — the client commands on existing jobs: `packd jobs` (list),
 * `packd cancel ID` (DELETE /jobs/{id}) and `packd fetch ID -o OUT.h5`
 * (download the result and verify its SHA-256). */
#include <stdio.h>
#include <string.h>

#include "cli.h"
#include "client_args.h"
#include "client_job.h"

int cmd_jobs(int argc, char **argv)
{
    pk_client_args a;
    int rc = pk_client_parse(argc, argv, &a);
    if (rc)
        return rc;
    pk_client c = {.server = a.server, .token = a.token};
    /* both go into the query string as they are */
    if (strspn(a.limit, "0123456789") != strlen(a.limit) ||
        (a.status && strspn(a.status, "abcdefghijklmnopqrstuvwxyz,") != strlen(a.status))) {
        fprintf(stderr, "packd jobs: --limit takes a number, --status a status name\n");
        return 64;
    }
    char path[400];
    snprintf(path, sizeof path, "/jobs?limit=%s%s%.100s", a.limit, a.status ? "&status=" : "",
             a.status ? a.status : "");
    pk_reply r;
    if (pk_client_request(&c, "GET", path, NULL, &r) != 0 || r.status != 200) {
        rc = pk_client_report("jobs", &r);
        pk_reply_free(&r);
        return rc;
    }
    json_t *doc = pk_reply_json(&r);
    pk_reply_free(&r);
    if (a.json) {
        json_dumpf(doc, stdout, JSON_INDENT(2));
        putchar('\n');
    } else {
        printf("%-36s  %-10s  %-10s  %4s  %-24s  %s\n", "JOB", "PROCESS", "STATUS", "%", "CREATED",
               "MESSAGE");
        size_t i;
        json_t *j;
        json_array_foreach (json_object_get(doc, "jobs"), i, j)
            printf("%-36s  %-10s  %-10s  %4lld  %-24s  %s\n", pk_doc_str(j, "jobID"),
                   pk_doc_str(j, "processID"), pk_doc_str(j, "status"),
                   (long long)json_integer_value(json_object_get(j, "progress")),
                   pk_doc_str(j, "created"), pk_doc_str(j, "message"));
        json_t *n = json_object_get(doc, "numberMatched");
        if (json_is_integer(n) &&
            (size_t)json_integer_value(n) > json_array_size(json_object_get(doc, "jobs")))
            printf("(%zu of %lld jobs; --limit N for more)\n",
                   json_array_size(json_object_get(doc, "jobs")), (long long)json_integer_value(n));
    }
    json_decref(doc);
    return 0;
}

int cmd_cancel(int argc, char **argv)
{
    pk_client_args a;
    int rc = pk_client_parse(argc, argv, &a);
    if (rc)
        return rc;
    pk_client c = {.server = a.server, .token = a.token};
    char path[300];
    snprintf(path, sizeof path, "/jobs/%s", a.arg);
    pk_reply r;
    if (pk_client_request(&c, "DELETE", path, NULL, &r) != 0 || r.status != 200) {
        rc = pk_client_report("cancel", &r);
        pk_reply_free(&r);
        return rc;
    }
    fwrite(r.body, 1, r.len, stdout);
    pk_reply_free(&r);
    return 0;
}

int cmd_fetch(int argc, char **argv)
{
    pk_client_args a;
    int rc = pk_client_parse(argc, argv, &a);
    if (rc)
        return rc;
    pk_client c = {.server = a.server, .token = a.token};
    json_t *info = NULL;
    rc = pk_client_fetch(&c, a.arg, a.output, &info);
    if (rc == 0 || json_object_get(info, "output")) {
        json_object_set_new(info, "jobID", json_string(a.arg));
        json_dumpf(info, stdout, JSON_INDENT(2) | JSON_REAL_PRECISION(10));
        putchar('\n');
    }
    json_decref(info);
    return rc;
}
