/* homog_record.c — per-step observables of a 'homogenize' run as JSON arrays.
 * Contract: api/homog/homog_record.h. */
#include "homog_record.h"

#include <float.h>
#include <math.h>
#include <stdio.h>

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
