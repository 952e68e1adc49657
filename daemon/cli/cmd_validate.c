/* cmd_validate.c — `packd validate JOB.json`: the schema and semantic checks
 * without running.  Contract: daemon/cli/cli.h. */
#include <stdio.h>
#include <string.h>

#include "cli.h"
#include "input_hint.h"
#include "api/pack/pack_job.h"
#include "api/process.h"

int cmd_validate(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: packd validate JOB.json\n");
        return 64;
    }
    json_t *job = cli_load_json(argv[1]);
    if (!job)
        return 1;
    pk_schema_errors errs = {0};
    const pk_process *proc;
    void *parsed = NULL;
    int rc = 0;
    const pk_check_ctx local = {.service = 0}; /* the user's own machine: files are read */
    if (pk_job_parse(job, &local, &proc, &parsed, &errs) != 0) {
        cli_print_errors(argv[1], &errs);
        cli_hint_missing_inputs(stderr, argv[1], job, &errs);
        rc = 1;
    } else {
        json_t *out = json_pack("{s:b,s:s,s:s}", "valid", 1, "file", argv[1], "process", proc->id);
        if (strcmp(proc->id, "pack") == 0) {
            /* what the job implies, so a user sees the cost before running it */
            const pk_pack_plan plan = ((const pk_pack_task *)parsed)->plan;
            json_object_set_new(out, "plan",
                                json_pack("{s:f,s:f,s:f,s:f,s:f,s:i}", "expected_grains",
                                          plan.expected_n, "phi_target_mix", plan.phi_mix,
                                          "phi_target_resolved", plan.phi_resolved,
                                          "mass_cut_fraction", plan.mass_cut, "d_max", plan.d_max,
                                          "size_classes", plan.resolved.nclass));
        }
        json_dumpf(out, stdout, JSON_INDENT(2));
        putchar('\n');
        json_decref(out);
        proc->free_job(parsed);
    }
    pk_schema_errors_free(&errs);
    json_decref(job);
    return rc;
}
