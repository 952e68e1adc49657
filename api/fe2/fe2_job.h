/* fe2_job.h — the 'fe2' process (FE², Meier 2009 ch. 6): JSON inputs
 * (schemas/fe2.inputs.schema.json) → job, the macro problem set up from it
 * (mesh, named sets, boundary conditions, stage targets), run. */
#ifndef PK_FE2_JOB_H
#define PK_FE2_JOB_H

#include <jansson.h>
#include <stddef.h>
#include <stdint.h>

#include "api/homog/homog_job.h"
#include "api/inputs/check_ctx.h"
#include "api/run_ctx.h"
#include "api/mesh/mesh_io.h"
#include "api/schemas/json_schema.h"
#include "api/schemas/option_table.h"
#include "core/base/progress.h"
#include "core/fe2/fe2_mesh.h"
#include "core/fe2/fe2_solver.h"

typedef enum pk_fe2_bc_type {
    PK_FE2_DISPLACEMENT,
    PK_FE2_PRESSURE,
    PK_FE2_TRACTION,
    PK_FE2_FORCE,
    PK_FE2_GRAVITY
} pk_fe2_bc_type;

/* Values a condition takes: 1 (displacement, pressure) or 2 (vectors). */
#define PK_FE2_BC_VALUES(type) ((type) == PK_FE2_DISPLACEMENT || (type) == PK_FE2_PRESSURE ? 1 : 2)

typedef struct pk_fe2_job {
    /* the option table's fields */
    pk_fe2_newton_opts newton;
    double wall_time_s;
    int balanced; /* initial_stress: 0 free, 1 balanced */
    char unit[8]; /* the length unit of the mesh, the loads and the RVE */
    size_t max_gauss_points, max_grains_total;
    int mpi_ranks; /* what an executor starts (docs/fe2.md); packd run takes its launch's */
    /* borrowed from the inputs (they outlive the job: process.h) */
    json_t *mesh, *bcs, *stages;
    /* micro: the RVE options as a 'homogenize' job (its rve_file unused
     * with a nested pack), and the nested pack job (or NULL) */
    pk_homog_job micro;
    void *pack_job;
    json_t *pack_inputs; /* owned: a copy stating the job's unit */
    size_t *micro_gp;    /* output.micro_states */
    size_t n_micro_gp;
} pk_fe2_job;

/* The options of the process (fe2_job.c). */
extern const pk_option_table pk_fe2_options;
/* The process's observable list (api/results/h5_observables.h; in
 * fe2_record.c). */
extern const pk_obs_row pk_fe2_observables[];

/* The macro problem set up from a job (fe2_setup.c): the mesh and its
 * sets, the conditions resolved to degrees of freedom, and each stage's
 * end values. */
typedef struct pk_fe2_bc {
    char name[64];
    pk_fe2_bc_type type;
    int comp;       /* displacement: 0 x, 1 y */
    double density; /* gravity */
    const pk_mesh2d_set *set;
    double *unit[2]; /* loads: f_ext [ndof] of the value 1 in component c (pressure: [0]) */
} pk_fe2_bc;

typedef struct pk_fe2_setup {
    pk_mesh2d sets; /* the named sets (its xy/conn moved into mesh) */
    pk_fe2_mesh mesh;
    size_t ndof, nbc, nstage, nfix;
    pk_fe2_bc *bc;
    int32_t *fix_dof;   /* [nfix] ascending */
    int32_t *fix_bc;    /* [nfix] the (first) displacement condition of each */
    double *value;      /* [nstage + 1][nbc][2]: values at the start and each stage's end */
    size_t *increments; /* [nstage] */
    char (*stage_name)[64];
} pk_fe2_setup;

/* Build the mesh and resolve the conditions and stages of job; errors
 * (JSON pointers relative to the inputs) appended; the number returned. */
size_t pk_fe2_setup_build(const pk_fe2_job *job, pk_fe2_setup *s, pk_schema_errors *errs);
void pk_fe2_setup_free(pk_fe2_setup *s);

/* The prescribed values [nfix] and f_ext [ndof] at fraction t ∈ [0, 1] of
 * stage k. */
void pk_fe2_setup_targets(const pk_fe2_setup *s, size_t k, double t, double *uD, double *fext);

/* process table hooks (see process.h): parse returns a pk_fe2_job */
void *pk_fe2_parse(json_t *inputs, const pk_check_ctx *ctx, pk_schema_errors *errs);
void pk_fe2_free(void *job);
int pk_fe2_run(const void *job, const pk_run_ctx *run, const char *job_json, const char *out_path,
               json_t **summary, char *err, size_t errlen);

#endif
