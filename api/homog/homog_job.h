/* homog_job.h — the 'homogenize' process: JSON inputs → job struct and load
 * path (schemas/homogenize.inputs.schema.json), semantic checks, run. */
#ifndef PK_HOMOG_JOB_H
#define PK_HOMOG_JOB_H

#include <jansson.h>
#include <stddef.h>

#include "api/inputs/check_ctx.h"
#include "api/results/h5_observables.h"
#include "api/run_ctx.h"
#include "core/homog/homog_bc.h"
#include "core/homog/homog_rve.h"
#include "api/schemas/json_schema.h"
#include "api/schemas/option_table.h"
#include "core/base/progress.h"

/* Every load step's F̄ (with the pre-compression): det F̄ > 0 and every
 * principal stretch (singular value) >= PK_HOMOG_MIN_STRETCH — at 0.5 an
 * affinely moved touching pair of equal grains has ε = r, the overlap bound
 * of the audit (homog_audit.h): beyond it a centre enters its neighbour and
 * the linear contact law (ε ≪ r, spec H3/H13) has lost its meaning.  |F̄|
 * (Frobenius) <= PK_HOMOG_MAX_STRETCH: every contact is open long before,
 * and F̄X, J̄V stay far from overflow. */
#define PK_HOMOG_MIN_STRETCH 0.5
#define PK_HOMOG_MAX_STRETCH 100.0

typedef struct pk_homog_job {
    char rve_file[1024];
    pk_homog_bc bc;
    double E_n;
    double *E_n_species; /* [n_species²] row-major, NULL = uniform E_n */
    size_t n_species;
    int friction;     /* "friction" given */
    pk_fric_law fric; /* E_t, tan ρ, h (E_t defaults to E_n) */
    double rho_deg;   /* friction angle ρ (fric.tan_rho = tan ρ) */
    int quality;      /* "quality": pk_quality (api/schemas/option_table.h) */
    double tol, abs_tol;
    size_t max_iter;
    int lanczos_steps;
    size_t refresh;
    int affine_predictor;
    int newton; /* relaxation.solver = newton */
    size_t newton_max_iter;
    int tangent;
    int out_micro, out_contacts;
    int out_frames;     /* "output": {"frames"}: 0 = no per-step frames (homog_frames.h) */
    int initial_policy; /* initial_state policy: 0 as_generated, 1 radius_inflation,
                                * 2 precompress */
    double initial_value;
    double radius_factor; /* initial_state radius_inflation */
    double precompress;   /* initial_state precompress λ₀ */
    double wall_time_s;
    size_t nstep;
    struct {      /* "load": the preset's parameters */
        int type; /* 0 simple_shear, 1 cyclic_shear, 2 uniaxial_compression, 3 list */
        double precompression, shear, amplitude, strain;
        int pre_steps, steps, axis;
        char plane[3];
    } load;
    int fdim;  /* 2 or 3: dimension the load path is written for (0 = any) */
    double *F; /* [nstep][9] row-major, 3D-embedded */
} pk_homog_job;

/* The options of the process (homog_job.c). */
extern const pk_option_table pk_homog_options;
/* The process's observable list (api/results/h5_observables.h; in
 * homog_record.c). */
extern const pk_obs_row pk_homog_observables[];

/* Inputs (schema-valid) → job; semantic errors appended with pointers
 * relative to the inputs object.  Returns their number (job->F is freed on
 * error). */
size_t pk_homog_job_from_json(json_t *inputs, pk_homog_job *job, pk_schema_errors *errs);
void pk_homog_job_free(pk_homog_job *job);
/* What the run models and stores (the summary's "model", /observables/modelled;
 * docs/presets.md): dim, quality, friction, tangent, the optional records
 * (contacts, micro state) and whether the per-step frames were kept. */
json_t *pk_homog_model_json(const pk_homog_job *job, int dim, int frames_kept);

/* The relaxation options of job for the RVE rve (homog_run.c; also the
 * RVEs of 'fe2'). */
void pk_homog_opts_of(const pk_homog_job *job, const pk_homog_rve *rve, pk_homog_opts *o);

/* process table hooks (see process.h): parse returns a pk_homog_job */
void *pk_homog_parse(json_t *inputs, const pk_check_ctx *ctx, pk_schema_errors *errs);
void pk_homog_free(void *job);
int pk_homog_run(const void *job, const pk_run_ctx *run, const char *job_json, const char *out_path,
                 json_t **summary, char *err, size_t errlen);

#endif
