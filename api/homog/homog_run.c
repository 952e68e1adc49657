/* homog_run.c — run a 'homogenize' job: RVE file → load path of relaxed,
 * committed steps (Table 4.1/4.2) → H5MD result with per-step observables. */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/dem/dem_rattler.h"
#include "api/results/h5_result.h"
#include "core/homog/homog_audit.h"
#include "homog_checkpoint.h"
#include "homog_frames.h"
#include "homog_job.h"
#include "homog_record.h"
#include "core/homog/homog_tangent.h"
#include "core/space/mat3.h"
#include "api/job_verdict.h"
#include "core/base/par.h"
#include "api/process.h"
#include "api/solver/sparse_cholmod.h"

void pk_homog_opts_of(const pk_homog_job *job, const pk_homog_rve *rve, pk_homog_opts *o)
{
    double rmean = 0;
    for (size_t i = 0; i < rve->n; i++)
        rmean += rve->r[i] / (double)rve->n;
    memset(o, 0, sizeof *o);
    o->E_n = job->E_n;
    o->affine_predictor = job->affine_predictor;
    o->dr.tol = job->tol;
    /* absolute floor scaled like the round-off of |f| (~1e-16·E·r̄·N) */
    o->dr.abs_floor = job->abs_tol * job->E_n * rmean * (double)rve->n;
    o->dr.max_iter = job->max_iter;
    o->dr.lanczos_steps = job->lanczos_steps;
    o->dr.refresh = job->refresh;
    o->dr.skin = 0.3 * rmean;
    o->newton = job->newton ? &pk_sparse_cholmod : NULL;
    o->newton_max_iter = job->newton_max_iter;
    o->friction = job->friction ? &job->fric : NULL;
    o->E_n_species = job->E_n_species;
    o->n_species = job->n_species;
}

static const char *eval_error(int rc)
{
    return rc == -2 ? "the periodic box is too small for this F̄ (an image contact could be missed)"
        : rc == -3  ? "det F̄ <= 0"
        : rc == -4  ? "friction is 2D only (Meier 2009 ch. 7) and this RVE is 3D"
                    : "out of memory";
}

/* The rule a periodic RVE breaks when its pair search cannot tell a grain's
 * neighbours from their periodic images (core/dem/dem_pairs.c): every edge
 * longer than twice the largest contact reach at F̄ = I. */
static void periodic_box_rule(const pk_homog_rve *rve, double skin, char *err, size_t errlen)
{
    double rmax = 0;
    for (size_t i = 0; i < rve->n; i++)
        rmax = fmax(rmax, rve->r[i]);
    double need = 2 * (2 * rmax + skin), shortest = INFINITY;
    for (int k = 0; k < rve->dim; k++)
        shortest = fmin(shortest, rve->L[k]);
    snprintf(err, errlen,
             "/rve: the periodic box is too small for its grains: every edge must exceed 2 x "
             "(largest diameter %.6g + pair-list skin %.6g) = %.6g, the shortest edge is %.6g "
             "(rule periodic_box: a contact and its periodic image must not both be in reach)",
             2 * rmax, skin, need, shortest);
}

/* An object of the n named values (taking their references). */
static json_t *object_of(const char *const *names, json_t *const *vals, size_t n)
{
    json_t *o = json_object();
    for (size_t k = 0; k < n; k++)
        json_object_set_new(o, names[k], vals[k]);
    return o;
}

/* Final micro state and contact network (output options). */
static int final_state_json(const pk_homog_rve *rve, const pk_homog_opts *o,
                            const pk_homog_state *s, int micro, int contacts, json_t *rec)
{
    const int dim = rve->dim;
    pk_dem_geom g = {.dim = dim, .periodic = rve->periodic};
    memcpy(g.L, rve->L, sizeof g.L);
    pk_dem_geom_set_F(&g, s->F);
    pk_dem_pairs c = {0};
    pk_homog_pairs_setup(&c, rve, o);
    uint8_t *fr = malloc(rve->n ? rve->n : 1), *rat = malloc(rve->n ? rve->n : 1);
    int rc = (!fr || !rat) ? -1 : pk_dem_pairs_build(&c, &g, s->x, rve->r, rve->n, o->dr.skin);
    if (rc == 0) {
        pk_dem_eval(&c, &g, s->x, rve->r, rve->n, o->E_n, NULL, NULL, NULL);
        for (size_t i = 0; i < rve->n; i++)
            fr[i] = !rve->fixed[i];
        if (pk_dem_rattlers(&c, dim, rve->n, fr, rat) == (size_t)-1)
            rc = -1;
    }
    if (rc == 0 && micro) {
        json_t *x = json_array(), *xi = json_array(), *ra = json_array(), *gr = json_array(),
               *fx = json_array(), *hu = json_array();
        for (size_t i = 0; i < rve->n; i++) {
            double X[3];
            pk_m3_vec(g.Finv, &s->x[3 * i], X);
            for (int a = 0; a < dim; a++) {
                json_array_append_new(x, json_real(s->x[3 * i + a]));
                json_array_append_new(xi, json_real(X[a] - rve->X[3 * i + a])); /* Ξ (4.18) */
            }
            json_array_append_new(ra, json_integer(rat[i]));
            json_array_append_new(gr, json_integer(rve->grain[i]));
            json_array_append_new(fx, json_integer(rve->fixed[i]));
            json_array_append_new(hu, json_integer(rve->hull[i]));
        }
        json_object_set_new(rec, "final_state",
                            object_of((const char *const[]){"position", "fluctuation", "rattler",
                                                            "grain", "prescribed", "hull"},
                                      (json_t *const[]){x, xi, ra, gr, fx, hu}, 6));
    }
    if (rc == 0 && contacts) {
        json_t *ci = json_array(), *cj = json_array(), *ov = json_array(), *fn = json_array(),
               *br = json_array();
        for (size_t p = 0; p < c.n; p++) {
            if (!(c.eps[p] >= 0) || !(c.len[p] > 0))
                continue;
            json_array_append_new(ci, json_integer(c.i[p]));
            json_array_append_new(cj, json_integer(c.j[p]));
            json_array_append_new(ov, json_real(c.eps[p]));
            json_array_append_new(fn, json_real(o->E_n * c.eps[p]));
            for (int a = 0; a < dim; a++)
                json_array_append_new(br, json_real(c.l[3 * p + a]));
        }
        json_object_set_new(
            rec, "final_contacts",
            object_of((const char *const[]){"i", "j", "overlap", "normal_force", "branch"},
                      (json_t *const[]){ci, cj, ov, fn, br}, 5));
    }
    pk_dem_pairs_free(&c);
    free(fr);
    free(rat);
    return rc;
}

static json_t *tensor_json(const double T[9], int dim)
{
    json_t *a = json_array();
    for (int i = 0; i < dim; i++)
        for (int j = 0; j < dim; j++)
            json_array_append_new(a, json_real(T[3 * i + j]));
    return a;
}

/* Why a grain could leave a restricted-Taylor RVE: its hull (rve->hull_gap). */
static const char *hull_note(const pk_homog_rve *rve)
{
    static _Thread_local char note[200];
    if (rve->bc != PK_BC_RESTRICTED_TAYLOR || !isfinite(rve->hull_gap))
        return "";
    snprintf(note, sizeof note,
             rve->hull_gap < 1 ? "; the hull is full (widest gap between neighbouring hull grains "
                                 "%.3g × the smallest diameter, Meier 2009 §3.5): a grain was "
                                 "squeezed through it"
                               : "; the hull is not full (widest gap between neighbouring hull "
                                 "grains %.3g × the smallest diameter ≥ 1, Meier 2009 §3.5)",
             rve->hull_gap);
    return note;
}

int pk_homog_run(const void *parsed, const pk_run_ctx *run, const char *job_json,
                 const char *out_path, json_t **summary, char *err, size_t errlen)
{
    const int threads = run->threads;
    pk_monitor *mon = run->mon;
    *summary = NULL;
    const pk_homog_job job = *(const pk_homog_job *)parsed; /* its arrays stay the caller's */
    pk_monitor_start(mon, job.wall_time_s);
    pk_box box;
    pk_particles p;
    if (pk_h5_read_particles(job.rve_file, &box, &p, err, errlen) != 0)
        return -1;
    const int dim = box.dim;
    int rc = -1;
    pk_homog_rve rve = {0};
    pk_homog_state com = {0}, tr = {0};
    pk_homog_frames fr = {0};   /* the deformed grains per step (homog_frames.h) */
    pk_sparse_ctx *nctx = NULL; /* Newton's solver context over the whole load path */
    pk_par *pool = NULL;        /* the job's threads (NULL: serial; the same results) */
    json_t *rec = NULL, *aud = NULL, *sum = NULL, *obs = NULL;
    if (job.fdim && job.fdim != dim) {
        snprintf(err, errlen, "the load path is %dD but the RVE is %dD", job.fdim, dim);
        goto out;
    }
    if (pk_homog_rve_build(&box, &p, job.bc, job.radius_factor, &rve, err, errlen) != 0)
        goto out;
    for (size_t i = 0; job.E_n_species && i < p.n; i++)
        if (p.species[i] < 0 || (size_t)p.species[i] >= job.n_species) {
            snprintf(err, errlen,
                     "/contact/E_n_species: grain %zu has species %d but the matrix "
                     "covers species 0..%zu",
                     i, (int)p.species[i], job.n_species - 1);
            goto out;
        }
    pk_homog_opts o;
    pk_homog_opts_of(&job, &rve, &o);
    pk_homog_frames_init(&fr, &rve, job.nstep);
    fr.keep &= job.out_frames; /* not asked: neither recorded nor written */
    /* a contact pattern seen in an earlier factorisation of this job (elastic
     * load steps) reuses its analysis; without a context (NULL on failure)
     * every factorisation is analysed afresh — the same numbers either way */
    if (o.newton && o.newton->ctx_new)
        o.newton_ctx = nctx = o.newton->ctx_new();
    o.par = pool = pk_par_new(threads);
    int irc = pk_homog_state_init(&rve, &o, &com);
    if (irc == -2) {
        periodic_box_rule(&rve, o.dr.skin, err, errlen);
        goto out;
    } else if (irc != 0) {
        snprintf(err, errlen, "out of memory");
        goto out;
    }
    size_t nfree = 0;
    for (size_t i = 0; i < rve.n; i++)
        nfree += !rve.fixed[i];
    double F0[9];
    pk_m3_identity(F0);
    for (int a = 0; job.precompress > 0 && a < dim; a++)
        F0[4 * a] = 1 - job.precompress;
    pk_homog_step st, last;
    pk_homog_audit au;
    const char *reason = "complete";
    char failure[900] = "", what[400];
    /* a re-queued job continues after its last saved step (checkpoint file
     * of `packd run --checkpoint`: committed state, record, counters) */
    pk_homog_ckpt ck = {0};
    const char *ck_digest = run->checkpoint.digest ? run->checkpoint.digest : "";
    double ck_every = run->checkpoint.interval_s, ck_last = pk_wall_seconds();
    const char *ck_path = run->checkpoint.path;
    char ck_err[300] = "";
    int ck_loaded = ck_path
        ? pk_homog_ckpt_load(ck_path, ck_digest, &ck, &com, &rec, ck_err, sizeof ck_err)
        : 1;
    const size_t first = ck_loaded == 0 ? ck.done : 0;
    if (ck_loaded == 0)
        st = last = ck.last;
    if (job.precompress > 0 &&
        ck_loaded != 0) { /* initial-state policy: relaxed, committed, not recorded */
        int e = pk_homog_eval(&rve, &o, &com, F0, &tr, &st, mon);
        if (e != 0) {
            snprintf(err, errlen, "pre-compression: %s", eval_error(e));
            goto out;
        }
        if (st.dr.stop == PK_DR_CANCELLED || st.dr.stop == PK_DR_WALL_TIME)
            reason = pk_dr_stop_name(st.dr.stop);
        else if (pk_homog_audit_step(&rve, &o, &tr, &st, &au)) {
            pk_homog_audit_describe(&au, &st, what, sizeof what);
            snprintf(failure, sizeof failure, "the pre-compression step failed its audit: %s%s",
                     what, (au.failed & PK_AUDIT_ESCAPED) ? hull_note(&rve) : "");
            reason = "audit_failed";
        } else
            pk_homog_commit(&com, &tr);
    }
    if (!rec)
        rec = pk_homog_record_new(dim, job.tangent);
    aud = pk_homog_record_audit_new();
    size_t unjammed = 0;
    double worst_resid = 0, worst_overlap = 0, worst_balance = 0;
    size_t done = first, total_iter = ck.total_iter, max_iter_step = ck.max_iter_step,
           not_converged = ck.not_converged;
    double A[81];
    memcpy(A, ck.A, sizeof A);
    int have_A = ck.have_A;
    pk_progress pr = {.stage = "homogenize", .phi = -1, .eta_s = -1, .total = job.nstep};
    for (size_t k = first; !strcmp(reason, "complete") && k < job.nstep; k++) {
        double F[9];
        pk_m3_mul(&job.F[9 * k], F0, F); /* F̄ = F̄_load·F̄_0 */
        int e = pk_homog_eval(&rve, &o, &com, F, &tr, &st, mon);
        if (e != 0) {
            snprintf(err, errlen, "load step %zu: %s", k, eval_error(e));
            goto out;
        }
        if (st.dr.stop == PK_DR_CANCELLED || st.dr.stop == PK_DR_WALL_TIME) {
            reason = pk_dr_stop_name(st.dr.stop);
            break;
        }
        unsigned bad = pk_homog_audit_step(&rve, &o, &tr, &st, &au);
        if (pk_homog_record_audit(aud, &au) != 0 ||
            (!(bad & PK_AUDIT_NOT_FINITE) && pk_homog_record_step(rec, dim, &st) != 0)) {
            snprintf(err, errlen, "out of memory");
            goto out;
        }
        worst_resid = fmax(worst_resid, au.residual_ratio);
        worst_overlap = fmax(worst_overlap, au.overlap_ratio);
        worst_balance = fmax(worst_balance, au.balance_ratio);
        total_iter += st.dr.iterations;
        if (st.dr.iterations > max_iter_step)
            max_iter_step = st.dr.iterations;
        if (bad) { /* the committed history would carry the defect on: stop here */
            pk_homog_audit_describe(&au, &st, what, sizeof what);
            snprintf(failure, sizeof failure, "load step %zu of %zu failed its audit: %s%s", k,
                     job.nstep, what, (bad & PK_AUDIT_ESCAPED) ? hull_note(&rve) : "");
            not_converged += !!(bad & PK_AUDIT_NOT_CONVERGED);
            reason = "audit_failed";
            break;
        }
        unjammed += st.contacts == 0 || (nfree && st.rattlers >= nfree);
        if (pk_homog_commit(&com, &tr) != 0 ||
            pk_homog_frames_add(&fr, &rve, &o, &com, k, job.nstep) != 0) {
            snprintf(err, errlen, "out of memory");
            goto out;
        }
        last = st;
        if (job.tangent) {
            pk_tangent_info ti;
            int t = pk_homog_tangent(&rve, &o, &com, &pk_sparse_cholmod, A, &ti);
            if (t < 0) {
                snprintf(err, errlen, "tangent of step %zu: %s", k,
                         t == -2 ? eval_error(-2) : "solver failure or out of memory");
                goto out;
            }
            if (t == 0 && ti.jammed_contacts == 0) {
                snprintf(
                    err, errlen,
                    "tangent asked but the RVE has no jammed contact at load step %zu (a loose "
                    "packing: use a jammed RVE or initial_state precompress)",
                    k);
                goto out;
            }
            have_A = t == 0;
            pk_homog_record_tangent(rec, dim, k, A, &ti, t == 0);
        }
        done = k + 1;
        if (ck_path && done < job.nstep && pk_wall_seconds() - ck_last >= ck_every) {
            ck = (pk_homog_ckpt){done, not_converged, total_iter, max_iter_step, have_A, {0}, st};
            memcpy(ck.A, A, sizeof A);
            pk_homog_ckpt_save(ck_path, ck_digest, &ck, &com, rec, ck_err, sizeof ck_err);
            ck_last = pk_wall_seconds();
        }
        pr.done = done;
        pr.fraction = (double)done / (double)job.nstep;
        if (mon) {
            int m = pk_monitor_tick(mon, &pr, 0);
            if (m) {
                reason = m == 1 ? "cancelled" : "wall_time";
                break;
            }
        }
    }
    if ((job.out_micro || job.out_contacts) &&
        final_state_json(&rve, &o, &com, job.out_micro, job.out_contacts, rec) != 0) {
        snprintf(err, errlen, "out of memory");
        goto out;
    }
    /* the observables (pk_homog_observables): the summary's and the file's */
    obs = json_object();
    pk_obs_set(obs, "boundary_condition", json_string(pk_homog_bc_name(job.bc)));
    pk_obs_set(obs, "termination_reason", json_string(reason));
    pk_obs_set(obs, "steps", json_integer((json_int_t)done));
    pk_obs_set(obs, "steps_requested", json_integer((json_int_t)job.nstep));
    pk_obs_set(obs, "steps_not_converged", json_integer((json_int_t)not_converged));
    pk_obs_set(obs, "rve_particles", json_integer((json_int_t)rve.n));
    pk_obs_set(obs, "rve_volume", json_real(rve.V));
    pk_obs_set(obs, "E_n", json_real(job.E_n));
    if (job.friction) {
        pk_obs_set(obs, "friction/E_t", json_real(job.fric.E_t));
        pk_obs_set(obs, "friction/tan_rho", json_real(job.fric.tan_rho));
        pk_obs_set(obs, "friction/h", json_real(job.fric.h));
    }
    if (ck_path) {
        pk_obs_set(obs, "resumed", json_boolean(ck_loaded == 0));
        if (ck_loaded == 0)
            pk_obs_set(obs, "resumed_from_step", json_integer((json_int_t)first));
        if (ck_err[0])
            pk_obs_set(obs, "checkpoint_error", json_string(ck_err));
        if (!strcmp(reason, "complete")) /* the path reached its end: nothing to resume */
            remove(ck_path);
    }
    pk_obs_set(obs, "radius_factor", json_real(job.radius_factor));
    pk_obs_set(obs, "precompression", json_real(job.precompress));
    pk_obs_set(obs, "dr_iterations_total", json_integer((json_int_t)total_iter));
    pk_obs_set(obs, "dr_iterations_max", json_integer((json_int_t)max_iter_step));
    pk_obs_set(obs, "threads", json_integer(pk_par_threads(pool)));
    pk_obs_set(obs, "audit/passed", json_boolean(!failure[0]));
    pk_obs_set(obs, "audit/steps_audited",
               json_integer((json_int_t)json_array_size(json_object_get(aud, "passed"))));
    pk_obs_set(obs, "audit/max_residual_ratio",
               json_real(isfinite(worst_resid) ? worst_resid : DBL_MAX));
    pk_obs_set(obs, "audit/max_balance_ratio",
               json_real(isfinite(worst_balance) ? worst_balance : DBL_MAX));
    pk_obs_set(obs, "audit/max_overlap_ratio",
               json_real(isfinite(worst_overlap) ? worst_overlap : DBL_MAX));
    const int has_hull = rve.bc == PK_BC_RESTRICTED_TAYLOR && isfinite(rve.hull_gap);
    if (has_hull) {
        pk_obs_set(obs, "hull/widest_gap_over_d_min", json_real(rve.hull_gap));
        pk_obs_set(obs, "hull/full", json_boolean(rve.hull_gap < 1));
    }

    /* the verdict (api/job_verdict.h): every recorded step audited */
    sum = json_object();
    json_object_set_new(sum, "process", json_string("homogenize"));
    json_object_set_new(sum, "complete", json_boolean(done == job.nstep));
    json_object_set_new(sum, "model", pk_homog_model_json(&job, dim, fr.keep && fr.count > 0));
    pk_obs_set(obs, "audit/overlap_ratio_bound",
               json_real(PK_AUDIT_OVERLAP_MAX)); /* the record's */
    json_object_update(sum, obs);
    if (failure[0])
        pk_verdict_fail(sum,
                        "%s (the result file holds the %zu steps before it and the failed "
                        "step's audit)",
                        failure, done);
    else if (!strcmp(reason, "wall_time"))
        pk_verdict_fail(sum,
                        "ran out of wall time (limits.wall_time_s %g s) after %zu of %zu load "
                        "steps",
                        job.wall_time_s, done, job.nstep);
    else if (!strcmp(reason, "cancelled"))
        pk_verdict_fail(sum, "cancelled after %zu of %zu load steps", done, job.nstep);
    if (has_hull && !(rve.hull_gap < 1))
        pk_verdict_warn(sum,
                        "the hull is not full (Meier 2009 §3.5): neighbouring hull grains "
                        "leave a gap of %.3g × the smallest diameter, wide enough for an inner "
                        "grain to leave the RVE",
                        rve.hull_gap);
    if (unjammed)
        pk_verdict_warn(sum,
                        "%zu of %zu load steps had no jammed grain (every free grain a "
                        "rattler or no contact at all): their stresses are those of a loose "
                        "packing (zero without contacts)",
                        unjammed, done);
    if (done) {
        json_object_set_new(sum, "F", tensor_json(com.F, dim));
        json_object_set_new(sum, "P", tensor_json(last.P, dim));
        json_object_set_new(sum, "sigma", tensor_json(last.sigma, dim));
        json_object_set_new(sum, "energy_density", json_real(last.energy_density));
        json_object_set_new(sum, "contacts", json_integer((json_int_t)last.contacts));
        json_object_set_new(sum, "rattlers", json_integer((json_int_t)last.rattlers));
        if (have_A) {
            json_t *a = json_array();
            for (int i = 0; i < dim * dim; i++)
                for (int j = 0; j < dim * dim; j++)
                    json_array_append_new(
                        a, json_real(A[(3 * (i / dim) + i % dim) * 9 + 3 * (j / dim) + j % dim]));
            json_object_set_new(sum, "tangent", a);
        }
    }

    pk_h5 *h = pk_h5_create(out_path, run->author, err, errlen);
    if (!h)
        goto out;
    /* lengths in the RVE file's unit, forces in N (E_n per length unit) */
    char lunit[32];
    pk_h5_read_unit(job.rve_file, lunit, sizeof lunit);
    pk_units units;
    pk_units_init(&units, lunit, dim);
    const char *L = units.length[0] ? units.length : NULL;
    int w = pk_h5_write_particles(h, &box, &p, L);
    w |= pk_homog_frames_write(h, &fr, &rve, &units);
    w |= pk_h5_write_parameters(h, "homogenize", job_json, 0);
    w |= pk_homog_record_write(h, rec, aud, dim, first, job.nstep, &units);
    w |= pk_h5_obs_rows(h, pk_homog_observables, obs, &units);
    json_object_set_new(sum, "units", pk_obs_units_json(pk_homog_observables, sum, &units));
    w |= pk_h5_obs_json(h, "modelled", json_object_get(sum, "model"));
    if (pk_verdict_close_h5(h, w, sum, out_path, err, errlen) != 0)
        goto out;
    *summary = sum;
    sum = NULL;
    rc = 0;
out:
    pk_par_free(pool);
    if (nctx)
        pk_sparse_cholmod.ctx_free(nctx);
    json_decref(rec);
    json_decref(aud);
    json_decref(sum);
    json_decref(obs);
    pk_homog_state_free(&com);
    pk_homog_frames_free(&fr);
    pk_homog_state_free(&tr);
    pk_homog_rve_free(&rve);
    pk_particles_free(&p);
    return rc;
}
