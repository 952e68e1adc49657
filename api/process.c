/* process.c — the process table and the one job path (parse once, run);
 * the contract is in process.h. */
#include "process.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "api/fe2/fe2_job.h"
#include "api/homog/homog_job.h"
#include "api/inputs/input_links.h"
#include "job_verdict.h"
#include "api/pack/pack_job.h"

static const char *const pack_pictures[] = {"packing", "grading", "history", NULL};
static const pk_process pack_process = {
    .id = "pack",
    .title = "Pack grains from a grading curve",
    .description = "Draw grain sizes from a grading (sieve) curve and place them in a 2D or 3D "
                   "box (periodic or walled) with a minimum gap; writes an H5MD result file.",
    .inputs_schema = "pack.inputs.schema.json",
    .pictures = pack_pictures,
    .observables = pk_pack_observables,
    .parse = pk_pack_parse,
    .free_job = pk_pack_free,
    .plan = pk_pack_plan_json,
    .run = pk_pack_run,
};

static const char *const homogenize_pictures[] = {"packing", "stress", "residual", NULL};
static const pk_process homogenize_process = {
    .id = "homogenize",
    .title = "Homogenize a packing (DEM RVE)",
    .description = "Load a packing as a soft-contact DEM RVE with a path of macroscopic "
                   "deformation gradients under Taylor, restricted Taylor or periodic boundary "
                   "conditions; per step the Piola and Cauchy stress, energies, relaxation "
                   "figures and optionally the tangent (Meier 2009); writes an H5MD result file.",
    .inputs_schema = "homogenize.inputs.schema.json",
    .pictures = homogenize_pictures,
    .observables = pk_homog_observables,
    .parse = pk_homog_parse,
    .free_job = pk_homog_free,
    .run = pk_homog_run,
};

static const char *const fe2_pictures[] = {"field", "response", "packing", NULL};
static const pk_process fe2_process = {
    .id = "fe2",
    .title = "FE²: a plane-strain boundary value problem with a DEM RVE at every Gauss point",
    .description = "Solve a 2D plane-strain finite-element problem (Q1 and triangles; a rectangle, "
                   "an inline mesh or a Gmsh file) whose material at every Gauss point is a "
                   "packing homogenized as a DEM RVE (Meier 2009 ch. 6): load stages of "
                   "prescribed displacements, pressures, tractions, forces and gravity, "
                   "Newton–Raphson with the consistent tangent, a line search and load-step "
                   "cutting; writes an H5MD result file with the mesh, the fields per converged "
                   "load step and the Newton histories.",
    .inputs_schema = "fe2.inputs.schema.json",
    .pictures = fe2_pictures,
    .observables = pk_fe2_observables,
    .parse = pk_fe2_parse,
    .free_job = pk_fe2_free,
    .run = pk_fe2_run,
};

const pk_process *const pk_processes[] = {&pack_process, &homogenize_process, &fe2_process, NULL};

const pk_process *pk_process_find(const char *id)
{
    for (size_t i = 0; id && pk_processes[i]; i++)
        if (strcmp(pk_processes[i]->id, id) == 0)
            return pk_processes[i];
    return NULL;
}

size_t pk_process_parse_inputs(const pk_process *p, json_t *inputs, const pk_check_ctx *ctx,
                               void **parsed, pk_schema_errors *errs)
{
    size_t before = errs->n;
    void *job = NULL;
    pk_schema_validate_embedded(p->inputs_schema, inputs, errs);
    if (errs->n == before && !(job = p->parse(inputs, ctx, errs)) && errs->n == before)
        pk_schema_errors_add(errs, "", "parse", "the inputs could not be read");
    if (job && (!parsed || errs->n != before)) {
        p->free_job(job);
        job = NULL;
    }
    if (parsed)
        *parsed = job;
    return errs->n - before;
}

size_t pk_process_validate_inputs(const pk_process *p, json_t *inputs, const pk_check_ctx *ctx,
                                  pk_schema_errors *errs)
{
    return pk_process_parse_inputs(p, inputs, ctx, NULL, errs);
}

/* Prefix the pointers of errors [from, n) with "/inputs". */
size_t pk_job_parse(json_t *job, const pk_check_ctx *ctx, const pk_process **proc, void **parsed,
                    pk_schema_errors *errs)
{
    size_t before = errs->n;
    *proc = NULL;
    if (parsed)
        *parsed = NULL;
    if (pk_schema_validate_embedded("job.schema.json", job, errs) != 0)
        return errs->n - before;
    const pk_process *p = pk_process_find(json_string_value(json_object_get(job, "process")));
    if (!p) { /* the envelope schema's enum should have caught this */
        pk_schema_errors_add(errs, "/process", "enum", "unknown process");
        return errs->n - before;
    }
    size_t mark = errs->n;
    if (pk_input_links_refuse(json_object_get(job, "inputs"), errs) == 0)
        pk_process_parse_inputs(p, json_object_get(job, "inputs"), ctx, parsed, errs);
    pk_schema_errors_prefix(errs, mark, "/inputs");
    if (errs->n == before)
        *proc = p;
    return errs->n - before;
}

int pk_job_run(json_t *job, const pk_run_ctx *run, const char *out_path, json_t **summary,
               pk_schema_errors *errs, char *err, size_t errlen)
{
    pk_run_ctx rx = run ? *run : PK_RUN_CTX_DEFAULT;
    if (rx.threads < 1)
        rx.threads = 1;
    const pk_process *p;
    void *parsed;
    const pk_check_ctx local = {.service = 0}; /* the job runs here: its files are read */
    *summary = NULL;
    if (pk_job_parse(job, &local, &p, &parsed, errs) != 0) {
        snprintf(err, errlen, "invalid job");
        return 1;
    }
    char *text = json_dumps(job, JSON_SORT_KEYS | JSON_COMPACT);
    if (!text) {
        p->free_job(parsed);
        snprintf(err, errlen, "out of memory");
        return -1;
    }
    int rc = p->run(parsed, &rx, text, out_path, summary, err, errlen);
    p->free_job(parsed);
    free(text);
    if (rc == 0 && pk_verdict_failed(*summary)) {
        snprintf(err, errlen, "%s", json_string_value(json_object_get(*summary, "failure")));
        return 2;
    }
    return rc;
}
