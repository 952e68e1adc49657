/* fe2_run.c — run an 'fe2' job: the macro problem (fe2_setup.c), the RVE
 * (a packd result file read as 'homogenize' does, or a nested 'pack' job
 * run once), the stages' load steps solved by core/fe2's Newton step with
 * the RVE material at every Gauss point, and the result file
 * (fe2_record.c).  Launched as several MPI ranks, the Gauss points are
 * spread over them (fe2_mpi.h): rank 0 runs all of this, the others hold
 * and evaluate their blocks until it is done. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "api/job_verdict.h"
#include "api/par/mpi_world.h"
#include "api/process.h"
#include "api/results/h5_result.h"
#include "api/solver/sparse_cholmod.h"
#include "core/base/par.h"
#include "core/fe2/fe2_rve.h"
#include "fe2_job.h"
#include "fe2_mpi.h"
#include "fe2_record.h"

/* Progress: core/fe2 ticks once per evaluation round (every Gauss point of
 * the mesh evaluated once); this adds the load step. */
typedef struct progress_ctx {
    pk_monitor *outer;
    size_t step, nstep, ngp, rounds0;
    const char *stage;
    char msg[200];
} progress_ctx;

static int fe2_progress(const pk_progress *p, void *vctx)
{
    progress_ctx *c = vctx;
    if (!c->outer || !c->outer->fn)
        return 0;
    pk_progress q = *p;
    size_t rounds = !strcmp(p->stage ? p->stage : "", "fe2") ? p->done : 0;
    if (rounds < c->rounds0)
        c->rounds0 = 0;
    snprintf(c->msg, sizeof c->msg,
             "load step %zu of %zu (stage %s): %zu Newton evaluation rounds, %zu Gauss-point "
             "evaluations",
             c->step, c->nstep, c->stage, rounds, rounds * c->ngp);
    q.stage = "fe2";
    q.done = c->step ? c->step - 1 : 0;
    q.total = c->nstep;
    q.fraction = c->nstep ? (double)q.done / (double)c->nstep : -1;
    q.message = c->msg;
    return c->outer->fn(&q, c->outer->ctx);
}

/* The RVE's grains: the file, or the nested pack job run into a temporary
 * file beside the result (removed once read). */
static int load_rve(const pk_fe2_job *job, const pk_run_ctx *run, const char *out_path, pk_box *box,
                    pk_particles *p, char *err, size_t errlen)
{
    if (!job->pack_job) {
        /* the file's lengths are in the job's unit: a file with another
         * unit is refused, one without (unit "1") is read in the job's */
        char fu[32] = "";
        if (pk_h5_read_unit(job->micro.rve_file, fu, sizeof fu) == 0 && *fu && strcmp(fu, "1") &&
            strcmp(fu, job->unit)) {
            snprintf(err, errlen,
                     "/micro/rve/file: the RVE's unit is \"%s\", the job's (/unit) \"%s\"; "
                     "state \"unit\": \"%s\"",
                     fu, job->unit, fu);
            return -1;
        }
        return pk_h5_read_particles(job->micro.rve_file, box, p, err, errlen);
    }
    char tmp[4200];
    snprintf(tmp, sizeof tmp, "%s.rve.%ld.h5", out_path, (long)getpid());
    const pk_process *pack = pk_process_find("pack");
    char *text = json_dumps(job->pack_inputs, JSON_SORT_KEYS | JSON_COMPACT);
    json_t *sum = NULL;
    char e2[400] = "";
    /* its own copy of the monitor: the pack run restarts the clock with its
     * own wall limit, the job's limit keeps counting from the job's start */
    pk_monitor pm = run->mon ? *run->mon : (pk_monitor){0};
    pk_run_ctx sub = *run;
    sub.mon = run->mon ? &pm : NULL;
    int rc = text ? pack->run(job->pack_job, &sub, text, tmp, &sum, e2, sizeof e2) : -1;
    free(text);
    if (rc == 0 && pk_verdict_failed(sum)) {
        snprintf(err, errlen, "the nested pack job (micro.rve.pack) failed: %s",
                 json_string_value(json_object_get(sum, "failure")));
        rc = -1;
    } else if (rc != 0)
        snprintf(err, errlen, "the nested pack job (micro.rve.pack): %s", e2);
    json_decref(sum);
    if (rc == 0)
        rc = pk_h5_read_particles(tmp, box, p, err, errlen);
    remove(tmp);
    return rc;
}

static json_t *series_json(const double *v, size_t n, size_t stride, size_t off)
{
    json_t *a = json_array();
    for (size_t i = 0; i < n; i++)
        json_array_append_new(a, json_real(v[i * stride + off]));
    return a;
}

int pk_fe2_run(const void *parsed, const pk_run_ctx *run, const char *job_json,
               const char *out_path, json_t **summary, char *err, size_t errlen)
{
    const int threads = run->threads;
    pk_monitor *mon = run->mon;
    *summary = NULL;
    const pk_fe2_job *job = parsed;
    pk_monitor_start(mon, job->wall_time_s);
    pk_fe2_setup s;
    pk_schema_errors errs = {0};
    pk_box box;
    pk_particles p = {0};
    pk_homog_rve rve = {0};
    pk_fe2_rve mr = {0};
    pk_fe2_state st = {0};
    pk_fe2_record rec = {0};
    pk_par *pool = NULL;
    json_t *sum = NULL, *obs = NULL;
    double *uD = NULL, *fext = NULL, *f0 = NULL;
    const double **micro = NULL;
    double *micro_x = NULL; /* [n_micro_gp][ngrain][3] the output RVEs (rank 0, MPI) */
    pk_fe2_mpi mpi = {0};
    int rc = -1, have_rve = 0, have_mr = 0, have_mpi = 0;
    if (pk_fe2_setup_build(job, &s, &errs) != 0) { /* a mesh file read only now (service) */
        snprintf(err, errlen, "%s: %s", errs.items[0].pointer, errs.items[0].message);
        goto out;
    }
    const size_t ngp = pk_fe2_gauss_count(&s.mesh);
    for (size_t i = 0; i < job->n_micro_gp; i++)
        if (job->micro_gp[i] >= ngp) {
            snprintf(err, errlen, "/output/micro_states/%zu: Gauss point %zu, the mesh has %zu", i,
                     job->micro_gp[i], ngp);
            goto out;
        }
    if (pk_mpi_size() > 1) {
        if (pk_fe2_mpi_init(&mpi, ngp, s.ndof, mon) != 0) {
            snprintf(err, errlen, "out of memory, or over %d MPI ranks", PK_PAR_MAX);
            goto out;
        }
        have_mpi = 1;
    }
    if (mpi.rank > 0) { /* the RVE as rank 0 read or packed it */
        int sr = pk_fe2_mpi_share_rve(&mpi, 0, &box, &p, err, errlen);
        if (sr != 0) {
            rc = sr > 0 ? 0 : -1; /* rank 0 ended the run before: it says why */
            if (sr > 0)
                sum = json_pack("{s:s,s:i}", "process", "fe2", "mpi_rank", mpi.rank);
            goto out_rank;
        }
    } else {
        int lr = load_rve(job, run, out_path, &box, &p, err, errlen);
        if (have_mpi && pk_fe2_mpi_share_rve(&mpi, lr == 0, &box, &p, err, errlen) != 0)
            lr = -1;
        if (lr != 0)
            goto out;
    }
    if (box.dim != 2) {
        snprintf(err, errlen, "the RVE is %dD: fe2 is plane strain and needs a 2D packing",
                 box.dim);
        goto out;
    }
    if ((double)ngp * (double)p.n > (double)job->max_grains_total) {
        snprintf(err, errlen,
                 "%zu Gauss points × %zu grains = %.0f: over limits.max_grains_total %zu", ngp, p.n,
                 (double)ngp * (double)p.n, job->max_grains_total);
        goto out;
    }
    if (pk_homog_rve_build(&box, &p, job->micro.bc, job->micro.radius_factor, &rve, err, errlen))
        goto out;
    have_rve = 1;
    pk_homog_opts o;
    pk_homog_opts_of(&job->micro, &rve, &o);
    o.par = pool = pk_par_new(threads);
    /* each rank holds the states of its block only (all of them alone) */
    if (pk_fe2_rve_init_block(&mr, &rve, 1, &o, &pk_sparse_cholmod, ngp, have_mpi ? mpi.lo : 0,
                              have_mpi ? mpi.hi : ngp, mon, err, errlen) != 0)
        goto out;
    have_mr = 1;
    pk_fe2_material mat = pk_fe2_rve_material(&mr);
    const pk_fe2_problem pb = {.mesh = &s.mesh,
                               .mat = &mat,
                               .nfix = s.nfix,
                               .fix_dof = s.fix_dof,
                               .solver = &pk_sparse_cholmod,
                               .par = pool,
                               .dist = have_mpi ? &mpi.dist : NULL};
    if (have_mpi)
        pk_fe2_mpi_attach(&mpi, &mr, rve.n);
    if (mpi.rank > 0) { /* serve rank 0 until it is done */
        if (pk_fe2_mpi_serve(&mpi, &pb, err, errlen) != 0)
            goto out;
        sum = json_pack("{s:s,s:i}", "process", "fe2", "mpi_rank", mpi.rank);
        rc = 0;
        goto out_rank;
    }
    uD = calloc(s.nfix + 1, sizeof *uD);
    fext = calloc(s.ndof + 1, sizeof *fext);
    micro = calloc(job->n_micro_gp + 1, sizeof *micro);
    micro_x = have_mpi ? calloc(3 * rve.n * job->n_micro_gp + 1, sizeof *micro_x) : NULL;
    if (!uD || !fext || !micro || (have_mpi && !micro_x) || pk_fe2_state_init(&st, &s.mesh) != 0 ||
        pk_fe2_record_init(&rec, &s, job->micro_gp, job->n_micro_gp, rve.n) != 0) {
        snprintf(err, errlen, "out of memory");
        goto out;
    }
    /* f_int of the start state at u = 0 (a trial evaluation, nothing
     * committed).  balanced: it joins every load.  free: the first step's
     * parts start from it, so the prestress is released along that step and
     * a step cut releases part of it (released at once, a cut could not make
     * the step smaller: the block-small RVE of seed 7 ended at det F < 0
     * whatever the cut). */
    {
        char why[256] = "";
        f0 = calloc(s.ndof + 1, sizeof *f0);
        int r0 = f0 ? pk_fe2_residual(&pb, st.u, NULL, f0, NULL, why, sizeof why) : -1;
        if (r0 != 0) {
            snprintf(err, errlen, "the start state (u = 0): %s", r0 > 0 ? why : "out of memory");
            goto out;
        }
    }

    size_t nstep = 0, done = 0, cuts_total = 0, iters_total = 0;
    for (size_t k = 0; k < s.nstage; k++)
        nstep += s.increments[k];
    progress_ctx pc = {.outer = mon, .nstep = nstep, .ngp = ngp};
    pk_monitor wm = mon ? *mon : (pk_monitor){0};
    wm.fn = fe2_progress;
    wm.ctx = &pc;
    char failure[700] = "";
    const char *reason = "complete";
    size_t rounds_total = 0;
    const double solve_t0 = pk_wall_seconds();
    for (size_t k = 0; k < s.nstage && !failure[0]; k++) {
        char sname[80];
        snprintf(sname, sizeof sname, s.stage_name[k][0] ? "%zu \"%s\"" : "%zu", k,
                 s.stage_name[k]);
        pc.stage = sname;
        for (size_t i = 1; i <= s.increments[k]; i++) {
            pc.step = done + 1;
            double t = (double)i / (double)s.increments[k];
            pk_fe2_setup_targets(&s, k, t, uD, fext);
            for (size_t d = 0; job->balanced && d < s.ndof; d++)
                fext[d] += f0[d];
            if (done == 0 && !job->balanced)
                memcpy(st.fext, f0, s.ndof * sizeof *f0);
            pk_fe2_step_report rep;
            memset(&rep, 0, sizeof rep);
            int r = pk_fe2_step(&pb, &job->newton, &st, uD, fext, &rep, &wm);
            if (pk_fe2_record_newton(&rec, done + 1, &rep) != 0) {
                snprintf(err, errlen, "out of memory");
                goto out;
            }
            for (size_t q = 0; q < rep.nparts; q++)
                iters_total += (size_t)(rep.parts[q].n > 0 ? rep.parts[q].n - 1 : 0);
            rounds_total += rep.rounds;
            cuts_total += (size_t)rep.cuts;
            if (r == 0) {
                /* the committed centres of the output Gauss points (a commit
                 * may have moved their storage) */
                for (size_t g = 0; g < job->n_micro_gp; g++) {
                    micro[g] =
                        have_mpi ? &micro_x[3 * rve.n * g] : mr.committed[job->micro_gp[g]].x;
                    if (have_mpi &&
                        pk_fe2_mpi_centres(&mpi, job->micro_gp[g], &micro_x[3 * rve.n * g], rep.why,
                                           sizeof rep.why) != 0) {
                        r = -1;
                        break;
                    }
                }
            }
            if (r == 0) {
                if (pk_fe2_record_step(&rec, done + 1, (double)k + t, k, rep.cuts, &st, micro) !=
                    0) {
                    snprintf(err, errlen, "out of memory");
                    goto out;
                }
                done++;
                continue;
            }
            if (mpi.broken) {
                reason = "rank_lost";
                snprintf(failure, sizeof failure,
                         "load step %zu of %zu (stage %s, increment %zu of %zu): %s", done + 1,
                         nstep, sname, i, s.increments[k], rep.why);
            } else if (r == 2) {
                reason = mon && mon->cancel && *mon->cancel ? "cancelled" : "wall_time";
                snprintf(failure, sizeof failure,
                         "%s in load step %zu of %zu (stage %s, increment %zu of %zu)",
                         !strcmp(reason, "cancelled") ? "cancelled"
                                                      : "ran out of wall time (limits.wall_time_s)",
                         done + 1, nstep, sname, i, s.increments[k]);
            } else {
                reason = r == 1 ? "not_converged" : "solver_failure";
                snprintf(failure, sizeof failure,
                         "load step %zu of %zu (stage %s, increment %zu of %zu) did not converge "
                         "after %d cuts: %s",
                         done + 1, nstep, sname, i, s.increments[k], rep.cuts,
                         rep.why[0] ? rep.why : "solver failure or out of memory");
            }
            break;
        }
    }

    /* the observables (pk_fe2_observables): the summary's and the file's */
    obs = json_object();
    pk_obs_set(obs, "termination_reason", json_string(reason));
    pk_obs_set(obs, "steps", json_integer((json_int_t)done));
    pk_obs_set(obs, "steps_requested", json_integer((json_int_t)nstep));
    pk_obs_set(obs, "nodes", json_integer((json_int_t)s.mesh.nnode));
    pk_obs_set(obs, "elements", json_integer((json_int_t)s.mesh.nelem));
    pk_obs_set(obs, "gauss_points", json_integer((json_int_t)ngp));
    pk_obs_set(obs, "rve_particles", json_integer((json_int_t)rve.n));
    pk_obs_set(obs, "boundary_condition", json_string(pk_homog_bc_name(job->micro.bc)));
    pk_obs_set(obs, "E_n", json_real(job->micro.E_n));
    pk_obs_set(obs, "newton_iterations_total", json_integer((json_int_t)iters_total));
    pk_obs_set(obs, "step_cuts_total", json_integer((json_int_t)cuts_total));
    pk_obs_set(obs, "threads", json_integer(pk_par_threads(pool)));
    pk_obs_set(obs, "mpi_ranks", json_integer(pk_mpi_size()));
    /* what a round costs (docs/perf/fe2-mpi.md): wall time of the load steps
     * (rounds, macro solves, commits) and, over ranks, the bytes rank 0 moved */
    pk_obs_set(obs, "evaluation_rounds", json_integer((json_int_t)rounds_total));
    pk_obs_set(obs, "steps_wall_s", json_real(pk_wall_seconds() - solve_t0));
    if (have_mpi) {
        pk_obs_set(obs, "mpi_bytes_sent", json_integer((json_int_t)mpi.bytes_out));
        pk_obs_set(obs, "mpi_bytes_received", json_integer((json_int_t)mpi.bytes_in));
    }
    sum = json_object();
    json_object_set_new(sum, "process", json_string("fe2"));
    json_object_set_new(sum, "complete", json_boolean(done == nstep));
    json_object_update(sum, obs);
    /* the figures per converged step: reactions of the displacement
     * conditions and the dilatancy Δ = (v/V − 1)·100 % of the specimen */
    json_t *reac = json_object();
    for (size_t b = 0; b < s.nbc; b++)
        if (s.bc[b].type == PK_FE2_DISPLACEMENT)
            json_object_set_new(
                reac, s.bc[b].name,
                series_json(rec.reaction.v, done, 2 * s.nbc, 2 * b + (size_t)s.bc[b].comp));
    json_object_set_new(sum, "reaction_per_step", reac);
    json_object_set_new(sum, "dilatancy_percent_per_step",
                        series_json(rec.dilatancy.v, done, 1, 0));
    json_object_set_new(sum, "time_per_step", series_json(rec.time.v, done, 1, 0));
    pk_units units; /* lengths in the job's unit, forces in N, per unit thickness */
    pk_units_init(&units, job->unit, 2);
    json_object_set_new(sum, "units", pk_obs_units_json(pk_fe2_observables, sum, &units));
    if (failure[0])
        pk_verdict_fail(sum, "%s (the result file holds the %zu converged load steps before it)",
                        failure, done);

    pk_h5 *h = pk_h5_create(out_path, run->author, err, errlen);
    if (!h)
        goto out;
    int w = pk_h5_write_particles(h, &box, &p, job->unit);
    w |= pk_h5_write_parameters(h, "fe2", job_json, 0);
    w |= pk_fe2_record_write(h, &rec, &units);
    w |= pk_h5_obs_rows(h, pk_fe2_observables, obs, &units);
    if (pk_verdict_close_h5(h, w, sum, out_path, err, errlen) != 0)
        goto out;
    *summary = sum;
    sum = NULL;
    rc = 0;
out_rank: /* a rank other than 0: no file, a summary saying which rank served */
    if (rc == 0 && mpi.rank > 0) {
        *summary = sum;
        sum = NULL;
    }
out:
    if (have_mpi && mpi.rank == 0)
        pk_fe2_mpi_stop(&mpi);
    pk_schema_errors_free(&errs);
    json_decref(sum);
    json_decref(obs);
    free(uD);
    free(micro_x);
    free(fext);
    free(f0);
    free(micro);
    pk_fe2_record_free(&rec);
    pk_fe2_state_free(&st);
    if (have_mr)
        pk_fe2_rve_free(&mr);
    if (have_rve)
        pk_homog_rve_free(&rve);
    pk_par_free(pool);
    pk_particles_free(&p);
    pk_fe2_setup_free(&s);
    if (have_mpi)
        pk_fe2_mpi_free(&mpi);
    return rc;
}
