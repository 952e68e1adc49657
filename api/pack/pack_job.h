/* pack_job.h — the 'pack' process: JSON inputs ⇄ job struct, feasibility plan, run. */
#ifndef PK_PACK_JOB_H
#define PK_PACK_JOB_H

#include <jansson.h>
#include <stddef.h>
#include <stdint.h>

#include "core/space/box.h"
#include "api/inputs/check_ctx.h"
#include "api/run_ctx.h"
#include "api/schemas/json_schema.h"
#include "api/schemas/option_table.h"
#include "api/results/h5_observables.h"
#include "pack_options.h"
#include "core/base/progress.h"
#include "core/psd/psd.h"

/* Largest count / limits.max_particles (the schema's maximum, the daemon's
 * max_particles cap). */
#define PK_PACK_MAX_COUNT 1000000000000LL

typedef struct pk_pack_job {
    int dim;
    pk_box box;
    char unit[8];
    pk_grading grading;            /* the whole curve, before the cut at d_min */
    int sampling;                  /* "sampling": -1 not given, 0 continuous, 1 discrete */
    int discrete;                  /* 1 = one diameter per class (Meier) */
    double d_min;                  /* cut-off diameter (0 = none) */
    double fuller_q, fuller_d_max; /* "grading": {"type": "fuller"} */
    int has_phi, phi_is_mix;
    double phi;   /* target value as given */
    size_t count; /* 0 = not given */
    double delta_d;
    char algorithm[16]; /* placer name, see pack_placer.h ("auto": resolved, pack_auto.h) */
    int quality;        /* "quality": pk_quality (api/schemas/option_table.h) */
    struct {            /* "algorithm": "auto" (pack_auto.h) */
        int requested;
        char reason[256];
        double threshold, phi_shell, spread; /* NAN where the rule did not use them */
    } choice;
    pk_placer_options opt; /* the placer's options (its table, pack_placer.h) */
    json_t *mesh;          /* borrowed "domain": {"mesh"} of the inputs, or NULL */
    uint64_t seed;
    size_t max_particles;
    double wall_time_s; /* 0 = none */
    int service;        /* 1: checked for a request to the daemon (check_ctx.h): the
                                  * placer's check opens no file and builds no mesh */
    int prepare;        /* 1: the placer's check keeps what it built for the run
                                  * (plan.prepared: tetfill's mesh, read and built once) */
} pk_pack_job;

/* What the job implies before anything is drawn. */
typedef struct pk_pack_plan {
    pk_grading resolved; /* grading cut at d_min */
    double mass_cut;     /* F_m(d_min): mass share not modelled (Eq. 14) */
    double phi_mix;      /* φ_M target (Eq. 15) */
    double phi_resolved; /* φ_eff target (Eqs. 16–17) */
    double expected_n;   /* expected number of grains */
    double scale;        /* expected size scale (count + phi), else 1 */
    double d_max;        /* largest diameter after scaling */
    void *prepared;      /* the placer's, when job.prepare (pk_placer.release) */
} pk_pack_plan;

/* The options of the job itself (pack_job.c); each placer has its own. */
extern const pk_option_table pk_pack_options;

/* A parsed job: what the process's parse hook returns and run takes. */
typedef struct pk_pack_task {
    pk_pack_job job;
    pk_pack_plan plan;
} pk_pack_task;

/* Inputs (already schema-valid) → job.  Semantic errors are appended with
 * pointers relative to the inputs object; returns their number. */
size_t pk_pack_job_from_json(json_t *inputs, pk_pack_job *job, pk_schema_errors *errs);

/* Feasibility: cut the curve, targets, expected N vs max_particles, box vs
 * grain size.  Returns the number of errors appended. */
size_t pk_pack_plan_make(const pk_pack_job *job, pk_pack_plan *plan, pk_schema_errors *errs);

/* process table hooks (see process.h): parse returns a pk_pack_task */
void *pk_pack_parse(json_t *inputs, const pk_check_ctx *ctx, pk_schema_errors *errs);
void pk_pack_free(void *task);
/* What the parsed task implies (pk_process.plan): expected grains, target
 * fractions, mass cut, d_max, size classes. */
json_t *pk_pack_plan_json(const void *task);
/* The pack process's observable list (h5_observables.h): the summary's
 * members, their datasets under /observables and their units. */
extern const pk_obs_row pk_pack_observables[];

int pk_pack_run(const void *task, const pk_run_ctx *run, const char *job_json, const char *out_path,
                json_t **summary, char *err, size_t errlen);

#endif
