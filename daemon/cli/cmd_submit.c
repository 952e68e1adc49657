/* cmd_submit.c — `packd submit JOB.json [--wait] [-o OUT.h5]`: POST the job
 * file's inputs to /processes/{process}/execution; with --wait follow the job
 * and, with -o, download its result and verify its SHA-256.  Prints the job's
 * status document (without --wait) or {jobID, status, message, output,
 * sha256, size, summary} on stdout. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "client_args.h"
#include "client_job.h"

int cmd_submit(int argc, char **argv)
{
    pk_client_args a;
    int rc = pk_client_parse(argc, argv, &a);
    if (rc)
        return rc;
    pk_client c = {.server = a.server, .token = a.token};
    json_t *job = cli_load_json(a.arg);
    if (!job)
        return 1;
    const char *process = json_string_value(json_object_get(job, "process"));
    json_t *inputs = json_object_get(job, "inputs");
    if (!process || !json_is_object(inputs)) {
        fprintf(stderr, "packd submit: %s: a job file is {\"process\": \"…\", \"inputs\": {…}}\n",
                a.arg);
        json_decref(job);
        return 1;
    }
    json_t *body = json_pack("{s:O}", "inputs", inputs);
    char *text = json_dumps(body, JSON_COMPACT);
    char path[300];
    snprintf(path, sizeof path, "/processes/%s/execution", process);
    json_decref(body);
    json_decref(job);
    pk_reply r;
    pk_client_request(&c, "POST", path, text, &r);
    free(text);
    if (r.status != 200 && r.status != 201) {
        rc = pk_client_report("submit", &r);
        pk_reply_free(&r);
        return rc;
    }
    json_t *doc = pk_reply_json(&r);
    pk_reply_free(&r);
    const char *id = json_string_value(json_object_get(doc, "jobID"));
    if (!id) {
        fprintf(stderr, "packd submit: the service answered %ld without a jobID\n", r.status);
        json_decref(doc);
        return 2;
    }
    if (!a.wait) {
        json_dumpf(doc, stdout, JSON_INDENT(2));
        putchar('\n');
        json_decref(doc);
        return 0;
    }
    char jid[64];
    snprintf(jid, sizeof jid, "%s", id);
    json_decref(doc);
    if (!a.quiet)
        fprintf(stderr, "packd: job %s submitted to %s\n", jid, a.server);
    json_t *fin = pk_client_wait(&c, jid, a.quiet);
    if (!fin)
        return 2;
    const char *st = json_string_value(json_object_get(fin, "status"));
    json_t *out = json_pack("{s:s,s:s,s:O}", "jobID", jid, "status", st, "message",
                            json_object_get(fin, "message"));
    rc = !strcmp(st, "successful") ? 0 : 3;
    if (a.output && strcmp(st, "dismissed") != 0) {
        json_t *info = NULL;
        int frc = pk_client_fetch(&c, jid, a.output, &info);
        json_object_update(out, info);
        json_decref(info);
        if (frc)
            rc = frc;
    } else if (rc == 3) {
        fprintf(stderr, "packd submit: job %s %s: %s\n", jid, st, pk_doc_str(fin, "message"));
    }
    json_decref(fin);
    json_dumpf(out, stdout, JSON_INDENT(2) | JSON_REAL_PRECISION(10));
    putchar('\n');
    json_decref(out);
    return rc;
}
