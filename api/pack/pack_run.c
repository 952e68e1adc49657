/* pack_run.c — run a parsed 'pack' job: sizes → placement → audit → result
 * file; the contract is in pack_job.h (pk_pack_run). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/space/gap_audit.h"
#include "api/results/h5_observables.h"
#include "api/results/h5_result.h"
#include "api/results/h5_units.h"
#include "api/job_verdict.h"
#include "pack_auto.h"
#include "pack_job.h"
#include "pack_model.h"
#include "pack_placer.h"
#include "core/space/particles.h"
#include "core/base/rng.h"

/* Draw the grain sizes the plan asks for (random stream 0 of the seed). */
static int draw_sizes(const pk_pack_job *job, const pk_pack_plan *plan, pk_sizes *sz, double *scale)
{
    *scale = 1;
    pk_rng rng;
    pk_rng_seed(&rng, job->seed, 0);
    const pk_grading *g = &plan->resolved;
    double V = pk_box_measure(&job->box);
    int rc;
    if (job->discrete) {
        size_t nop = job->count ? job->count : (size_t)llround(plan->expected_n);
        if (nop == 0)
            nop = 1;
        rc = pk_sample_discrete(g, job->dim, nop, sz);
    } else if (job->count) {
        rc = pk_sample_by_count(g, job->dim, job->count, &rng, sz);
    } else {
        rc =
            pk_sample_by_measure(g, job->dim, plan->phi_resolved * V, &rng, job->max_particles, sz);
    }
    if (rc != 0)
        return -1;
    if (job->count && job->has_phi) {
        /* Scale exactly to the target with the drawn sizes (the plan's scale
         * was an expectation). */
        *scale = pow(plan->phi_resolved * V / pk_sizes_measure(sz, job->dim), 1.0 / job->dim);
        for (size_t i = 0; i < sz->n; i++)
            sz->d[i] *= *scale;
    }
    return 0;
}

/* Cumulative % passing of the resolved material at d (target, from the curve). */
static double target_passing(const pk_pack_plan *plan, double d)
{
    double keep = 1 - plan->mass_cut;
    double f = (pk_grading_passing(&plan->resolved, d) - plan->mass_cut) / keep;
    return 100 * fmin(1, fmax(0, f));
}

/* Grains whose true surface crosses a wall by more than tol. */
static size_t grains_outside_walls(const pk_box *b, const pk_particles *p, double tol)
{
    size_t n = 0;
    for (size_t i = 0; i < p->n; i++)
        for (int k = 0; k < b->dim; k++)
            if (!b->periodic[k] &&
                (p->x[3 * i + k] - p->r[i] < -tol || b->L[k] - p->x[3 * i + k] - p->r[i] < -tol)) {
                n++;
                break;
            }
    return n;
}

/* The pack process's observables: the summary's members, /observables/<name>
 * and the summary's units all come from this list (h5_observables.h); the
 * placer's own are /observables/<algorithm>/ with the placer's units. */
const pk_obs_row pk_pack_observables[] = {
    {"algorithm", PK_U_NONE, PK_OBS_SCALAR, NULL},
    {"termination_reason", PK_U_NONE, PK_OBS_SCALAR, NULL},
    {"count_requested", PK_U_NONE, PK_OBS_SCALAR, NULL},
    {"count_placed", PK_U_NONE, PK_OBS_SCALAR, NULL},
    {"count_expected", PK_U_NONE, PK_OBS_SCALAR, NULL},
    {"phi_resolved", PK_U_NONE, PK_OBS_SCALAR, NULL},
    {"phi_mix", PK_U_NONE, PK_OBS_SCALAR, NULL},
    {"phi_target_resolved", PK_U_NONE, PK_OBS_SCALAR, NULL},
    {"phi_target_mix", PK_U_NONE, PK_OBS_SCALAR, NULL},
    {"mass_cut_fraction", PK_U_NONE, PK_OBS_SCALAR, NULL},
    {"d_min", PK_U_LENGTH, PK_OBS_SCALAR, NULL},
    {"delta_d", PK_U_LENGTH, PK_OBS_SCALAR, NULL},
    {"size_scale", PK_U_NONE, PK_OBS_SCALAR, NULL},
    {"smallest_gap", PK_U_LENGTH, PK_OBS_SCALAR, NULL},
    {"smallest_wall_gap", PK_U_LENGTH, PK_OBS_SCALAR, NULL}, /* -1 when every axis is periodic */
    {"pairs_below_delta_d", PK_U_NONE, PK_OBS_SCALAR, NULL},
    {"grains_below_wall_gap", PK_U_NONE, PK_OBS_SCALAR, NULL},
    {"timing/sizes_s", PK_U_SECONDS, PK_OBS_SCALAR, NULL},
    {"timing/place_s", PK_U_SECONDS, PK_OBS_SCALAR, NULL},
    {"timing/audit_s", PK_U_SECONDS, PK_OBS_SCALAR, NULL},
    {"model", PK_U_NONE, PK_OBS_RECORD, "modelled"}, /* write_scene */
    {"auto", PK_U_NONE, PK_OBS_RECORD, NULL},
    {NULL, PK_U_NONE, PK_OBS_SCALAR, NULL},
};

/* What was modelled and, for "auto", the choice: /observables/modelled,
 * /observables/auto (the summary's "model" and "auto"). */
static int write_scene(pk_h5 *h, json_t *summary)
{
    int rc = pk_h5_obs_json(h, "modelled", json_object_get(summary, "model"));
    if (json_object_get(summary, "auto"))
        pk_h5_obs_json(h, "auto", json_object_get(summary, "auto"));
    return rc;
}

/* The unit of a placer observable: "<algorithm>/<name>" looked up in the
 * placer's table (a pk_h5_unit_fn). */
typedef struct placer_units {
    const pk_placer *placer;
    pk_units units;
} placer_units;

static const char *placer_unit_of(const char *name, const void *ctx)
{
    const placer_units *pu = ctx;
    size_t n = strlen(pu->placer->name);
    if (strncmp(name, pu->placer->name, n) != 0 || name[n] != '/')
        return NULL;
    return pk_unit_in(pu->placer->units, name + n + 1, &pu->units);
}

static int write_result(const pk_pack_job *job, const pk_pack_plan *plan, const char *job_json,
                        const pk_box *box, double V, const pk_particles *p, const pk_sizes *sz,
                        double scale, const pk_place_stats *st, json_t *obs_values,
                        const char *out_path, const char *author, json_t *summary, char *err,
                        size_t errlen)
{
    pk_h5 *h = pk_h5_create(out_path, author, err, errlen);
    if (!h)
        return -1;
    const char *u = job->unit;
    const int dim = job->dim;
    double solid = pk_particles_solid_measure(p);
    int rc = 0;
    pk_h5_write_particles(h, box, p, u);
    pk_h5_write_parameters(h, "pack", job_json, job->seed);
    pk_units units;
    pk_units_init(&units, u, dim);
    rc |= pk_h5_obs_rows(h, pk_pack_observables, obs_values, &units);
    if (st->obs) {
        /* a history {events, time, ...} as H5MD time-dependent elements */
        placer_units pu = {.placer = pk_placer_find(job->algorithm)};
        pk_units_init(&pu.units, u, dim);
        json_t *obs = json_copy(st->obs), *hist = json_object_get(st->obs, "history");
        char hp[64];
        snprintf(hp, sizeof hp, "%s/history", job->algorithm);
        if (hist && json_object_del(obs, "history") == 0)
            pk_h5_obs_history(h, hp, hist, "events", "time");
        rc |= obs ? pk_h5_obs_json_units(h, job->algorithm, obs, placer_unit_of, &pu) : -1;
        json_decref(obs);
    }
    if (st->write_extra)
        rc |= st->write_extra(h, job->algorithm, st->extra);
    /* Per class: bounds, target and achieved shares of the resolved measure. */
    const pk_grading *g = &plan->resolved;
    int nc = g->nclass;
    double *lo = calloc((size_t)nc + 1, sizeof *lo), *hi = calloc((size_t)nc + 1, sizeof *hi);
    double *tgt = calloc((size_t)nc + 1, sizeof *tgt), *ach = calloc((size_t)nc + 1, sizeof *ach);
    double *exp_n = calloc((size_t)nc + 1, sizeof *exp_n);
    int64_t *n_placed = calloc((size_t)nc + 1, sizeof *n_placed);
    int64_t *n_drawn = calloc((size_t)nc + 1, sizeof *n_drawn);
    double *sieve = calloc((size_t)nc + 2, sizeof *sieve);
    double *pass_t = calloc((size_t)nc + 2, sizeof *pass_t),
           *pass_a = calloc((size_t)nc + 2, sizeof *pass_a);
    if (!lo || !hi || !tgt || !ach || !exp_n || !n_placed || !n_drawn || !sieve || !pass_t ||
        !pass_a) {
        rc = -1;
        goto done;
    }
    double keep = 1 - plan->mass_cut;
    pk_grading_expected_count(g, dim, plan->phi_mix * V, exp_n);
    for (int c = 0; c < nc; c++) {
        lo[c] = g->cls[c].d_lo * scale;
        hi[c] = g->cls[c].d_hi * scale;
        tgt[c] = g->cls[c].mass_fraction / keep;
    }
    for (size_t i = 0; i < p->n; i++)
        if (p->species[i] >= 0 && p->species[i] < nc) {
            ach[p->species[i]] += pk_ball_measure(dim, p->r[i]);
            n_placed[p->species[i]]++;
        }
    for (size_t i = 0; i < sz->n; i++)
        if (sz->species[i] >= 0 && sz->species[i] < nc)
            n_drawn[sz->species[i]]++;
    for (int c = 0; c < nc; c++)
        ach[c] = solid > 0 ? ach[c] / solid : 0;
    /* passing curve at the class bounds, fine → coarse */
    int ns = 0;
    for (int c = nc - 1; c >= 0; c--) {
        if (ns == 0 || lo[c] > sieve[ns - 1])
            sieve[ns++] = lo[c];
        if (hi[c] > sieve[ns - 1])
            sieve[ns++] = hi[c];
    }
    for (int s = 0; s < ns; s++) {
        pass_t[s] = target_passing(plan, sieve[s] / scale);
        double below = 0;
        for (size_t i = 0; i < p->n; i++)
            if (2 * p->r[i] < sieve[s] * (1 + 1e-12))
                below += pk_ball_measure(dim, p->r[i]);
        pass_a[s] = solid > 0 ? 100 * below / solid : 0;
    }
    pk_h5_obs_doubles(h, "grading/class_d_lo", lo, (size_t)nc, u);
    pk_h5_obs_doubles(h, "grading/class_d_hi", hi, (size_t)nc, u);
    pk_h5_obs_doubles(h, "grading/class_target_fraction", tgt, (size_t)nc, NULL);
    pk_h5_obs_doubles(h, "grading/class_achieved_fraction", ach, (size_t)nc, NULL);
    pk_h5_obs_doubles(h, "grading/class_count_expected", exp_n, (size_t)nc, NULL);
    pk_h5_obs_ints(h, "grading/class_count_drawn", n_drawn, (size_t)nc);
    pk_h5_obs_ints(h, "grading/class_count_placed", n_placed, (size_t)nc);
    pk_h5_obs_doubles(h, "grading/sieve_size", sieve, (size_t)ns, u);
    pk_h5_obs_doubles(h, "grading/target_passing_percent", pass_t, (size_t)ns, NULL);
    pk_h5_obs_doubles(h, "grading/achieved_passing_percent", pass_a, (size_t)ns, NULL);

    json_t *cls = json_array();
    for (int c = 0; c < nc; c++)
        json_array_append_new(cls,
                              json_pack("{s:f,s:f,s:I,s:f,s:f}", "d_lo", lo[c], "d_hi", hi[c],
                                        "placed", (json_int_t)n_placed[c], "target_fraction",
                                        tgt[c], "achieved_fraction", ach[c]));
    json_object_set_new(summary, "classes", cls);
done:
    free(lo);
    free(hi);
    free(tgt);
    free(ach);
    free(exp_n);
    free(n_placed);
    free(n_drawn);
    free(sieve);
    free(pass_t);
    free(pass_a);
    rc |= write_scene(h, summary);
    return pk_verdict_close_h5(h, rc, summary, out_path, err, errlen);
}

int pk_pack_run(const void *task, const pk_run_ctx *run, const char *job_json, const char *out_path,
                json_t **summary, char *err, size_t errlen)
{
    /* the placers run serially (run->threads unused) */
    pk_run_ctx rx = *run;
    pk_monitor *mon = rx.mon;
    const pk_pack_job job = ((const pk_pack_task *)task)->job;
    const pk_pack_plan plan = ((const pk_pack_task *)task)->plan;
    *summary = NULL;
    pk_monitor own = {0}; /* the job's wall time holds without a caller's monitor too */
    if (!mon && job.wall_time_s > 0)
        rx.mon = mon = &own;
    pk_monitor_start(mon, job.wall_time_s); /* across all stages, from now */

    double t0 = pk_wall_seconds();
    pk_sizes sz = {0};
    double scale = 1;
    const pk_placer *placer = pk_placer_find(job.algorithm);
    if (!(placer && placer->own_sizes) && draw_sizes(&job, &plan, &sz, &scale) != 0) {
        snprintf(err, errlen, "drawing sizes failed: %s", pk_psd_error());
        return -1;
    }
    double t_sizes = pk_wall_seconds() - t0;

    pk_particles p;
    if (pk_particles_init(&p, job.dim, sz.n + 1) != 0) {
        pk_sizes_free(&sz);
        snprintf(err, errlen, "out of memory for %zu grains", sz.n);
        return -1;
    }
    pk_place_stats st = {0};
    /* a limit that ran out while the sizes were drawn stops the job before
     * the placer sets up (a large run's grids take seconds): nothing placed */
    int stop = placer && !placer->own_sizes ? pk_monitor_check(mon) : 0;
    if (stop)
        st = (pk_place_stats){.reason = stop == 2 ? PK_STOP_WALL_TIME : PK_STOP_CANCELLED,
                              .requested = sz.n};
    else if (!placer || placer->place(&job, &plan, &sz, &rx, &p, &st, err, errlen) != 0) {
        if (!placer)
            snprintf(err, errlen, "no placer named %s", job.algorithm);
        pk_sizes_free(&sz);
        pk_particles_free(&p);
        json_decref(st.obs);
        if (st.free_extra)
            st.free_extra(st.extra);
        return -1;
    }
    const pk_box box = st.has_domain ? st.domain_box : job.box;
    const double V = st.has_domain ? st.domain_measure : pk_box_measure(&job.box);

    double t1 = pk_wall_seconds();
    pk_gap_report gap;
    double rmax = 0;
    for (size_t i = 0; i < p.n; i++)
        rmax = fmax(rmax, p.r[i]);
    double horizon = fmax(job.delta_d, rmax) + 1e-300;
    /* tolerance: 1e-12 of the largest length, far below any meaningful gap;
     * placers with bounded overlaps by design (tetfill: ε r_min) add their
     * bound, so only overlaps beyond it count as violations */
    double tol = 1e-12 * fmax(box.L[0], fmax(box.L[1], box.L[2])) + st.overlap_tol;
    const double audit_dd = st.short_delta_d ? st.audit_delta_d : job.delta_d;
    if (pk_gap_audit(&box, &p, audit_dd, tol, horizon, &gap) != 0) {
        json_decref(st.obs);
        if (st.free_extra)
            st.free_extra(st.extra);
        pk_sizes_free(&sz);
        pk_particles_free(&p);
        snprintf(err, errlen, "out of memory in the gap audit");
        return -1;
    }
    if (st.walls_touch) /* the placer's wall rule: true grains inside the walls */
        gap.walls_below = grains_outside_walls(&box, &p, tol);
    double t_audit = pk_wall_seconds() - t1;

    const double phi = pk_particles_solid_measure(&p) / V;
    json_t *o = json_object();
    pk_obs_set(o, "algorithm", json_string(job.algorithm));
    pk_obs_set(o, "termination_reason", json_string(pk_place_termination(&st)));
    pk_obs_set(o, "count_requested", json_integer((json_int_t)st.requested));
    pk_obs_set(o, "count_placed", json_integer((json_int_t)st.placed));
    pk_obs_set(o, "count_expected", json_real(plan.expected_n));
    pk_obs_set(o, "phi_resolved", json_real(phi));
    if (!st.phi_own) { /* grown until jammed: φ is the packing's own, no target or mix */
        pk_obs_set(o, "phi_mix", json_real(phi / (1 - plan.mass_cut)));
        pk_obs_set(o, "phi_target_resolved", json_real(plan.phi_resolved));
        pk_obs_set(o, "phi_target_mix", json_real(plan.phi_mix));
    }
    pk_obs_set(o, "mass_cut_fraction", json_real(plan.mass_cut));
    pk_obs_set(o, "d_min", json_real(job.d_min));
    pk_obs_set(o, "delta_d", json_real(job.delta_d));
    pk_obs_set(o, "size_scale", json_real(scale));
    pk_obs_set(o, "smallest_gap", json_real(gap.min_gap));
    pk_obs_set(o, "smallest_wall_gap", json_real(isinf(gap.min_wall_gap) ? -1 : gap.min_wall_gap));
    pk_obs_set(o, "pairs_below_delta_d", json_integer((json_int_t)gap.pairs_below));
    pk_obs_set(o, "grains_below_wall_gap", json_integer((json_int_t)gap.walls_below));
    pk_obs_set(o, "timing/sizes_s", json_real(t_sizes));
    pk_obs_set(o, "timing/place_s", json_real(st.seconds));
    pk_obs_set(o, "timing/audit_s", json_real(t_audit));

    json_t *sum = json_object();
    json_object_set_new(sum, "process", json_string("pack"));
    json_t *choice = pk_pack_auto_json(&job);
    if (choice)
        json_object_set_new(sum, "auto", choice);
    json_object_set_new(sum, "model", pk_pack_model_json(&job, &plan));
    json_object_set_new(sum, "complete",
                        json_false()); /* here in the listing; pk_pack_verdict sets it */
    json_object_update(sum, o);
    pk_units units;
    pk_units_init(&units, job.unit, job.dim);
    json_object_set_new(sum, "units", pk_obs_units_json(pk_pack_observables, sum, &units));
    pk_pack_verdict(&job, &plan, &st, &p, &gap, phi, audit_dd, sum);
    int rc = write_result(&job, &plan, job_json, &box, V, &p, &sz, scale, &st, o, out_path,
                          rx.author, sum, err, errlen);
    json_decref(o);
    pk_sizes_free(&sz);
    pk_particles_free(&p);
    if (st.free_extra)
        st.free_extra(st.extra);
    if (st.obs)
        json_object_set(sum, job.algorithm, st.obs);
    json_decref(st.obs);
    if (rc != 0) {
        json_decref(sum);
        return -1;
    }
    *summary = sum;
    return 0;
}
