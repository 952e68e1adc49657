/* pack_place_edmd.c — the 'edmd' placer: core/edmd/edmd (Lubachevsky–Stillinger
 * growth) with the job's "edmd" options; start from zero radii (Meier) or
 * from RSA at δ·d (Titscher/Kansal, core/rsa/rsa); walls keep Δd/2 clearance or,
 * with "wall_gap": "none", only the true grains inside (core/edmd/edmd_walls.h). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/edmd/edmd.h"
#include "edmd_checkpoint_h5.h"
#include "core/edmd/edmd_contacts.h"
#include "core/edmd/edmd_rigidity.h"
#include "core/edmd/edmd_walls.h"
#include "core/space/gap_audit.h"
#include "core/space/length_snap.h"
#include "pack_placer.h"
#include "api/solver/sparse_cholmod.h"

static void preset(void *dst) { pk_edmd_params_default(&((pk_edmd_options *)dst)->prm); }

/* The enums' values follow the names (pk_edmd_growth, _until, _rule;
 * start_zero and equal_masses are 0/1). */
_Static_assert(sizeof(pk_edmd_growth) == sizeof(int) && sizeof(pk_edmd_until) == sizeof(int) &&
                   sizeof(pk_edmd_rule) == sizeof(int),
               "named values are stored as int");
static const char *const growth_names[] = {"relative", "shell", NULL};
static const char *const until_names[] = {"target", "jammed", NULL};
static const char *const start_names[] = {"rsa", "zero", NULL};
static const char *const maximize_names[] = {"none", "delta_d", NULL};
static const char *const rule_names[] = {"elastic", "lift", "meier", NULL};
static const char *const masses_names[] = {"volume", "equal", NULL};
static const char *const wall_gap_names[] = {"half", "none", NULL};
#define F(m) PK_OPT_FIELD(pk_edmd_options, m)
#define MAX_INT 9007199254740991LL
static const pk_option edmd_rows[] = {
    {"/edmd/start", PK_OPT_ENUM, F(prm.start_zero), .names = start_names},
    {"/edmd/delta", PK_OPT_NUMBER, F(prm.delta), PK_OPT_IMPLICIT, .dflt = NAN},
    {"/edmd/growth", PK_OPT_ENUM, F(prm.growth), PK_OPT_PRESET, .names = growth_names},
    {"/edmd/until", PK_OPT_ENUM, F(prm.until), PK_OPT_PRESET, .names = until_names},
    {"/edmd/maximize", PK_OPT_ENUM, F(maximize_delta_d), .names = maximize_names},
    {"/edmd/growth_rate", PK_OPT_NUMBER, F(prm.growth_rate), PK_OPT_PRESET,
     PK_OPT_QUALITY(0.03, 0.003)},
    {"/edmd/jamming/reduced_pressure", PK_OPT_NUMBER, F(prm.p_max), PK_OPT_PRESET,
     PK_OPT_QUALITY(1e4, 1e12)},
    {"/edmd/jamming/rate_factor", PK_OPT_NUMBER, F(prm.jam_rate_factor), PK_OPT_PRESET},
    {"/edmd/jamming/full_rate_above", PK_OPT_NUMBER, F(prm.jam_full_rate_p), PK_OPT_IMPLICIT,
     .dflt = INFINITY},
    {"/edmd/jamming/delta_phi", PK_OPT_NUMBER, F(prm.dphi_crit), PK_OPT_PRESET},
    {"/edmd/jamming/events", PK_OPT_INTEGER, F(prm.dphi_events), PK_OPT_IMPLICIT, .lo = 1,
     .hi = MAX_INT},
    {"/edmd/stall/events", PK_OPT_INTEGER, F(prm.stall_events), PK_OPT_PRESET, .lo = 10,
     .hi = MAX_INT},
    {"/edmd/stall/growth", PK_OPT_NUMBER, F(prm.stall_growth), PK_OPT_PRESET},
    {"/edmd/collision_rule", PK_OPT_ENUM, F(prm.rule), PK_OPT_PRESET, .names = rule_names},
    {"/edmd/rescale", PK_OPT_BOOL, F(prm.rescale), PK_OPT_PRESET},
    {"/edmd/rescale_tolerance", PK_OPT_NUMBER, F(prm.rescale_tol), PK_OPT_PRESET},
    {"/edmd/skin", PK_OPT_NUMBER, F(prm.skin), PK_OPT_PRESET},
    {"/edmd/masses", PK_OPT_ENUM, F(prm.equal_masses), PK_OPT_PRESET, .names = masses_names},
    {"/edmd/max_events", PK_OPT_INTEGER, F(prm.max_events), PK_OPT_IMPLICIT, .lo = 1,
     .hi = MAX_INT},
    {"/edmd/wall_gap", PK_OPT_ENUM, F(wall_gap_none), .names = wall_gap_names},
};
#undef F
#undef MAX_INT
static const pk_option_table edmd_options =
    PK_OPT_TABLE("pack.inputs.schema.json", pk_edmd_options, edmd_rows, preset);

/* The job's options → the engine's parameters. */
static void read_params(const pk_pack_job *job, const pk_pack_plan *plan, pk_edmd_params *prm)
{
    const pk_edmd_options *o = &job->opt.edmd;
    *prm = o->prm;
    prm->seed = job->seed;
    prm->delta_d = job->delta_d;
    if (o->maximize_delta_d) {
        prm->growth = PK_EDMD_GROW_SHELL;
        prm->until = PK_EDMD_UNTIL_JAMMED;
    }
    /* NAN: the default δ, chosen by place_edmd from the drawn sizes
     * (pk_edmd_start_delta) */
    if (prm->growth == PK_EDMD_GROW_SHELL)
        prm->delta = 1.0;
    if (prm->growth == PK_EDMD_GROW_RELATIVE && job->has_phi)
        prm->phi_target = plan->phi_resolved;
}

/* EDMD growing every diameter until jammed (relative growth) bounds the sizes
 * only by φ <= 1 (core/edmd/edmd.c): the largest grain, shell included,
 * may reach (d_max + Δd)·φ_s^(-1/dim), φ_s the shells' fraction at the target
 * sizes.  On a periodic axis that must stay below L/2, or a pair could meet
 * two images of each other (minimum image).  φ_s is bounded below by
 * φ (1 + Δd/d_max)^dim, so the check errs on the refusing side. */
/* EDMD growing the grains themselves until jammed: the given sizes are
 * ratios, the final sizes are set by jamming. */
static int grows_until_jammed(const pk_pack_job *job)
{
    const pk_edmd_options *o = &job->opt.edmd;
    return o->prm.until == PK_EDMD_UNTIL_JAMMED && o->prm.growth == PK_EDMD_GROW_RELATIVE &&
        !o->maximize_delta_d;
}

static void check_periodic_jamming(const pk_pack_job *job, const pk_pack_plan *plan,
                                   pk_schema_errors *errs)
{
    if (!grows_until_jammed(job))
        return;
    const int dim = job->dim;
    double phi_s = plan->phi_resolved * pow(1 + job->delta_d / plan->d_max, dim);
    double reach = (plan->d_max + job->delta_d) * pow(fmax(phi_s, 1e-300), -1.0 / dim);
    for (int k = 0; k < dim; k++) {
        if (!job->box.periodic[k] || reach < 0.5 * job->box.L[k])
            continue;
        char ptr[64];
        snprintf(ptr, sizeof ptr, "/domain/box/size/%d", k);
        double need = pow((plan->d_max + job->delta_d) / (0.5 * job->box.L[k]), dim);
        pk_schema_errors_add(
            errs, ptr, "periodicJamming",
            "until jammed the grains may grow to fill the box: the largest could "
            "reach d = %.4g, over half the periodic edge %g (minimum image); needs "
            "φ at the target sizes > %.3g (got %.3g): more grains, a walled axis "
            "or until: target",
            reach, job->box.L[k], need, phi_s);
        return;
    }
}

static void check_edmd(const pk_pack_job *job, const pk_pack_plan *plan, void **prepared,
                       pk_schema_errors *errs)
{
    (void)prepared;
    size_t before = errs->n;
    check_periodic_jamming(job, plan, errs);
    if (errs->n != before)
        return;
    pk_edmd_params prm;
    read_params(job, plan, &prm);
    if (prm.growth == PK_EDMD_GROW_SHELL && prm.start_zero)
        pk_schema_errors_add(errs, "/edmd/start", "consistent",
                             "shell growth starts from an RSA configuration (start: rsa)");
    if (prm.growth == PK_EDMD_GROW_SHELL && prm.until == PK_EDMD_UNTIL_TARGET &&
        !(job->delta_d > 0))
        pk_schema_errors_add(errs, "/delta_d", "consistent",
                             "shell growth to a target needs delta_d > 0 (or maximize: delta_d)");
    if (job->opt.edmd.wall_gap_none && !(job->delta_d > 0))
        pk_schema_errors_add(
            errs, "/edmd/wall_gap", "consistent",
            "wall_gap none lets the shell reach delta_d/2 into the walls: needs delta_d > 0");
    if (prm.rule == PK_EDMD_RULE_MEIER && !prm.equal_masses)
        pk_schema_errors_add(errs, "/edmd/collision_rule", "consistent",
                             "Meier's Eq. (9) is an equal-mass rule: use masses: equal");
    /* the periodic edge > 2 (d_max + Δd) rule is the plan's (pack_job.c) */
}

/* The job's checkpoint file (the run context's): saved by the run, loaded
 * to resume. */
typedef struct ckpt_file {
    const char *path, *digest;
    char unit_digest[160]; /* the job's digest, marked: the state is in the unit ℓ */
    char err[300];
} ckpt_file;

static int save_ckpt(const pk_edmd_snapshot *snap, void *ctx)
{
    ckpt_file *f = ctx;
    return pk_edmd_ckpt_save(f->path, f->digest, snap, f->err, sizeof f->err);
}

/* Why a packing that met its stop criterion is not certified jammed. */
static void not_rigid_warning(const pk_rigidity *rg, const pk_edmd_stats *es, double ctol,
                              char *buf, size_t len)
{
    if (rg->backbone == 0)
        snprintf(buf, len,
                 "EDMD stopped on %s at reduced pressure %.3g, but no grain has dim + 1 contacts "
                 "at tolerance %.3g: no rigid backbone, the packing (phi %.6f) is not jammed; "
                 "lower growth_rate or jamming.rate_factor",
                 pk_edmd_criterion_name(es->criterion), es->pressure, ctol, es->phi);
    else if (!rg->tested)
        snprintf(buf, len,
                 "EDMD stopped on %s at reduced pressure %.3g, but the backbone of %zu grains has "
                 "%zu contacts, below the %zu a rigid one needs (Maxwell count, tolerance %.3g): "
                 "the packing (phi %.6f) is not jammed",
                 pk_edmd_criterion_name(es->criterion), es->pressure, rg->backbone, rg->contacts,
                 rg->maxwell_min, ctol, es->phi);
    else
        snprintf(buf, len,
                 "EDMD stopped on %s at reduced pressure %.3g, but the backbone of %zu grains "
                 "(%zu contacts, Maxwell count %zu) has %zu floppy modes: the packing (phi %.6f) "
                 "is not jammed",
                 pk_edmd_criterion_name(es->criterion), es->pressure, rg->backbone, rg->contacts,
                 rg->maxwell_min, rg->floppy, es->phi);
    const size_t used = strlen(buf);
    if (used < len && ctol < PK_JAM_TOL_MAX)
        snprintf(buf + used, len - used, " (nor rigid at any contact tolerance up to %g)",
                 PK_JAM_TOL_MAX);
}

static json_t *doubles(const double *a, size_t n)
{
    json_t *arr = json_array();
    for (size_t i = 0; i < n; i++)
        json_array_append_new(arr, json_real(a[i]));
    return arr;
}

/* The engine runs in units of the first box edge ℓ (core/space/length_snap.h):
 * that edge is 1, equal edges too, other walled edges snapped inside the
 * job's walls (periodic ones exact: L/ℓ); diameters snapped one lattice step
 * below (never larger than drawn: every sieve they pass they still pass), Δd
 * one step above (every gap of the job's unit still >= the job's Δd).  So a
 * job in another length unit computes the same bits. */
typedef struct edmd_unit {
    double ell;
    pk_pack_job job; /* the job in the unit (box, delta_d) */
    pk_sizes sz;     /* the drawn sizes in the unit */
} edmd_unit;

static double snap_step(double v)
{
    int e;
    frexp(v, &e);
    return ldexp(1, e - PK_SNAP_BITS);
}

static int to_unit(const pk_pack_job *job, const pk_sizes *sz, edmd_unit *u)
{
    const double ell = job->box.L[0];
    u->ell = ell;
    u->job = *job;
    for (int k = 0; k < job->box.dim; k++) {
        const double L = job->box.L[k], v = L / ell;
        u->job.box.L[k] = L == ell ? 1 : job->box.periodic[k] ? v : pk_snap_within(v, ell, L);
    }
    const double dd = job->delta_d / ell;
    u->job.delta_d = dd > 0 ? pk_snap(dd) + snap_step(pk_snap(dd)) : dd;
    u->sz = *sz;
    u->sz.d = malloc((sz->n ? sz->n : 1) * sizeof *u->sz.d);
    if (!u->sz.d)
        return -1;
    for (size_t i = 0; i < sz->n; i++) {
        const double d = pk_snap(sz->d[i] / ell);
        u->sz.d[i] = d - snap_step(d);
    }
    return 0;
}

/* The grains back in the job's unit. */
static void from_unit(const edmd_unit *u, pk_particles *p)
{
    for (size_t i = 0; i < p->n; i++) {
        for (int k = 0; k < 3; k++)
            p->x[3 * i + k] *= u->ell;
        p->r[i] *= u->ell;
    }
}

static int place_edmd_unit(const pk_pack_job *job, const pk_pack_job *user, double ell,
                           const pk_pack_plan *plan, const pk_sizes *sz, const pk_run_ctx *run,
                           pk_particles *p, pk_place_stats *st, char *err, size_t errlen);

static int place_edmd(const pk_pack_job *job, const pk_pack_plan *plan, const pk_sizes *sz,
                      const pk_run_ctx *run, pk_particles *p, pk_place_stats *st, char *err,
                      size_t errlen)
{
    edmd_unit u;
    if (to_unit(job, sz, &u) != 0) {
        snprintf(err, errlen, "out of memory for %zu grains", sz->n);
        return -1;
    }
    int rc = place_edmd_unit(&u.job, job, u.ell, plan, &u.sz, run, p, st, err, errlen);
    free(u.sz.d);
    if (rc != 0)
        return rc;
    from_unit(&u, p);
    st->audit_delta_d *= u.ell;
    static const char *const lengths[] = {"delta_d_reached", "wall_gap_guaranteed"};
    for (size_t k = 0; k < 2 && st->obs; k++) {
        json_t *v = json_object_get(st->obs, lengths[k]);
        if (v)
            json_object_set_new(st->obs, lengths[k], json_real(json_real_value(v) * u.ell));
    }
    return 0;
}

/* place_edmd in the unit ℓ: job and sz in it, user the job as given (its
 * numbers in the warnings). */
static int place_edmd_unit(const pk_pack_job *job, const pk_pack_job *user, double ell,
                           const pk_pack_plan *plan, const pk_sizes *sz, const pk_run_ctx *run,
                           pk_particles *p, pk_place_stats *st, char *err, size_t errlen)
{
    pk_monitor *mon = run->mon;
    pk_edmd_params prm;
    read_params(job, plan, &prm);
    /* the default δ: RSA at φ = PK_EDMD_START_PHI (core/edmd/edmd.h); should RSA
     * still fall short (it does not below its saturation), the run starts
     * from zero radii instead — a given δ is the user's: it fails */
    const int delta_default = isnan(prm.delta);
    if (delta_default)
        prm.delta = pk_edmd_start_delta(job->box.dim, sz->d, sz->n, job->delta_d,
                                        pk_box_measure(&job->box), PK_EDMD_START_PHI);
    const int rsa_start = !prm.start_zero && prm.delta > 0;
    double rsa_seconds = 0;
    if (rsa_start) {
        pk_rsa_stats rs;
        double gap = prm.growth == PK_EDMD_GROW_SHELL ? 0.0 : job->delta_d;
        if (pk_edmd_start_rsa(&job->box, sz->d, sz->species, sz->n, prm.delta, gap, job->seed, mon,
                              p, &rs) != 0) {
            snprintf(err, errlen, "RSA start configuration failed");
            return -1;
        }
        rsa_seconds = rs.seconds;
        if (rs.reason == PK_STOP_CANCELLED || rs.reason == PK_STOP_WALL_TIME) {
            for (size_t i = 0; i < p->n; i++)
                p->r[i] *= prm.delta; /* the start's sizes: the grains as they were placed */
            *st = (pk_place_stats){.reason = rs.reason,
                                   .placed = rs.placed,
                                   .requested = sz->n,
                                   .seconds = rs.seconds,
                                   .short_delta_d = 1,
                                   .audit_delta_d = gap};
            return 0;
        }
        if (rs.placed < sz->n && !delta_default) {
            snprintf(
                err, errlen,
                "RSA start placed only %zu of %zu grains at delta = %g: lower edmd.delta or use "
                "start: zero",
                rs.placed, sz->n, prm.delta);
            return -1;
        }
        if (rs.placed < sz->n)
            p->n = 0; /* the default start fell short: from zero radii */
    }
    prm.start_zero = p->n == 0; /* (shell growth: δ = 1 is given, never zero) */
    if (prm.start_zero) {
        double x[3] = {0, 0, 0};
        for (size_t i = 0; i < sz->n; i++)
            if (pk_particles_push(p, x, 0.5 * sz->d[i], sz->species[i]) == (size_t)-1) {
                snprintf(err, errlen, "out of memory for %zu grains", sz->n);
                return -1;
            }
    }
    /* "wall_gap": "none" (Titscher §6.3: Δd between grains only): the shell
     * may reach Δd/2 of the job into the walls */
    double w = job->opt.edmd.wall_gap_none ? 0.5 * job->delta_d : 0;
    ckpt_file cf = {0};
    pk_edmd_checkpoint ck = {0};
    pk_edmd_snapshot snap = {0};
    cf.path = run->checkpoint.path;
    /* a snapshot in the job's unit (written before the engine ran in ℓ) is
     * another job's: not resumed */
    snprintf(cf.unit_digest, sizeof cf.unit_digest, "%s/unit-edge",
             run->checkpoint.digest ? run->checkpoint.digest : "");
    cf.digest = cf.unit_digest;
    ck.interval_s = run->checkpoint.interval_s;
    int loaded = 1;
    if (cf.path) {
        ck.save = save_ckpt;
        ck.ctx = &cf;
        loaded = pk_edmd_ckpt_load(cf.path, cf.digest, &snap, cf.err, sizeof cf.err);
        if (loaded == 0)
            ck.resume = &snap;
        prm.checkpoint = &ck;
    }
    pk_edmd_stats es;
    /* the monitor's wall limit counts from the job's start (pk_monitor_start),
     * so it covers the RSA start too; its Δd in the job's unit */
    double unit_was = mon ? mon->length_unit : 0;
    if (mon)
        mon->length_unit = ell;
    int run_rc = pk_edmd_run_shell_in_walls(&job->box, w, p, &prm, mon, &es);
    if (run_rc != 0 && ck.resume &&
        !ck.resumed) { /* a snapshot that does not fit: from the start */
        snprintf(cf.err, sizeof cf.err, "checkpoint %s does not fit this job; started anew",
                 cf.path);
        loaded = -1;
        ck.resume = NULL;
        run_rc = pk_edmd_run_shell_in_walls(&job->box, w, p, &prm, mon, &es);
    }
    if (mon)
        mon->length_unit = unit_was;
    pk_edmd_snapshot_free(&snap);
    if (run_rc != 0) {
        snprintf(err, errlen,
                 "EDMD failed (bad parameters, periodic box too small or out of memory)");
        return -1;
    }
    /* a run that reached its end needs no checkpoint; a stopped one (cancel,
     * wall time) keeps it for the next attempt */
    if (cf.path &&
        (es.reason == PK_STOP_COMPLETE || es.reason == PK_STOP_JAMMED ||
         es.reason == PK_STOP_STALLED))
        remove(cf.path);
    /* the shell short of the job's Δd (jammed, stalled, out of time): the
     * packing is kept, audited at the Δd reached and says so */
    const int dd_short =
        prm.growth == PK_EDMD_GROW_SHELL && es.delta_d * ell < user->delta_d * (1 - 1e-12);
    *st = (pk_place_stats){.reason = es.reason,
                           .termination = pk_edmd_criterion_name(es.criterion),
                           .phi_own = prm.until == PK_EDMD_UNTIL_JAMMED &&
                               prm.growth == PK_EDMD_GROW_RELATIVE,
                           .placed = p->n,
                           .requested = sz->n,
                           .seconds = es.seconds,
                           .walls_touch = w > 0};
    /* until jammed: the contact network, certified (core/edmd/edmd_rigidity.h) */
    pk_contact_stats cs = {0};
    pk_rigidity rg = {0};
    double ctol = pk_contact_tolerance(job->box.dim, es.pressure);
    if (prm.until == PK_EDMD_UNTIL_JAMMED &&
        pk_jam_certify(&job->box, p, es.delta_d, fmax(0.5 * es.delta_d - w, 0), ctol,
                       &pk_sparse_cholmod, &cs, &rg, &ctol) != 0) {
        snprintf(err, errlen, "out of memory in the contact analysis");
        return -1;
    }
    if (prm.until == PK_EDMD_UNTIL_JAMMED) {
        /* a stop criterion of jamming held (the pressure, or the Δφ test the
         * job chose), and the backbone is rigid: "jammed"; else said */
        const int stop_ok = es.criterion == PK_EDMD_CRIT_PRESSURE ||
            es.criterion == PK_EDMD_CRIT_DELTA_PHI ||
            (es.criterion == PK_EDMD_CRIT_STALL && es.pressure >= prm.p_max);
        if (!stop_ok &&
            (es.criterion == PK_EDMD_CRIT_STALL || es.criterion == PK_EDMD_CRIT_MAX_EVENTS))
            snprintf(st->warning, sizeof st->warning,
                     "EDMD stopped on %s at reduced pressure %.3g, below "
                     "jamming.reduced_pressure %.3g: the packing (phi %.6f) is not proven jammed",
                     pk_edmd_criterion_name(es.criterion), es.pressure, prm.p_max, es.phi);
        else if (stop_ok && !rg.rigid)
            not_rigid_warning(&rg, &es, ctol, st->warning, sizeof st->warning);
        st->goal_reached = stop_ok && rg.rigid && es.reason == PK_STOP_JAMMED;
    }
    if (dd_short) {
        /* walls that see the true grains (w = the job's Δd/2) let a shell h < w
         * through them by w − h: the grains are pulled inside and Δd is what
         * the pairs keep afterwards */
        double pulled = 1, shell_dd = es.delta_d;
        if (w > 0 && (pulled = pk_edmd_pull_inside(&job->box, p)) < 1) {
            pk_gap_report rep;
            if (pk_gap_audit(&job->box, p, es.delta_d, 0, es.delta_d + 1e-300, &rep) != 0) {
                snprintf(err, errlen, "out of memory in the gap audit");
                return -1;
            }
            es.delta_d = fmin(es.delta_d, rep.min_gap);
        }
        st->short_delta_d = 1;
        st->audit_delta_d = es.delta_d;
        int len = snprintf(st->warning, sizeof st->warning,
                           "shell growth stopped (%s) at Δd = %.6g, short of the job's delta_d = "
                           "%.6g: every gap of the result is >= %.6g",
                           pk_edmd_criterion_name(es.criterion), es.delta_d * ell, user->delta_d,
                           es.delta_d * ell);
        if (pulled < 1 && len > 0 && (size_t)len < sizeof st->warning)
            len += snprintf(st->warning + len, sizeof st->warning - (size_t)len,
                            " (the shell reached %.6g; the grains it let through the walls "
                            "were pulled inside, walled coordinates scaled by %.6f)",
                            shell_dd * ell, pulled);
        if (len > 0 && (size_t)len < sizeof st->warning)
            snprintf(st->warning + len, sizeof st->warning - (size_t)len,
                     "; lower phi or delta_d, or try a smaller edmd.growth_rate");
    }
    json_t *obs = json_object();
    json_object_set_new(obs, "phi_final", json_real(es.phi));
    json_object_set_new(obs, "phi_shell", json_real(es.phi_sim));
    json_object_set_new(obs, "reduced_pressure", json_real(es.pressure));
    if (prm.until == PK_EDMD_UNTIL_JAMMED) {
        json_object_set_new(obs, "reduced_pressure_target", json_real(prm.p_max));
        json_object_set_new(obs, "jammed", json_boolean(st->goal_reached));
    }
    json_object_set_new(obs, "collision_rule",
                        json_string(prm.rule == PK_EDMD_RULE_MEIER      ? "meier"
                                        : prm.rule == PK_EDMD_RULE_LIFT ? "lift"
                                                                        : "elastic"));
    json_object_set_new(obs, "kinetic_energy_ratio", json_real(es.kinetic_ratio));
    if (isfinite(es.phi_jam_estimate))
        json_object_set_new(obs, "phi_jamming_estimate", json_real(es.phi_jam_estimate));
    json_object_set_new(obs, "termination_criterion",
                        json_string(pk_edmd_criterion_name(es.criterion)));
    json_object_set_new(obs, "delta_d_reached", json_real(es.delta_d));
    /* a shell that reached w: its clearance beyond w is round-off */
    const double wall_gap = 0.5 * es.delta_d - w;
    json_object_set_new(obs, "wall_gap_guaranteed", json_real(wall_gap > 1e-12 * w ? wall_gap : 0));
    json_object_set_new(obs, "start", json_string(prm.start_zero ? "zero" : "rsa"));
    if (!prm.start_zero) {
        json_object_set_new(obs, "start_delta", json_real(prm.delta));
        json_object_set_new(obs, "start_seconds", json_real(rsa_seconds));
    }
    json_object_set_new(obs, "time_simulated", json_real(es.t_stop));
    if (cf.path) {
        json_object_set_new(obs, "resumed", json_boolean(ck.resumed));
        if (ck.resumed) {
            json_object_set_new(obs, "resumed_from_events",
                                json_integer((json_int_t)ck.resumed_events));
            json_object_set_new(obs, "resumed_from_time", json_real(ck.resumed_time));
        }
        json_object_set_new(obs, "checkpoints_saved", json_integer(ck.saved));
        if (ck.save_failures || loaded < 0)
            json_object_set_new(obs, "checkpoint_error", json_string(cf.err));
    }
    if (isfinite(es.t_end))
        json_object_set_new(obs, "time_end", json_real(es.t_end));
    json_object_set_new(obs, "events", json_integer((json_int_t)es.events));
    json_object_set_new(obs, "events_pair", json_integer((json_int_t)es.pair));
    json_object_set_new(obs, "events_wall", json_integer((json_int_t)es.wall));
    json_object_set_new(obs, "events_neighbour_list", json_integer((json_int_t)es.nlist));
    json_object_set_new(obs, "events_invalidated", json_integer((json_int_t)es.invalid));
    json_object_set_new(obs, "rescales", json_integer((json_int_t)es.rescales));
    json_object_set_new(obs, "overlaps_predicted", json_integer((json_int_t)es.overlaps));
    json_object_set_new(obs, "collisions_per_second",
                        json_real(es.seconds > 0 ? (double)es.pair / es.seconds : 0));
    if (prm.until == PK_EDMD_UNTIL_JAMMED) { /* a contact network only where one was tested */
        json_object_set_new(obs, "contacts", json_integer((json_int_t)cs.contacts));
        json_object_set_new(obs, "wall_contacts", json_integer((json_int_t)cs.wall_contacts));
        json_object_set_new(obs, "rattlers", json_integer((json_int_t)cs.rattlers));
        json_object_set_new(obs, "contact_tolerance", json_real(ctol));
        json_object_set_new(obs, "backbone", json_integer((json_int_t)rg.backbone));
        json_object_set_new(obs, "backbone_contacts", json_integer((json_int_t)rg.contacts));
        json_object_set_new(obs, "maxwell_contacts", json_integer((json_int_t)rg.maxwell_min));
        json_object_set_new(obs, "backbone_rigid", json_boolean(rg.rigid));
        if (rg.tested)
            json_object_set_new(obs, "floppy_modes", json_integer((json_int_t)rg.floppy));
        if (rg.backbone) {
            json_object_set_new(obs, "mean_contact_number", json_real(cs.mean_contacts));
            json_object_set_new(obs, "rattler_fraction", json_real(cs.rattler_fraction));
        }
    }
    json_t *h = json_object();
    json_object_set_new(h, "events", doubles(es.hist_events, es.nhist));
    json_object_set_new(h, "time", doubles(es.hist_t, es.nhist));
    json_object_set_new(h, "phi", doubles(es.hist_phi, es.nhist));
    json_object_set_new(h, "reduced_pressure", doubles(es.hist_p, es.nhist));
    json_object_set_new(obs, "history", h);
    st->obs = obs;
    return 0;
}

/* Its observables with a unit; the rest are counts, fractions or in reduced
 * units (time, d̄/u). */
static const pk_unit_row edmd_units[] = {
    {"delta_d_reached", PK_U_LENGTH},
    {"wall_gap_guaranteed", PK_U_LENGTH},
    {"start_seconds", PK_U_SECONDS},
    {"collisions_per_second", PK_U_HERTZ},
    {NULL, PK_U_NONE},
};

const pk_placer pk_placer_edmd = {.name = "edmd",
                                  .has_history = 1,
                                  .grows_until_jammed = grows_until_jammed,
                                  .options = &edmd_options,
                                  .units = edmd_units,
                                  .check = check_edmd,
                                  .place = place_edmd};
