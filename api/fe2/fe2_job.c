/* fe2_job.c — the 'fe2' process's option table, inputs → job with its
 * checks (the micro options through the 'homogenize' table, a nested pack
 * through the 'pack' process); the contract is in fe2_job.h. */
#include "fe2_job.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "api/inputs/input_open.h"
#include "api/process.h"

static const char *const initial_stress_names[] = {"free", "balanced", NULL};
#define F(m) PK_OPT_FIELD(pk_fe2_job, m)
static const pk_option fe2_rows[] = {
    {"/unit", PK_OPT_STRING, F(unit), .sdefault = "mm"},
    {"/newton/rtol", PK_OPT_NUMBER, F(newton.rtol), .dflt = 1e-8},
    {"/newton/atol", PK_OPT_NUMBER, F(newton.atol), .dflt = 1e-12},
    {"/newton/max_iter", PK_OPT_INTEGER, F(newton.max_iter), .dflt = 20, .lo = 1, .hi = 64},
    {"/newton/line_search", PK_OPT_BOOL, F(newton.line_search), .dflt = 1},
    {"/newton/max_cuts", PK_OPT_INTEGER, F(newton.max_cuts), .dflt = 6, .lo = 0, .hi = 30},
    {"/initial_stress", PK_OPT_ENUM, F(balanced), .names = initial_stress_names},
    {"/limits/wall_time_s", PK_OPT_NUMBER, F(wall_time_s), PK_OPT_IMPLICIT},
    {"/limits/max_gauss_points", PK_OPT_INTEGER, F(max_gauss_points), .dflt = 20000, .lo = 1,
     .hi = 1000000},
    {"/limits/max_grains_total", PK_OPT_INTEGER, F(max_grains_total), .dflt = 20000000, .lo = 1,
     .hi = 1e9},
    {"/parallel/mpi_ranks", PK_OPT_INTEGER, F(mpi_ranks), .dflt = 1, .lo = 1, .hi = 64},
};
#undef F
const pk_option_table pk_fe2_options =
    PK_OPT_TABLE("fe2.inputs.schema.json", pk_fe2_job, fe2_rows, NULL);

/* Append the errors of tmp to errs with prefix before their pointers. */
static void copy_prefixed(pk_schema_errors *errs, const pk_schema_errors *tmp, const char *prefix)
{
    for (size_t i = 0; i < tmp->n; i++) {
        char ptr[sizeof tmp->items[0].pointer];
        snprintf(ptr, sizeof ptr, "%s%.*s", prefix, (int)(sizeof ptr - strlen(prefix) - 1),
                 tmp->items[i].pointer);
        pk_schema_errors_add(errs, ptr, tmp->items[i].rule, "%s", tmp->items[i].message);
    }
}

/* The micro options as 'homogenize' inputs: the same keys, one F̄ = 1 as
 * the (unused) load path; a nested pack names no file yet. */
static void micro_parse(json_t *micro, const pk_check_ctx *ctx, pk_fe2_job *job,
                        pk_schema_errors *errs)
{
    if (json_object_get(micro, "friction"))
        pk_schema_errors_add(errs, "/micro/friction", "friction",
                             "friction is not offered for fe2: the macro Newton iteration needs "
                             "the consistent tangent Ā, and the frictional return map has none "
                             "(Meier 2009 ch. 7 derives none); drop \"friction\"");
    json_t *h = json_object();
    static const char *const keys[] = {"boundary_condition", "contact", "relaxation",
                                       "initial_state"};
    for (size_t k = 0; k < sizeof keys / sizeof *keys; k++)
        if (json_object_get(micro, keys[k]))
            json_object_set(h, keys[k], json_object_get(micro, keys[k]));
    json_t *rve = json_object_get(micro, "rve");
    /* a nested pack job states the fe2 job's unit, or none (it gets it) */
    json_t *pack_in = json_object_get(rve, "pack");
    const char *pu = json_string_value(json_object_get(pack_in, "unit"));
    if (pu && strcmp(pu, job->unit) != 0)
        pk_schema_errors_add(errs, "/micro/rve/pack/unit", "semantic",
                             "the nested pack job's unit \"%s\" differs from the fe2 job's unit "
                             "\"%s\": the RVE's lengths are in the job's unit; drop one or make "
                             "them equal",
                             pu, job->unit);
    if (pack_in) {
        job->pack_inputs = json_deep_copy(pack_in);
        json_object_set_new(job->pack_inputs, "unit", json_string(job->unit));
    }
    if (job->pack_inputs)
        json_object_set_new(h, "rve", json_pack("{s:s}", "file", "(nested pack)"));
    else {
        json_object_set(h, "rve", rve);
        const char *file = json_string_value(json_object_get(rve, "file"));
        if (file && !(ctx && ctx->service)) /* as for homogenize (pk_homog_parse) */
            pk_input_check(file, "/micro/rve/file", "rve", errs);
    }
    json_object_set_new(h, "load",
                        json_pack("{s:s, s:[[i,i,i,i]]}", "type", "list", "F", 1, 0, 0, 1));
    pk_schema_errors tmp = {0};
    if (pk_homog_job_from_json(h, &job->micro, &tmp) == 0 && job->micro.initial_policy == 2)
        pk_schema_errors_add(&tmp, "/initial_state/policy", "semantic",
                             "precompress is not offered for fe2: every Gauss point starts from "
                             "the RVE relaxed at F̄ = 1; use radius_inflation for a prestressed, "
                             "jammed start");
    copy_prefixed(errs, &tmp, "/micro");
    pk_schema_errors_free(&tmp);
    json_decref(h);
    if (job->pack_inputs) {
        const pk_process *pack = pk_process_find("pack");
        if (json_integer_value(json_object_get(job->pack_inputs, "dim")) != 2)
            pk_schema_errors_add(errs, "/micro/rve/pack/dim", "semantic",
                                 "the RVE of an fe2 job is 2D (plane strain): dim must be 2");
        pk_schema_errors t2 = {0};
        pk_process_parse_inputs(pack, job->pack_inputs, ctx, &job->pack_job, &t2);
        copy_prefixed(errs, &t2, "/micro/rve/pack");
        pk_schema_errors_free(&t2);
    }
}

static void job_free(pk_fe2_job *job)
{
    pk_homog_job_free(&job->micro);
    if (job->pack_job)
        pk_process_find("pack")->free_job(job->pack_job);
    json_decref(job->pack_inputs);
    free(job->micro_gp);
    free(job);
}

void *pk_fe2_parse(json_t *inputs, const pk_check_ctx *ctx, pk_schema_errors *errs)
{
    size_t before = errs->n;
    pk_fe2_job *job = calloc(1, sizeof *job);
    if (!job) {
        pk_schema_errors_add(errs, "", "memory", "out of memory");
        return NULL;
    }
    pk_options_fill(&pk_fe2_options, inputs, job, errs);
    job->mesh = json_object_get(inputs, "mesh");
    job->bcs = json_object_get(inputs, "boundary_conditions");
    job->stages = json_object_get(inputs, "stages");
    micro_parse(json_object_get(inputs, "micro"), ctx, job, errs);
    json_t *gps = json_object_get(json_object_get(inputs, "output"), "micro_states");
    job->n_micro_gp = json_array_size(gps);
    job->micro_gp = calloc(job->n_micro_gp + 1, sizeof *job->micro_gp);
    for (size_t i = 0; job->micro_gp && i < job->n_micro_gp; i++)
        job->micro_gp[i] = (size_t)json_integer_value(json_array_get(gps, i));
    /* the mesh and the conditions on it: a request to the service names a
     * mesh file it must not open here (check_ctx.h), so its sets are
     * checked when the job runs; inline meshes and rectangles are built
     * (bounded by limits.max_gauss_points) */
    if (!(ctx && ctx->service && !json_object_get(job->mesh, "rectangle") &&
          !json_object_get(job->mesh, "nodes"))) {
        pk_fe2_setup s;
        pk_fe2_setup_build(job, &s, errs);
        size_t ngp = s.mesh.gp_first ? pk_fe2_gauss_count(&s.mesh) : 0;
        for (size_t i = 0; i < job->n_micro_gp; i++)
            if (errs->n == before && job->micro_gp[i] >= ngp) {
                char ptr[64];
                snprintf(ptr, sizeof ptr, "/output/micro_states/%zu", i);
                pk_schema_errors_add(errs, ptr, "semantic",
                                     "Gauss point %zu: the mesh has %zu (0..%zu)", job->micro_gp[i],
                                     ngp, ngp ? ngp - 1 : 0);
            }
        pk_fe2_setup_free(&s);
    }
    if (errs->n != before) {
        job_free(job);
        return NULL;
    }
    return job;
}

void pk_fe2_free(void *job)
{
    if (job)
        job_free(job);
}
