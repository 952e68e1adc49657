/* homog_job.c — the 'homogenize' process's option table, inputs → job with
 * its checks, the F̄ path; the contract is in homog_job.h. */
#include "homog_job.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "api/inputs/input_open.h"
#include "core/space/mat3.h"

static const char *const bc_names[] = {"taylor", "restricted_taylor", "periodic",
                                       NULL}; /* pk_homog_bc */
static const char *const predictor_names[] = {"none", "affine", NULL};
static const char *const solver_names[] = {"dr", "newton", NULL};
static const char *const policy_names[] = {"as_generated", "radius_inflation", "precompress", NULL};
static const char *const load_names[] = {"simple_shear", "cyclic_shear", "uniaxial_compression",
                                         "list", NULL};
_Static_assert(sizeof(pk_homog_bc) == sizeof(int), "named values are stored as int");
#define F(m) PK_OPT_FIELD(pk_homog_job, m)
static const pk_option homog_rows[] = {
    {"/rve/file", PK_OPT_STRING, F(rve_file), PK_OPT_IMPLICIT},
    {"/boundary_condition", PK_OPT_ENUM, F(bc), PK_OPT_IMPLICIT, .dflt = PK_BC_PERIODIC,
     .names = bc_names},
    {"/contact/E_n", PK_OPT_NUMBER, F(E_n), .dflt = 1},
    {"/friction/E_t", PK_OPT_NUMBER, F(fric.E_t), PK_OPT_IMPLICIT, .dflt = NAN}, /* NAN: E_n */
    {"/friction/rho_deg", PK_OPT_NUMBER, F(rho_deg), PK_OPT_IMPLICIT},
    {"/friction/h", PK_OPT_NUMBER, F(fric.h)},
    {"/quality", PK_OPT_ENUM, F(quality), .dflt = PK_QUALITY_STANDARD, .names = pk_quality_names},
    {"/relaxation/tol", PK_OPT_NUMBER, F(tol), .dflt = 1e-8, PK_OPT_QUALITY(1e-5, 1e-10)},
    {"/relaxation/abs_tol", PK_OPT_NUMBER, F(abs_tol), .dflt = 1e-13},
    {"/relaxation/max_iter", PK_OPT_INTEGER, F(max_iter), .dflt = 1000000, .lo = 1, .hi = 1e9},
    {"/relaxation/solver", PK_OPT_ENUM, F(newton), .names = solver_names},
    {"/relaxation/newton_max_iter", PK_OPT_INTEGER, F(newton_max_iter), .dflt = 50, .lo = 1,
     .hi = 10000},
    {"/relaxation/predictor", PK_OPT_ENUM, F(affine_predictor), .dflt = 1,
     .names = predictor_names},
    {"/relaxation/lanczos_steps", PK_OPT_INTEGER, F(lanczos_steps), .dflt = 40, .lo = 2,
     .hi = 1000},
    {"/relaxation/refresh", PK_OPT_INTEGER, F(refresh), .dflt = 200, .lo = 10, .hi = 1000000},
    {"/tangent", PK_OPT_BOOL, F(tangent)},
    {"/initial_state/policy", PK_OPT_ENUM, F(initial_policy), PK_OPT_IMPLICIT,
     .names = policy_names},
    {"/initial_state/value", PK_OPT_NUMBER, F(initial_value)},
    {"/output/micro_state", PK_OPT_BOOL, F(out_micro)},
    {"/output/contacts", PK_OPT_BOOL, F(out_contacts)},
    {"/output/frames", PK_OPT_BOOL, F(out_frames), .dflt = 1},
    {"/limits/wall_time_s", PK_OPT_NUMBER, F(wall_time_s), PK_OPT_IMPLICIT},
    {"/load/type", PK_OPT_ENUM, F(load.type), PK_OPT_IMPLICIT, .names = load_names},
    {"/load/precompression", PK_OPT_NUMBER, F(load.precompression), .dflt = 0.01},
    {"/load/pre_steps", PK_OPT_INTEGER, F(load.pre_steps), .dflt = 10, .lo = 1, .hi = 100000},
    {"/load/steps", PK_OPT_INTEGER, F(load.steps), PK_OPT_IMPLICIT, .dflt = 1, .lo = 1,
     .hi = 100000},
    {"/load/shear", PK_OPT_NUMBER, F(load.shear), PK_OPT_IMPLICIT, .dflt = 1},
    {"/load/amplitude", PK_OPT_NUMBER, F(load.amplitude), PK_OPT_IMPLICIT, .dflt = 0.5},
    {"/load/axis", PK_OPT_INTEGER, F(load.axis), .dflt = 1, .lo = 1, .hi = 3},
    {"/load/strain", PK_OPT_NUMBER, F(load.strain), PK_OPT_IMPLICIT, .dflt = 0.3},
    {"/load/plane", PK_OPT_STRING, F(load.plane), .sdefault = "12"},
};
#undef F
const pk_option_table pk_homog_options =
    PK_OPT_TABLE("homogenize.inputs.schema.json", pk_homog_job, homog_rows, NULL);

json_t *pk_homog_model_json(const pk_homog_job *job, int dim, int frames_kept)
{
    return json_pack("{s:i,s:s,s:b,s:b,s:s,s:f,s:b,s:b,s:b}", "dim", dim, "quality",
                     pk_quality_names[job->quality], "friction", job->friction, "tangent",
                     job->tangent, "solver", job->newton ? "newton" : "dr", "tolerance", job->tol,
                     "contacts_stored", job->out_contacts, "micro_state_stored", job->out_micro,
                     "frames_stored", frames_kept);
}

void pk_homog_job_free(pk_homog_job *job)
{
    free(job->F);
    job->F = NULL;
    job->nstep = 0;
    free(job->E_n_species);
    job->E_n_species = NULL;
    job->n_species = 0;
}

/* contact.E_n_species: square and symmetric (E_n,ij = E_n,ji: one contact,
 * one spring); the schema checks the entries are positive numbers. */
static void species_stiffness(json_t *m, pk_homog_job *job, pk_schema_errors *errs)
{
    size_t n = json_array_size(m);
    if (!n)
        return;
    job->E_n_species = malloc(n * n * sizeof *job->E_n_species);
    if (!job->E_n_species) {
        pk_schema_errors_add(errs, "/contact/E_n_species", "memory", "out of memory");
        return;
    }
    job->n_species = n;
    for (size_t a = 0; a < n; a++) {
        json_t *row = json_array_get(m, a);
        if (json_array_size(row) != n) {
            char ptr[64];
            snprintf(ptr, sizeof ptr, "/contact/E_n_species/%zu", a);
            pk_schema_errors_add(errs, ptr, "semantic",
                                 "row %zu has %zu entries: the matrix must be %zu × %zu", a,
                                 json_array_size(row), n, n);
            return;
        }
        for (size_t b = 0; b < n; b++)
            job->E_n_species[a * n + b] = json_number_value(json_array_get(row, b));
    }
    for (size_t a = 0; a < n; a++)
        for (size_t b = a + 1; b < n; b++)
            if (job->E_n_species[a * n + b] != job->E_n_species[b * n + a]) {
                char ptr[64];
                snprintf(ptr, sizeof ptr, "/contact/E_n_species/%zu/%zu", a, b);
                pk_schema_errors_add(
                    errs, ptr, "semantic",
                    "E_n_species must be symmetric: [%zu][%zu] = %g but [%zu][%zu] = %g", a, b,
                    job->E_n_species[a * n + b], b, a, job->E_n_species[b * n + a]);
                return;
            }
}

static int push_F(pk_homog_job *job, size_t *cap, const double F[9])
{
    if (job->nstep == *cap) {
        size_t c = *cap ? 2 * *cap : 64;
        double *n = realloc(job->F, c * 9 * sizeof *n);
        if (!n)
            return -1;
        job->F = n;
        *cap = c;
    }
    memcpy(&job->F[9 * job->nstep++], F, 9 * sizeof *F);
    return 0;
}

/* "12" → (0, 1) */
static void plane_of(const pk_homog_job *job, int *i, int *j)
{
    const char *s = job->load.plane;
    if (strlen(s) != 2)
        s = "12";
    *i = s[0] - '1';
    *j = s[1] - '1';
}

/* (1 − λc)1 ramped over pre_steps, then the shear history λs(t) (steps). */
static int shear_path(pk_homog_job *job, size_t *cap, int cyclic)
{
    double lc = job->load.precompression;
    int pre = job->load.pre_steps;
    int steps = job->load.steps;
    int pi, pj;
    plane_of(job, &pi, &pj);
    double F[9];
    for (int k = 1; k <= pre; k++) {
        pk_m3_identity(F);
        for (int a = 0; a < 3; a++)
            F[4 * a] = 1 - lc * k / pre;
        if (push_F(job, cap, F))
            return -1;
    }
    double amp = cyclic ? job->load.amplitude : job->load.shear;
    for (int k = 1; k <= steps; k++) {
        double t = (double)k / steps, ls;
        if (!cyclic)
            ls = amp * t;
        else if (t <= 0.25) /* 0 → a → −a → 0, piecewise linear */
            ls = 4 * amp * t;
        else if (t <= 0.75)
            ls = amp * (1 - 4 * (t - 0.25));
        else
            ls = -amp + 4 * amp * (t - 0.75);
        pk_m3_identity(F);
        for (int a = 0; a < 3; a++)
            F[4 * a] = 1 - lc;
        F[3 * pi + pj] += ls;
        if (push_F(job, cap, F))
            return -1;
    }
    return 0;
}

size_t pk_homog_job_from_json(json_t *inputs, pk_homog_job *job, pk_schema_errors *errs)
{
    size_t before = errs->n;
    memset(job, 0, sizeof *job);
    pk_options_fill(&pk_homog_options, inputs, job, errs);
    species_stiffness(json_object_get(json_object_get(inputs, "contact"), "E_n_species"), job,
                      errs);
    job->friction = json_is_object(json_object_get(inputs, "friction"));
    if (job->friction) {
        if (isnan(job->fric.E_t))
            job->fric.E_t = job->E_n;
        job->fric.tan_rho = tan(job->rho_deg * M_PI / 180);
    } else
        job->fric = (pk_fric_law){0};
    job->radius_factor = 1;
    if (job->initial_policy == 1) /* radius_inflation */
        job->radius_factor = 1 + job->initial_value;
    if (job->initial_policy == 2) /* precompress */
        job->precompress = job->initial_value;

    json_t *load = json_object_get(inputs, "load");
    const int list = job->load.type == 3, uniaxial = job->load.type == 2;
    size_t cap = 0;
    int rc = 0;
    if (list) {
        json_t *list_F = json_object_get(load, "F"), *row;
        size_t k;
        json_array_foreach (list_F, k, row) {
            size_t m = json_array_size(row);
            char ptr[64];
            snprintf(ptr, sizeof ptr, "/load/F/%zu", k);
            if (m != 4 && m != 9) {
                pk_schema_errors_add(errs, ptr, "semantic",
                                     "F̄ needs 4 (2D) or 9 (3D) numbers, got %zu", m);
                continue;
            }
            int d = m == 4 ? 2 : 3;
            if (job->fdim && job->fdim != d)
                pk_schema_errors_add(errs, ptr, "semantic",
                                     "all F̄ of a path must have the same dimension");
            job->fdim = d;
            double F[9];
            pk_m3_identity(F);
            for (int a = 0; a < d; a++)
                for (int b = 0; b < d; b++)
                    F[3 * a + b] = json_number_value(json_array_get(row, (size_t)(a * d + b)));
            rc |= push_F(job, &cap, F);
        }
    } else if (uniaxial) {
        int axis = job->load.axis - 1, steps = job->load.steps;
        double lam = job->load.strain;
        if (axis == 2)
            job->fdim = 3;
        for (int k = 1; k <= steps; k++) {
            double F[9];
            pk_m3_identity(F);
            F[4 * axis] = 1 - lam * k / steps;
            rc |= push_F(job, &cap, F);
        }
    } else {
        int cyc = job->load.type == 1;
        int pi, pj;
        plane_of(job, &pi, &pj);
        if (pi == pj)
            pk_schema_errors_add(errs, "/load/plane", "semantic",
                                 "a shear plane needs two different axes");
        if (pi == 2 || pj == 2)
            job->fdim = 3;
        rc |= shear_path(job, &cap, cyc);
    }
    if (rc) {
        pk_schema_errors_add(errs, "/load", "memory", "out of memory for the load path");
    }
    if (job->friction && job->tangent)
        pk_schema_errors_add(
            errs, "/tangent", "semantic",
            "no tangent with friction: the consistent tangent of the return map is not "
            "implemented (ch. 7 derives none); use finite differences of the stress");
    if (job->friction && job->newton)
        pk_schema_errors_add(errs, "/relaxation/solver", "semantic",
                             "friction needs solver \"dr\" (Newton has no frictional stiffness)");
    if (job->friction && job->fdim == 3)
        pk_schema_errors_add(errs, "/friction", "semantic",
                             "friction is 2D only (Meier 2009 ch. 7)");
    if (job->friction && pk_fric_law_active(&job->fric) && job->bc != PK_BC_TAYLOR)
        pk_schema_errors_add(errs, "/friction", "semantic",
                             "friction with rho_deg > 0 or h > 0 needs boundary_condition taylor "
                             "(Meier 2009 §7.4): under %s sliding contacts make the relaxation "
                             "diverge (their forces are not the gradient of the energy it "
                             "minimises); use taylor or drop friction",
                             pk_homog_bc_name(job->bc));
    /* every step (on top of the pre-compression): finite, det F̄ > 0, the
     * principal stretches within bounds (PK_HOMOG_MIN_STRETCH, spec H13) */
    double F0[9];
    pk_m3_identity(F0);
    for (int a = 0; a < 3; a++)
        F0[4 * a] = 1 - job->precompress;
    for (size_t k = 0; k < job->nstep && errs->n - before < 20; k++) {
        double F[9];
        pk_m3_mul(&job->F[9 * k], F0, F);
        int d3 = job->fdim == 3 ? 3 : 2, finite = 1;
        double fro = 0;
        for (int a = 0; a < d3; a++)
            for (int b = 0; b < d3; b++) {
                finite &= isfinite(F[3 * a + b]) != 0;
                fro += F[3 * a + b] * F[3 * a + b];
            }
        double d = pk_m3_det(F), smin = pk_m3_sigma_min(F, d3);
        char ptr[64];
        if (list)
            snprintf(ptr, sizeof ptr, "/load/F/%zu", k);
        else
            snprintf(ptr, sizeof ptr, "/load");
        const char *pre = job->precompress > 0 ? " (with the pre-compression)" : "";
        if (!finite || !isfinite(fro))
            pk_schema_errors_add(errs, ptr, "semantic", "F̄ of step %zu%s is not finite", k, pre);
        else if (!(d > 0))
            pk_schema_errors_add(errs, ptr, "semantic",
                                 "det F̄ of step %zu%s is %g: must be > 0 (no inversion or collapse "
                                 "of the cell)",
                                 k, pre, d);
        else if (!(smin >= PK_HOMOG_MIN_STRETCH))
            pk_schema_errors_add(errs, ptr, "semantic",
                                 "F̄ of step %zu%s has a principal stretch %.4g (det F̄ %.4g): each "
                                 "must be >= %g; below, touching grains overlap by more than a "
                                 "radius (the contact law needs ε ≪ r)",
                                 k, pre, smin, d, PK_HOMOG_MIN_STRETCH);
        else if (!(sqrt(fro) <= PK_HOMOG_MAX_STRETCH))
            pk_schema_errors_add(errs, ptr, "semantic",
                                 "|F̄| of step %zu%s is %.4g: must be <= %g (every contact is open "
                                 "long before)",
                                 k, pre, sqrt(fro), PK_HOMOG_MAX_STRETCH);
    }
    if (errs->n != before)
        pk_homog_job_free(job);
    return errs->n - before;
}

void *pk_homog_parse(json_t *inputs, const pk_check_ctx *ctx, pk_schema_errors *errs)
{
    pk_homog_job *job = malloc(sizeof *job);
    if (!job) {
        pk_schema_errors_add(errs, "", "memory", "out of memory");
        return NULL;
    }
    if (pk_homog_job_from_json(inputs, job, errs) == 0) {
        /* a job file on this machine names an RVE that opens (check_ctx.h);
         * the run reads it */
        if ((ctx && ctx->service) || pk_input_check(job->rve_file, "/rve/file", "rve", errs) == 0)
            return job;
        pk_homog_job_free(job);
    }
    free(job);
    return NULL;
}

void pk_homog_free(void *job)
{
    if (job)
        pk_homog_job_free(job);
    free(job);
}
