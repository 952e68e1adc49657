/* pack_job.h — the 'pack' process: JSON inputs ⇄ job struct, feasibility plan, run. */
#ifndef PK_PACK_JOB_H
#define PK_PACK_JOB_H

#include <jansson.h>
#include <stddef.h>
#include <stdint.h>

#include "core/space/box.h"
#include "api/inputs/check_ctx.h"
#include "api/schemas/json_schema.h"
#include "core/base/progress.h"
#include "core/psd/psd.h"

/* Largest count / limits.max_particles (the schema's maximum, the daemon's
 * max_particles cap). */
#define PK_PACK_MAX_COUNT 1000000000000LL

typedef struct pk_pack_job {
    int dim;
    pk_box box;
    char unit[8];
    pk_grading grading;          /* the whole curve, before the cut at d_min */
    int discrete;                /* 1 = one diameter per class (Meier) */
    double d_min;                /* cut-off diameter (0 = none) */
    int has_phi, phi_is_mix;
    double phi;                  /* target value as given */
    size_t count;                /* 0 = not given */
    double delta_d;
    char algorithm[16];          /* placer name, see pack_placer.h */
    json_t *inputs;              /* borrowed: placers read their own options from it */
    uint64_t seed;
    size_t max_particles;
    double wall_time_s;          /* 0 = none */
    int service;                 /* 1: checked for a request to the daemon (check_ctx.h): the
                                  * placer's check opens no file and builds no mesh */
} pk_pack_job;

/* What the job implies before anything is drawn. */
typedef struct pk_pack_plan {
    pk_grading resolved;         /* grading cut at d_min */
    double mass_cut;             /* F_m(d_min): mass share not modelled (Eq. 14) */
    double phi_mix;              /* φ_M target (Eq. 15) */
    double phi_resolved;         /* φ_eff target (Eqs. 16–17) */
    double expected_n;           /* expected number of grains */
    double scale;                /* expected size scale (count + phi), else 1 */
    double d_max;                /* largest diameter after scaling */
} pk_pack_plan;

/* Inputs (already schema-valid) → job.  Semantic errors are appended with
 * pointers relative to the inputs object; returns their number. */
size_t pk_pack_job_from_json(json_t *inputs, pk_pack_job *job, pk_schema_errors *errs);

/* Feasibility: cut the curve, targets, expected N vs max_particles, box vs
 * grain size.  Returns the number of errors appended. */
size_t pk_pack_plan_make(const pk_pack_job *job, pk_pack_plan *plan, pk_schema_errors *errs);

/* process table hooks (see process.h) */
void pk_pack_check(json_t *inputs, const pk_check_ctx *ctx, pk_schema_errors *errs);
int pk_pack_run(json_t *inputs, const char *job_json, const char *out_path, pk_monitor *mon,
                json_t **summary, char *err, size_t errlen);

#endif
