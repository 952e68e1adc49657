/* homog_record.c — per-step observables of a 'homogenize' run as JSON arrays.
 * Contract: api/homog/homog_record.h. */
#include "homog_record.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* "ab" (1-based digits) for indices a, b < 3 */
static void comp_name(char *buf, size_t len, int a, int b)
{
    (void)len;
    buf[0] = (char)('1' + a), buf[1] = (char)('1' + b), buf[2] = 0;
}

static void comp4_name(char *buf, int a, int b, int c, int d)
{
    comp_name(buf, 3, a, b);
    comp_name(buf + 2, 3, c, d);
}

/* The recorded components of a dim×dim tensor (all, or a < b for the skew
 * part): their names "ab" and row-major indices into a 3×3 array.  One list
 * serves the series set-up and every step, so the two can never disagree. */
static int tensor_components(int dim, int skew_only, char names[9][8], int idx[9])
{
    int n = 0;
    for (int a = 0; a < dim; a++)
        for (int b = 0; b < dim; b++) {
            if (skew_only && b <= a)
                continue;
            comp_name(names[n], sizeof names[n], a, b);
            idx[n++] = 3 * a + b;
        }
    return n;
}

/* obj[name] = {component: []} */
static void tensor_series(json_t *parent, const char *name, int dim, int skew_only)
{
    char names[9][8];
    int idx[9];
    int n = tensor_components(dim, skew_only, names, idx);
    json_t *t = json_object();
    for (int k = 0; k < n; k++)
        json_object_set_new(t, names[k], json_array());
    json_object_set_new(parent, name, t);
}

static const char *const scalar_series[] = {"J",
                                            "energy",
                                            "energy_density",
                                            "contacts",
                                            "contacts_formed",
                                            "contacts_broken",
                                            "coordination",
                                            "rattlers",
                                            "max_overlap_ratio",
                                            "sum_force",
                                            "reaction_defect",
                                            "energy_tangential",
                                            "dissipation",
                                            "contacts_sliding",
                                            NULL};
static const char *const dr_series[] = {"newton_iterations",
                                        "newton_steps",
                                        "newton_exit_code",
                                        "newton_attempts",
                                        "newton_shifts",
                                        "fire_iterations",
                                        "iterations",
                                        "residual",
                                        "residual_initial",
                                        "stop_code",
                                        "dt",
                                        "gamma",
                                        "lambda_min",
                                        "lambda_max",
                                        "lambda_min_clamped",
                                        NULL};

json_t *pk_homog_record_new(int dim, int with_tangent)
{
    json_t *r = json_object();
    tensor_series(r, "F", dim, 0);
    tensor_series(r, "P", dim, 0);
    tensor_series(r, "sigma", dim, 0);
    tensor_series(r, "sigma_skew", dim, 1);
    for (int k = 0; scalar_series[k]; k++)
        json_object_set_new(r, scalar_series[k], json_array());
    json_t *dr = json_object();
    for (int k = 0; dr_series[k]; k++)
        json_object_set_new(dr, dr_series[k], json_array());
    json_object_set_new(dr, "stop_names",
                        json_string("0 converged, 1 converged_absolute, 2 not_needed, 3 max_iter, "
                                    "4 cancelled, 5 wall_time"));
    json_object_set_new(dr, "newton_exit_names",
                        json_string("-1 not used, 0 converged, 1 block_not_positive_definite, "
                                    "2 line_search_failed, 3 iteration_cap, 4 stalled"));
    json_object_set_new(r, "dr", dr);
    if (with_tangent) {
        json_t *t = json_object();
        json_t *A = json_object();
        for (int a = 0; a < dim; a++)
            for (int b = 0; b < dim; b++)
                for (int c = 0; c < dim; c++)
                    for (int d = 0; d < dim; d++) {
                        char nm[8];
                        comp4_name(nm, a, b, c, d);
                        json_object_set_new(A, nm, json_array());
                    }
        json_object_set_new(t, "A", A);
        json_object_set_new(t, "step", json_array());
        json_object_set_new(t, "status_code", json_array());
        json_object_set_new(t, "status_names",
                            json_string("0 positive_definite, 1 indefinite, 2 singular, 3 failed"));
        json_object_set_new(t, "seconds", json_array());
        json_object_set_new(t, "free_dofs", json_array());
        json_object_set_new(r, "tangent", t);
    }
    return r;
}

static int put(json_t *obj, const char *key, json_t *v)
{
    return v ? json_array_append_new(json_object_get(obj, key), v) : -1;
}

static int put_tensor(json_t *rec, const char *name, int dim, const double T[9], int skew_only)
{
    char names[9][8];
    int idx[9];
    int n = tensor_components(dim, skew_only, names, idx);
    json_t *t = json_object_get(rec, name);
    int rc = 0;
    for (int k = 0; k < n; k++)
        rc |= put(t, names[k], json_real(T[idx[k]]));
    return rc;
}

int pk_homog_record_step(json_t *rec, int dim, const pk_homog_step *st)
{
    int rc = 0;
    rc |= put_tensor(rec, "F", dim, st->F, 0);
    rc |= put_tensor(rec, "P", dim, st->P, 0);
    rc |= put_tensor(rec, "sigma", dim, st->sigma, 0);
    rc |= put_tensor(rec, "sigma_skew", dim, st->sigma_skew, 1);
    rc |= put(rec, "J", json_real(st->J));
    rc |= put(rec, "energy", json_real(st->energy));
    rc |= put(rec, "energy_density", json_real(st->energy_density));
    rc |= put(rec, "contacts", json_integer((json_int_t)st->contacts));
    rc |= put(rec, "contacts_formed", json_integer((json_int_t)st->formed));
    rc |= put(rec, "contacts_broken", json_integer((json_int_t)st->broken));
    rc |= put(rec, "coordination", json_real(st->coordination));
    rc |= put(rec, "rattlers", json_integer((json_int_t)st->rattlers));
    rc |= put(rec, "energy_tangential", json_real(st->energy_t));
    rc |= put(rec, "dissipation", json_real(st->dissipation));
    rc |= put(rec, "contacts_sliding", json_integer((json_int_t)st->sliding));
    rc |= put(rec, "max_overlap_ratio", json_real(st->max_overlap_ratio));
    rc |= put(rec, "sum_force", json_real(st->sum_force));
    rc |= put(rec, "reaction_defect", json_real(st->reaction_defect));
    json_t *dr = json_object_get(rec, "dr");
    rc |= put(dr, "newton_iterations", json_integer((json_int_t)st->newton.iterations));
    rc |= put(dr, "newton_steps", json_integer((json_int_t)st->newton.steps));
    rc |= put(dr, "newton_exit_code",
              json_integer(st->used_newton ? (json_int_t)st->newton.exit : -1));
    rc |= put(dr, "newton_attempts", json_integer((json_int_t)st->newton.attempts));
    rc |= put(dr, "newton_shifts", json_integer((json_int_t)st->newton.shifts));
    rc |= put(dr, "fire_iterations", json_integer((json_int_t)st->newton.fire_iterations));
    rc |= put(dr, "iterations", json_integer((json_int_t)st->dr.iterations));
    rc |= put(dr, "residual", json_real(st->dr.f));
    rc |= put(dr, "residual_initial", json_real(st->dr.f0));
    rc |= put(dr, "stop_code", json_integer((json_int_t)st->dr.stop));
    rc |= put(dr, "dt", json_real(st->dr.dt));
    rc |= put(dr, "gamma", json_real(st->dr.gamma));
    rc |= put(dr, "lambda_min", json_real(st->dr.lambda_min));
    rc |= put(dr, "lambda_max", json_real(st->dr.lambda_max));
    rc |= put(dr, "lambda_min_clamped", json_integer(st->dr.clamped));
    return rc ? -1 : 0;
}

int pk_homog_record_tangent(json_t *rec, int dim, size_t step, const double A[81],
                            const pk_tangent_info *info, int ok)
{
    json_t *t = json_object_get(rec, "tangent");
    int rc = 0;
    rc |= put(t, "status_code", json_integer((json_int_t)info->block.status));
    rc |= put(t, "seconds", json_real(info->seconds));
    rc |= put(t, "free_dofs", json_integer((json_int_t)info->free_dofs));
    if (!ok)
        return rc ? -1 : 0; /* A only for steps listed in tangent/step */
    rc |= put(t, "step", json_integer((json_int_t)step));
    json_t *At = json_object_get(t, "A");
    for (int a = 0; a < dim; a++)
        for (int b = 0; b < dim; b++)
            for (int c = 0; c < dim; c++)
                for (int d = 0; d < dim; d++) {
                    char nm[8];
                    comp4_name(nm, a, b, c, d);
                    rc |= put(At, nm, json_real(A[(3 * a + b) * 9 + 3 * c + d]));
                }
    return rc ? -1 : 0;
}

static const char *const audit_series[] = {
    "passed",         "failed_checks", "residual_ratio", "balance_ratio",
    "grains_outside", "escape_radii",  "overlap_ratio",  NULL};

json_t *pk_homog_record_audit_new(void)
{
    json_t *a = json_object();
    for (int k = 0; audit_series[k]; k++)
        json_object_set_new(a, audit_series[k], json_array());
    json_object_set_new(a, "failed_check_bits",
                        json_string("1 not converged, 2 unbalanced, 4 escaped, 8 not finite, "
                                    "16 overlap"));
    json_object_set_new(a, "overlap_ratio_bound", json_real(PK_AUDIT_OVERLAP_MAX));
    json_object_set_new(a, "balance_ratio_bound", json_real(PK_AUDIT_BALANCE_SLACK));
    json_object_set_new(a, "residual_ratio_bound", json_real(1));
    return a;
}

/* non-finite figures as ±DBL_MAX (JSON, hence the record, has no NaN) */
static json_t *real_fin(double v)
{
    return json_real(isfinite(v) ? v : v < 0 ? -DBL_MAX : DBL_MAX);
}

int pk_homog_record_audit(json_t *aud, const pk_homog_audit *a)
{
    int rc = 0;
    rc |= put(aud, "passed", json_integer(a->failed == 0));
    rc |= put(aud, "failed_checks", json_integer((json_int_t)a->failed));
    rc |= put(aud, "residual_ratio", real_fin(a->residual_ratio));
    rc |= put(aud, "balance_ratio", real_fin(a->balance_ratio));
    rc |= put(aud, "grains_outside", json_integer((json_int_t)a->outside));
    rc |= put(aud, "escape_radii", real_fin(a->escape));
    rc |= put(aud, "overlap_ratio", real_fin(a->overlap_ratio));
    return rc ? -1 : 0;
}

/* ---- the record in the result file (H5MD time-dependent elements) ---- */

#define OBS "/observables/"

/* The homogenize process's observables (h5_observables.h): the summary's
 * members, their datasets under /observables and their units.  Scalars are
 * written from the run's values (pk_h5_obs_rows); the record's series are
 * written here, the summary holding their last step. */
#define S(name, kind, file)                                                                        \
    {                                                                                              \
        name, kind, PK_OBS_SCALAR, "homogenize/" file                                              \
    }
#define R(name, kind, file)                                                                        \
    {                                                                                              \
        name, kind, PK_OBS_RECORD, file                                                            \
    }
#define FILE_ONLY(file, kind)                                                                      \
    {                                                                                              \
        "homogenize/" file, kind, PK_OBS_FILE, NULL                                                \
    }
const pk_obs_row pk_homog_observables[] = {
    S("boundary_condition", PK_U_NONE, "boundary_condition"),
    S("termination_reason", PK_U_NONE, "termination_reason"),
    S("steps", PK_U_NONE, "steps"),
    S("steps_requested", PK_U_NONE, "steps_requested"),
    S("steps_not_converged", PK_U_NONE, "steps_not_converged"),
    S("resumed", PK_U_NONE, "resumed"), /* with a checkpoint file */
    S("resumed_from_step", PK_U_NONE, "resumed_from_step"),
    S("checkpoint_error", PK_U_NONE, "checkpoint_error"),
    S("rve_particles", PK_U_NONE, "rve_particles"),
    S("rve_volume", PK_U_VOLUME, "rve_volume"),
    S("E_n", PK_U_STIFFNESS, "E_n"),
    S("friction/E_t", PK_U_STIFFNESS, "friction/E_t"),
    S("friction/tan_rho", PK_U_NONE, "friction/tan_rho"),
    S("friction/h", PK_U_NONE, "friction/h"),
    S("radius_factor", PK_U_NONE, "radius_factor"),
    S("precompression", PK_U_NONE, "precompression"),
    S("dr_iterations_total", PK_U_NONE, "dr_iterations_total"),
    S("dr_iterations_max", PK_U_NONE, "dr_iterations_max"),
    {"threads", PK_U_NONE, PK_OBS_RUN, NULL},
    S("hull/widest_gap_over_d_min", PK_U_NONE, "hull/widest_gap_over_d_min"),
    S("hull/full", PK_U_NONE, "hull/full"),
    /* the audit over the steps (its series: /observables/audit) */
    {"audit/passed", PK_U_NONE, PK_OBS_SCALAR, "audit/all_passed"},
    {"audit/steps_audited", PK_U_NONE, PK_OBS_SCALAR, "audit/steps_audited"},
    {"audit/max_residual_ratio", PK_U_NONE, PK_OBS_SCALAR, "audit/max_residual_ratio"},
    {"audit/max_balance_ratio", PK_U_NONE, PK_OBS_SCALAR, "audit/max_balance_ratio"},
    {"audit/max_overlap_ratio", PK_U_NONE, PK_OBS_SCALAR, "audit/max_overlap_ratio"},
    R("audit/overlap_ratio_bound", PK_U_NONE, "audit/overlap_ratio_bound"),
    R("model", PK_U_NONE, "modelled"),
    /* the last committed step of the series */
    R("F", PK_U_NONE, "homogenize/F"),
    R("P", PK_U_STRESS, "homogenize/P"),
    R("sigma", PK_U_STRESS, "homogenize/sigma"),
    R("energy_density", PK_U_STRESS, "homogenize/energy_density"),
    R("contacts", PK_U_NONE, "homogenize/contacts"),
    R("rattlers", PK_U_NONE, "homogenize/rattlers"),
    R("tangent", PK_U_STRESS, "homogenize/tangent/A"), /* Ā as [d²][d²] */
    /* series and arrays of the file alone with a unit; every other one is
     * a count, a ratio or dimensionless (J, iterations) */
    FILE_ONLY("sigma_skew", PK_U_STRESS),
    FILE_ONLY("energy", PK_U_ENERGY),
    FILE_ONLY("energy_tangential", PK_U_ENERGY),
    FILE_ONLY("dissipation", PK_U_ENERGY),
    FILE_ONLY("sum_force", PK_U_FORCE),
    FILE_ONLY("dr/residual", PK_U_FORCE),
    FILE_ONLY("dr/residual_initial", PK_U_FORCE),
    FILE_ONLY("tangent/seconds", PK_U_SECONDS),
    FILE_ONLY("final_state/position", PK_U_LENGTH),
    FILE_ONLY("final_state/fluctuation", PK_U_LENGTH),
    {NULL, PK_U_NONE, PK_OBS_SCALAR, NULL},
};
#undef S
#undef R
#undef FILE_ONLY

const char *pk_homog_unit_of(const char *name, const void *units)
{
    return pk_obs_unit_at(pk_homog_observables, name, units);
}

typedef struct {
    pk_h5 *h;
    const pk_units *u;
    size_t nstep; /* steps requested: time = load fraction (k + 1)/nstep */
} writer;

/* step k and time (k+1)/nstep for k = first..first+S-1 */
static int clock_of(size_t first, size_t S, size_t nstep, int64_t **step, double **time)
{
    *step = malloc((S ? S : 1) * sizeof **step);
    *time = malloc((S ? S : 1) * sizeof **time);
    if (!*step || !*time)
        return -1;
    for (size_t i = 0; i < S; i++) {
        (*step)[i] = (int64_t)(first + i);
        (*time)[i] = (double)(first + i + 1) / (double)(nstep ? nstep : 1);
    }
    return 0;
}

/* A JSON array of numbers as an element at path (clock: NULL to write
 * step/time, else the element to share them with). */
static int series(const writer *w, const char *path, const char *clock, json_t *arr,
                  const int64_t *step, const double *time)
{
    size_t S = json_array_size(arr), i;
    json_t *e;
    int all_int = 1;
    json_array_foreach (arr, i, e)
        all_int &= json_is_integer(e);
    const char *unit = pk_homog_unit_of(path + strlen(OBS), w->u);
    void *v = malloc((S ? S : 1) * 8);
    if (!v)
        return -1;
    json_array_foreach (arr, i, e) {
        if (all_int && !unit)
            ((int64_t *)v)[i] = (int64_t)json_integer_value(e);
        else
            ((double *)v)[i] = json_number_value(e);
    }
    int rc = pk_h5_time_element(w->h, path, clock, step, time, NULL,
                                all_int && !unit ? PK_H5_I64 : PK_H5_F64, 1, &S, v, unit);
    free(v);
    return rc;
}

/* A tensor recorded by components {"11": [...], ...} as value [S][d][d]
 * (the skew part: a < b recorded, the rest by antisymmetry). */
static int tensor(const writer *w, const char *path, const char *clock, json_t *t, int dim,
                  int skew, const int64_t *step, const double *time)
{
    size_t S = json_array_size(json_object_get(t, skew ? "12" : "11"));
    double *v = calloc((S ? S : 1) * 9, sizeof *v);
    if (!v)
        return -1;
    for (int a = 0; a < dim; a++)
        for (int b = 0; b < dim; b++) {
            char nm[3];
            comp_name(nm, 3, skew && b < a ? b : a, skew && b < a ? a : b);
            json_t *arr = json_object_get(t, nm);
            double sign = skew && b < a ? -1 : 1;
            for (size_t k = 0; arr && k < S; k++)
                v[(k * (size_t)dim + (size_t)a) * (size_t)dim + (size_t)b] =
                    sign * json_number_value(json_array_get(arr, k));
        }
    size_t dims[3] = {S, (size_t)dim, (size_t)dim};
    int rc = pk_h5_time_element(w->h, path, clock, step, time, NULL, PK_H5_F64, 3, dims, v,
                                pk_homog_unit_of(path + strlen(OBS), w->u));
    free(v);
    return rc;
}

/* Ā per tangent step: value [S][d][d][d][d], step = the listed steps. */
static int tangent_A(const writer *w, json_t *t, int dim)
{
    json_t *steps = json_object_get(t, "step"), *A = json_object_get(t, "A");
    size_t S = json_array_size(steps), d = (size_t)dim, n = d * d * d * d;
    double *v = calloc((S ? S : 1) * n, sizeof *v), *time = malloc((S ? S : 1) * sizeof *time);
    int64_t *step = malloc((S ? S : 1) * sizeof *step);
    int rc = -1;
    if (v && time && step) {
        for (size_t k = 0; k < S; k++) {
            step[k] = (int64_t)json_integer_value(json_array_get(steps, k));
            time[k] = (double)(step[k] + 1) / (double)(w->nstep ? w->nstep : 1);
        }
        size_t q = 0;
        for (int a = 0; a < dim; a++)
            for (int b = 0; b < dim; b++)
                for (int c = 0; c < dim; c++)
                    for (int e = 0; e < dim; e++, q++) {
                        char nm[8];
                        comp4_name(nm, a, b, c, e);
                        json_t *arr = json_object_get(A, nm);
                        for (size_t k = 0; k < S; k++)
                            v[k * n + q] = json_number_value(json_array_get(arr, k));
                    }
        size_t dims[5] = {S, d, d, d, d};
        rc = pk_h5_time_element(w->h, OBS "homogenize/tangent/A", NULL, step, time, NULL, PK_H5_F64,
                                5, dims, v, w->u->stress[0] ? w->u->stress : NULL);
    }
    free(v);
    free(time);
    free(step);
    return rc;
}

/* Every per-step array of obj (and of its objects but tensors) as an element
 * under prefix, sharing the clock of the first; the rest left in obj. */
static int series_of(const writer *w, const char *prefix, json_t *obj, const char **clock,
                     char *clock_buf, const int64_t *step, const double *time)
{
    const char *key;
    json_t *v;
    void *tmp;
    int rc = 0;
    json_object_foreach_safe (obj, tmp, key, v) {
        char path[256];
        snprintf(path, sizeof path, "%s/%s", prefix, key);
        if (!json_is_array(v))
            continue;
        rc |= series(w, path, *clock, v, step, time);
        if (!*clock) {
            snprintf(clock_buf, 256, "%s", path);
            *clock = clock_buf;
        }
        json_object_del(obj, key);
    }
    return rc;
}

/* final_state: [n][dim] positions and fluctuations, flags [n]. */
static int final_state(const writer *w, json_t *fs, int dim)
{
    const char *key;
    json_t *v;
    int rc = 0;
    json_object_foreach (fs, key, v) {
        int vec = !strcmp(key, "position") || !strcmp(key, "fluctuation");
        size_t n = json_array_size(v), i;
        char path[128];
        snprintf(path, sizeof path, OBS "homogenize/final_state/%s", key);
        void *a = malloc((n ? n : 1) * 8);
        if (!a)
            return -1;
        json_t *e;
        json_array_foreach (v, i, e) {
            if (vec)
                ((double *)a)[i] = json_number_value(e);
            else
                ((int64_t *)a)[i] = (int64_t)json_integer_value(e);
        }
        size_t dims[2] = {vec ? n / (size_t)dim : n, (size_t)dim};
        pk_h5_write_array(w->h, path, vec ? PK_H5_F64 : PK_H5_I64, vec ? 2 : 1, dims, a,
                          pk_homog_unit_of(path + strlen(OBS), w->u));
        free(a);
    }
    return rc;
}

/* The final contact network: /connectivity/contacts [n_c][2] (indices into
 * /particles/rve) with the per-contact figures beside it. */
static int final_contacts(const writer *w, json_t *fc, int dim)
{
    json_t *ci = json_object_get(fc, "i"), *cj = json_object_get(fc, "j");
    size_t n = json_array_size(ci);
    int64_t *pairs = malloc((n ? n : 1) * 2 * sizeof *pairs);
    double *br = malloc((n ? n : 1) * (size_t)dim * sizeof *br);
    double *ov = malloc((n ? n : 1) * sizeof *ov), *fn = malloc((n ? n : 1) * sizeof *fn);
    int rc = -1;
    if (pairs && br && ov && fn) {
        json_t *b = json_object_get(fc, "branch");
        for (size_t k = 0; k < n; k++) {
            pairs[2 * k] = (int64_t)json_integer_value(json_array_get(ci, k));
            pairs[2 * k + 1] = (int64_t)json_integer_value(json_array_get(cj, k));
            ov[k] = json_number_value(json_array_get(json_object_get(fc, "overlap"), k));
            fn[k] = json_number_value(json_array_get(json_object_get(fc, "normal_force"), k));
            for (int a = 0; a < dim; a++)
                br[k * (size_t)dim + (size_t)a] =
                    json_number_value(json_array_get(b, k * (size_t)dim + (size_t)a));
        }
        size_t d2[2] = {n, (size_t)dim};
        rc = pk_h5_connectivity(w->h, "/connectivity/contacts", pairs, n, "/particles/rve");
        pk_h5_write_array(w->h, "/connectivity/contact_overlap", PK_H5_F64, 1, d2, ov,
                          w->u->length[0] ? w->u->length : NULL);
        pk_h5_write_array(w->h, "/connectivity/contact_normal_force", PK_H5_F64, 1, d2, fn, "N");
        pk_h5_write_array(w->h, "/connectivity/contact_branch", PK_H5_F64, 2, d2, br,
                          w->u->length[0] ? w->u->length : NULL);
    }
    free(pairs);
    free(br);
    free(ov);
    free(fn);
    return rc;
}

int pk_homog_record_write(pk_h5 *h, json_t *rec, json_t *aud, int dim, size_t audit_first,
                          size_t nstep, const pk_units *u)
{
    writer w = {h, u, nstep};
    json_t *r = json_deep_copy(rec), *a = json_deep_copy(aud);
    int64_t *step = NULL, *astep = NULL;
    double *time = NULL, *atime = NULL;
    int rc = -1;
    size_t S = json_array_size(json_object_get(rec, "J"));
    size_t SA = json_array_size(json_object_get(aud, "passed"));
    if (!r || !a || clock_of(0, S, nstep, &step, &time) != 0 ||
        clock_of(audit_first, SA, nstep, &astep, &atime) != 0)
        goto out;
    /* the per-step series share one clock: the load steps 0..S-1 */
    rc = 0;
    const char *clock = NULL;
    char clock_buf[256];
    static const char *const tensors[] = {"F", "P", "sigma", "sigma_skew"};
    for (int k = 0; k < 4; k++) {
        char path[128];
        snprintf(path, sizeof path, OBS "homogenize/%s", tensors[k]);
        rc |= tensor(&w, path, clock, json_object_get(r, tensors[k]), dim, k == 3, step, time);
        if (!clock) {
            snprintf(clock_buf, sizeof clock_buf, "%s", path);
            clock = clock_buf;
        }
        json_object_del(r, tensors[k]);
    }
    rc |= series_of(&w, OBS "homogenize", r, &clock, clock_buf, step, time);
    rc |=
        series_of(&w, OBS "homogenize/dr", json_object_get(r, "dr"), &clock, clock_buf, step, time);
    json_t *t = json_object_get(r, "tangent");
    if (t) {
        rc |= tangent_A(&w, t, dim);
        json_object_del(t, "A");
        json_object_del(t, "step");
        /* status, time and size of every committed step's tangent */
        size_t ST = json_array_size(json_object_get(t, "status_code"));
        int64_t *ts = NULL;
        double *tt = NULL;
        if (clock_of(0, ST, nstep, &ts, &tt) == 0) {
            const char *tclock = NULL;
            char tbuf[256];
            rc |= series_of(&w, OBS "homogenize/tangent", t, &tclock, tbuf, ts, tt);
        } else
            rc = -1;
        free(ts);
        free(tt);
    }
    json_t *fs = json_object_get(r, "final_state"), *fc = json_object_get(r, "final_contacts");
    if (fs)
        rc |= final_state(&w, fs, dim);
    if (fc)
        rc |= final_contacts(&w, fc, dim);
    json_object_del(r, "final_state");
    json_object_del(r, "final_contacts");
    pk_h5_obs_json_units(h, "homogenize", r, pk_homog_unit_of, u); /* the codes' names */
    /* the audit: one entry per audited step (from audit_first on) */
    const char *aclock = NULL;
    char abuf[256];
    rc |= series_of(&w, OBS "audit", a, &aclock, abuf, astep, atime);
    pk_h5_obs_json(h, "audit", a);
out:
    json_decref(r);
    json_decref(a);
    free(step);
    free(time);
    free(astep);
    free(atime);
    return rc ? -1 : 0;
}
