/* edmd.c — the EDMD growth-packing driver: set-up, event loop, stop criteria.
 * Contract: core/edmd/edmd.h; folder guide core/edmd/README.md.
 *
 * Time unit: the time a grain at the rms speed per axis (u = mean target
 * diameter d̄ per unit time) needs to cross d̄.  Relative growth: every
 * diameter is d_i·s(t) with s' = γ, so γ is relative to the FINAL (target)
 * diameter: d_i' = γ·d_i (Meier: s(0) = 0; Titscher §6.2: s(0) = δ,
 * t_end = (1 − δ)/γ).  Titscher's Eq. 30, t_end = (1 − δ)/(δ γ_T), takes
 * the rate relative to the INITIAL diameter d_0 = δ d (d' = γ_T d_0): the
 * same end time with γ = δ γ_T.  Shell growth: true radii fixed, the shell
 * grows at γ_a = γ·d̄/2 (Titscher §6.3: t_end = Δd/(2γ_a), Eq. 31; §6.4:
 * until jammed, Δd_max = 2 h(t_stop)). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "edmd_checkpoint.h"
#include "edmd_state.h"
#include "core/base/rng.h"

/* Near jamming the skins shrink as SKIN_P0/p above that reduced pressure,
 * to SKIN_MIN of the base skin at most (mono 3D N = 2000 to jamming: −9 %
 * instructions against fixed skins; docs/perf/edmd.md). */
#define SKIN_P0 100.0
#define SKIN_MIN 0.1
/* Skin factor of the grains below the mean radius (see setup; Fuller-like
 * 1–16 N = 10^4 to jamming: 13.0k instructions per collision, 16.1k at 1). */
#define SKIN_FINE 2.5
/* From RESORT_MIN_N grains on (arrays beyond the caches) the grains are
 * renumbered along a Z-order curve every RESORT_WINDOWS·N events, as they
 * diffuse from their start order (N = 10^6 to φ = 0.55: −26 % CPU time). */
#define RESORT_MIN_N 32768
#define RESORT_WINDOWS 10

/* The clock is re-based every REBASE_WINDOWS·N events, so |v·t| stays a few
 * flights (a re-base touches every grain; a longer window loses precision
 * near contact: N = 8 in a walled cube then jams short of π/6 more often). */
#define REBASE_WINDOWS 4

/* Reduced pressure past which a run to jamming grows at
 * pk_edmd_params.jam_rate_factor of its rate (the structure is arrested
 * near p ~ 10^2–10^3). */
#define JAM_SLOW_P 1e3

static void state_free(edmd_state *s)
{
    edmd_nlist_free(s);
    free(s->k);
    free(s->m);
    free(s->ev);
    free(s->ncoll);
    edmd_queue_free(s);
    free(s->skin);
    free(s->rref);
    free(s->ncoll_nl);
}

static int state_alloc(edmd_state *s, size_t n)
{
    size_t c = n ? n : 1;
    s->k = edmd_big_calloc(c, sizeof *s->k);
    s->m = edmd_big_calloc(c, sizeof *s->m);
    s->ev = edmd_big_calloc(c, sizeof *s->ev);
    s->ncoll = edmd_big_calloc(c, sizeof *s->ncoll);
    const int queue = edmd_queue_alloc(s, c);
    s->skin = edmd_big_calloc(c, sizeof *s->skin);
    s->rref = edmd_big_calloc(c, sizeof *s->rref);
    s->ncoll_nl = edmd_big_calloc(c, sizeof *s->ncoll_nl);
    s->nl = edmd_big_calloc(c, sizeof *s->nl);
    s->nl_mark = edmd_big_calloc(c, sizeof *s->nl_mark);
    if (!s->k || !s->m || !s->ev || !s->ncoll || queue != 0 || !s->skin || !s->rref ||
        !s->ncoll_nl || !s->nl || !s->nl_mark)
        return -1;
    if (pk_particles_init(&s->bs, s->dim, c) != 0)
        return -1;
    edmd_big_hint(s->bs.x, 3 * c * sizeof *s->bs.x); /* (not touched yet) */
    edmd_big_hint(s->bs.r, c * sizeof *s->bs.r);
    return 0;
}

/* True radius R_i(t) = ρ_i(t) − h(t), clamped at 0. */
static inline double true_radius(const edmd_state *s, size_t i, double t)
{
    return fmax(edmd_rho(s, i, t) - (s->h0 + s->h1 * t), 0);
}

/* pk_ball_measure's expression, inlined (the same operations, the same
 * sums): φ is summed over all grains every window of N events. */
static inline double ball_measure(int dim, double r)
{
    return dim == 2 ? M_PI * r * r : 4.0 / 3.0 * M_PI * r * r * r;
}

static double phi_true(const edmd_state *s, double t)
{
    const double h = s->h0 + s->h1 * t;
    double sum = 0;
    for (size_t i = 0; i < s->n; i++) {
        const double r = edmd_rho(s, i, t) - h; /* true_radius */
        sum += ball_measure(s->dim, r > 0 ? r : 0);
    }
    return sum / pk_box_measure(&s->box);
}

static double phi_sim(const edmd_state *s, double t)
{
    double sum = 0;
    for (size_t i = 0; i < s->n; i++)
        sum += ball_measure(s->dim, edmd_rho(s, i, t));
    return sum / pk_box_measure(&s->box);
}

/* Smallest t >= 0 with φ_true(t) >= phi (φ_true is non-decreasing). */
static double time_of_phi(const edmd_state *s, double phi)
{
    double lo = 0, hi = 1;
    while (phi_true(s, hi) < phi && hi < 1e300)
        hi *= 2;
    for (int it = 0; it < 200 && hi - lo > 1e-15 * hi; it++) {
        double mid = 0.5 * (lo + hi);
        if (phi_true(s, mid) >= phi)
            hi = mid;
        else
            lo = mid;
    }
    return hi;
}

static int all_periodic(const edmd_state *s)
{
    for (int k = 0; k < s->dim; k++)
        if (!s->box.periodic[k])
            return 0;
    return 1;
}

static double kinetic(const edmd_state *s)
{
    double K = 0;
    for (size_t i = 0; i < s->n; i++)
        for (int k = 0; k < s->dim; k++)
            K += 0.5 * s->m[i] * s->k[i].v[k] * s->k[i].v[k];
    return K;
}

/* In a fully periodic box the centre of mass is at rest (Meier's Eq. 3.9
 * does not conserve momentum for unequal rates). */
static void remove_drift(edmd_state *s)
{
    if (!all_periodic(s))
        return;
    double P[3] = {0, 0, 0}, M = 0;
    for (size_t i = 0; i < s->n; i++) {
        M += s->m[i];
        for (int k = 0; k < s->dim; k++)
            P[k] += s->m[i] * s->k[i].v[k];
    }
    for (size_t i = 0; i < s->n; i++)
        for (int k = 0; k < s->dim; k++)
            s->k[i].v[k] -= P[k] / M;
}

static void predict_all(edmd_state *s)
{
    for (size_t i = 0; i < s->n; i++)
        edmd_predict(s, i);
    edmd_queue_init(s);
}

/* The criterion of a monitor stop (pk_monitor_tick: 1 cancelled, 2 wall limit). */
static pk_edmd_criterion monitor_criterion(int m)
{
    return m == 2 ? PK_EDMD_CRIT_WALL_TIME : PK_EDMD_CRIT_CANCEL;
}

/* All lists and events anew (after a skin change or a renumbering): 0, -1
 * out of memory, 1 when the monitor stopped the run during the list build
 * (*crit set): the run must end, its positions are still exact. */
static int rebuild_all(edmd_state *s, pk_edmd_criterion *crit)
{
    int rc = edmd_nlist_build_all(s);
    if (rc == 0)
        predict_all(s);
    else if (rc > 0)
        *crit = monitor_criterion(s->stop);
    return rc;
}

/* Synchronise everyone and move the time origin to now (|t| stays small
 * against Δt).  Predictions are shifted, not recomputed. */
static void rebase(edmd_state *s)
{
    double T = s->t;
    for (size_t i = 0; i < s->n; i++) {
        edmd_kin *k = &s->k[i];
        edmd_pos(s, i, k->p);
        edmd_wrap_near(s, k->p);
        k->a += k->g * T;
    }
    s->h0 += s->h1 * T;
    s->t = 0;
    edmd_queue_shift(s, T); /* (the queue is rebuilt about the new clock) */
}

/* Kinetic-energy rescaling: every trajectory changes, so all predictions are
 * redone.  p holds the positions now while the velocities change. */
static void rescale(edmd_state *s, double K0)
{
    for (size_t i = 0; i < s->n; i++)
        edmd_pos(s, i, s->k[i].p);
    remove_drift(s);
    double K = kinetic(s);
    double lam = K > 0 ? sqrt(K0 / K) : 1;
    for (size_t i = 0; i < s->n; i++) {
        double x[3] = {s->k[i].p[0], s->k[i].p[1], s->k[i].p[2]};
        for (int k = 0; k < 3; k++)
            s->k[i].v[k] *= lam;
        edmd_pin(s, i, x);
    }
    s->K = kinetic(s);
    for (size_t i = 0; i < s->n; i++)
        s->ncoll[i]++;
    predict_all(s);
}

/* Multiply every growth rate (and the shell's) by f from now on, radii
 * continuous; every prediction is redone (the pair quadratics change). */
static void scale_growth(edmd_state *s, double f)
{
    const double t = s->t;
    for (size_t i = 0; i < s->n; i++) {
        edmd_kin *k = &s->k[i];
        const double g = k->g * f;
        k->a += (k->g - g) * t;
        k->g = g;
        s->ncoll[i]++;
    }
    const double h1 = s->h1 * f;
    s->h0 += (s->h1 - h1) * t;
    s->h1 = h1;
    predict_all(s);
}

static void hist_push(pk_edmd_stats *st, uint64_t *stride, uint64_t ev, double t, double phi,
                      double p)
{
    if (st->nhist == PK_EDMD_HIST_MAX) { /* keep every other point, double the stride */
        size_t k = 0;
        for (size_t q = 0; q < st->nhist; q += 2, k++) {
            st->hist_events[k] = st->hist_events[q];
            st->hist_t[k] = st->hist_t[q];
            st->hist_phi[k] = st->hist_phi[q];
            st->hist_p[k] = st->hist_p[q];
        }
        st->nhist = k;
        *stride *= 2;
    }
    st->hist_events[st->nhist] = (double)ev;
    st->hist_t[st->nhist] = t;
    st->hist_phi[st->nhist] = phi;
    st->hist_p[st->nhist] = p;
    st->nhist++;
}

/* The growth law: radii ρ_i(t) = a_i + g_i·t (k[i].a, k[i].g) and the shell
 * h0 + h1·t; *t_end: when the law reaches the target sizes.  -1 on bad input. */
static int set_rates(edmd_state *s, const pk_particles *p, const pk_edmd_params *prm, double dbar,
                     double *t_end)
{
    const size_t n = s->n;
    const double gam = prm->growth_rate, h = 0.5 * prm->delta_d;
    if (prm->growth == PK_EDMD_GROW_RELATIVE) {
        double s0 = prm->start_zero ? 0 : prm->delta;
        if (!(s0 >= 0 && s0 < 1))
            return -1;
        *t_end = (1 - s0) / gam;
        for (size_t i = 0; i < n; i++) {
            if (prm->start_zero) { /* ρ = (r + h)·γt: the shell scales with the grain */
                s->k[i].a = 0;
                s->k[i].g = (p->r[i] + h) * gam;
            } else {
                s->k[i].a = s0 * p->r[i] + h;
                s->k[i].g = p->r[i] * gam;
            }
        }
        s->h0 = h;
        s->h1 = 0;
        return 0;
    }
    if (prm->start_zero)
        return -1;
    double ga = 0.5 * gam * dbar;
    for (size_t i = 0; i < n; i++) {
        s->k[i].a = p->r[i];
        s->k[i].g = ga;
    }
    s->h0 = 0;
    s->h1 = ga;
    *t_end = h / ga;
    return 0;
}

/* Masses (normalised to mean 1: by volume, or equal) and equipartition
 * velocities of scale d̄/√m without drift; positions wrapped into [0, L). */
static void set_motion(edmd_state *s, const pk_particles *p, const pk_edmd_params *prm, double dbar,
                       double rmax)
{
    const size_t n = s->n;
    const int dim = s->dim;
    double msum = 0;
    for (size_t i = 0; i < n; i++) {
        s->m[i] = prm->equal_masses ? 1.0 : pow(p->r[i] / rmax, dim);
        if (!(s->m[i] > 0))
            s->m[i] = 1e-300;
        msum += s->m[i];
    }
    pk_rng rng;
    pk_rng_seed(&rng, prm->seed, 2);
    for (size_t i = 0; i < n; i++) {
        s->m[i] *= (double)n / msum;
        double sc = dbar / sqrt(s->m[i]);
        for (int k = 0; k < dim; k++)
            s->k[i].v[k] = sc * pk_rng_normal(&rng);
    }
    remove_drift(s);
    for (size_t i = 0; i < n; i++) {
        for (int k = 0; k < 3; k++)
            s->k[i].p[k] = k >= dim ? 0 : p->x[3 * i + k];
        pk_box_wrap(&s->box, s->k[i].p); /* t = 0: p is the position */
    }
}

/* Skins: a fraction of the radius at the reference time, at most twice
 * the mean (coarse grains would list hundreds of fines); grains below the
 * mean get SKIN_FINE·(2ρ̄ − r), up to SKIN_FINE·2ρ̄ for the finest: fines
 * fly as fast as the coarse and rattle in their pores, so with a small
 * skin they rebuild all the time (a rebuild is a multi-level cell query),
 * while their lists (few grains of their size) stay short
 * (docs/perf/edmd.md, SKIN_FINE).  A skin leaves a pair one periodic image
 * within reach.  -1 when the periodic box is too small for that. */
static int set_skins(edmd_state *s, const pk_edmd_params *prm, double t_end)
{
    const size_t n = s->n;
    const int dim = s->dim;
    double t_ref = isfinite(t_end) ? t_end : 0;
    double rho_mean = 0, rho_max = 0;
    for (size_t i = 0; i < n; i++) {
        double r = edmd_rho(s, i, t_ref);
        rho_mean += r / (double)n;
        rho_max = fmax(rho_max, r);
    }
    double Lper = INFINITY;
    for (int k = 0; k < dim; k++)
        if (s->box.periodic[k])
            Lper = fmin(Lper, s->box.L[k]);
    /* periodic images: a pair must have one image within reach (Meier et al. §3) */
    double grow_max = 1; /* growing until jammed: bound the sizes by φ <= 1 */
    if (prm->until == PK_EDMD_UNTIL_JAMMED && prm->growth == PK_EDMD_GROW_RELATIVE)
        grow_max = pow(1 / fmax(phi_sim(s, t_ref), 1e-300), 1.0 / dim);
    double room = 0.25 * Lper - rho_max * grow_max;
    if (!(room > 0))
        return -1;
    for (size_t i = 0; i < n; i++) {
        double r = edmd_rho(s, i, t_ref);
        s->rref[i] = r;
        const double base = fmin(fmax(r, 2 * rho_mean - r), 2 * rho_mean);
        const int fine = r < rho_mean * (1 - 1e-9); /* equal grains: r = ρ̄ to round-off */
        s->skin[i] = prm->skin * (fine ? SKIN_FINE * (2 * rho_mean - r) : base);
        if (0.5 * s->skin[i] > room)
            s->skin[i] = 2 * room;
    }
    return 0;
}

/* Set rates, masses, velocities, positions (zero start), skins.  Returns the
 * stop time (INFINITY when growing until jammed) or NAN on bad input. */
static double setup(edmd_state *s, const pk_particles *p, const pk_edmd_params *prm,
                    pk_edmd_stats *st)
{
    const size_t n = s->n;
    double dbar = 0, rmax = 0;
    for (size_t i = 0; i < n; i++) {
        dbar += 2 * p->r[i] / (double)n;
        rmax = fmax(rmax, p->r[i]);
    }
    if (!(dbar > 0) || !(prm->growth_rate > 0))
        return NAN;
    double t_end;
    if (set_rates(s, p, prm, dbar, &t_end) != 0)
        return NAN;
    st->t_end = t_end;
    double t_stop = t_end;
    if (prm->until == PK_EDMD_UNTIL_JAMMED)
        t_stop = INFINITY;
    else if (prm->growth == PK_EDMD_GROW_RELATIVE && prm->phi_target > 0)
        t_stop = time_of_phi(s, prm->phi_target);
    set_motion(s, p, prm, dbar, rmax);
    if (set_skins(s, prm, t_end) != 0)
        return NAN;
    double vmax_g = 0;
    for (size_t i = 0; i < n; i++)
        vmax_g = fmax(vmax_g, s->k[i].g);
    s->eps_v = 1e-9 * fmax(dbar, 2 * vmax_g);
    return t_stop;
}

/* The driver's bookkeeping beside the engine state: the event windows and
 * schedules (stall, pressure, re-base, re-sort, checkpoints), the run's
 * current growth rate and the progress record. */
typedef struct run_loop {
    const pk_edmd_params *prm;
    pk_edmd_stats *st;
    pk_monitor *mon;
    pk_edmd_checkpoint *ckpt;
    size_t *perm;          /* perm[k] = grain of the caller's p at engine index k */
    double w0, hcell;      /* wall clock at the start; the Z-order cell */
    double t_stop, t_base; /* stop time; absolute time of the re-based origin t = 0 */
    double K0, K_hi, K_lo; /* kinetic energy kept within (K_lo, K_hi) by rescaling */
    double gam_now;        /* the growth rate now (slowed near jamming) */
    double stall_acc, phi_prev, pressure, skin_built;
    int slowed, stall_auto;
    uint64_t c_win, next_check;   /* the pressure / Δφ window */
    uint64_t stall_win, stall_ev; /* the stall window */
    uint64_t hist_stride, hist_count;
    uint64_t rebase_win, last_rebase;
    uint64_t resort_win, next_resort;
    pk_progress pr;
    double eta_w, eta_f, rate; /* the last rate sample (wall s, fraction); fraction per s */
    char msg[160];
} run_loop;

/* Carry out event i, due now: a pair collision (or its stale prediction), a
 * neighbour-list exit, a wall collision.  -1 out of memory. */
static int dispatch(edmd_state *s, pk_edmd_stats *st, size_t i)
{
    edmd_event *e = &s->ev[i];
    const int32_t w = e->with;
    if (w >= 0) {
        size_t j = (size_t)w;
        if (e->stamp != s->ncoll[j]) { /* partner changed course since */
            st->invalid++;
            if (e->t2 < INFINITY) { /* the runner-up, predicted with i's flight */
                *e = (edmd_event){e->t2, INFINITY, e->with2, EDMD_EV_NONE, e->stamp2, 0};
                st->second++;
            } else {
                edmd_predict(s, i);
            }
            edmd_queue_update(s, i);
            return 0;
        }
        /* both predictions below read the neighbours' records: start all
         * those loads now (edmd_prefetch_list) */
        edmd_prefetch_list(s, i);
        edmd_prefetch_list(s, j);
        s->virial += edmd_collide_pair(s, i, j);
        s->ncoll[i]++;
        s->ncoll[j]++;
        st->pair++;
        edmd_predict(s, i);
        edmd_queue_update(s, i);
        edmd_predict(s, j);
        edmd_queue_update(s, j);
        return 0;
    } else if (w == EDMD_EV_NLIST) {
        if (edmd_nlist_rebuild(s, i) != 0)
            return -1;
        st->nlist++;
    } else if (w <= EDMD_EV_WALL0) {
        edmd_collide_wall(s, i, EDMD_EV_WALL0 - w);
        s->ncoll[i]++;
        st->wall++;
    }
    edmd_predict(s, i);
    edmd_queue_update(s, i);
    return 0;
}

/* Take the first event and carry it out, the clock moved to it; *crit set
 * when the run ends before it (the stop time, or no event ever).  -1 out of
 * memory. */
static int step(edmd_state *s, run_loop *L, pk_edmd_criterion *crit)
{
    size_t i = edmd_queue_top(s);
    double te = s->ev[i].t;
    if (te >= L->t_stop - L->t_base) {
        double tt = fmax(L->t_stop - L->t_base, s->t);
        s->kint += s->K * (tt - s->t);
        s->t = tt;
        *crit = PK_EDMD_CRIT_TARGET;
        return 0;
    }
    if (!(te < INFINITY)) {
        *crit = PK_EDMD_CRIT_STALL; /* nothing will ever happen (no growth, no motion) */
        return 0;
    }
    /* the records the next event will most likely read start loading now,
     * behind this event's work (events are scattered over the box: at
     * 10^6 grains each of these is a DRAM miss) */
    if (L->resort_win) { /* (arrays beyond the caches; below, a cost: 10^4 +4 % CPU) */
        const int32_t nx = edmd_queue_runner_up(s);
        if (nx >= 0)
            edmd_prefetch_grain(s, (size_t)nx);
    }
    s->kint += s->K * (te - s->t);
    L->stall_acc += te - s->t;
    s->t = te;
    L->st->events++;
    return dispatch(s, L->st, i);
}

/* The stall window: the sizes grew by less than the stall threshold over it. */
static int stalled(const run_loop *L)
{
    /* the default: 10^-12, and until jammed below a hundredth of what a
     * packing at the window's pressure p grows (~γ/p per window), so the
     * stall never preempts the pressure test */
    double stall_growth = L->prm->stall_growth;
    if (L->stall_auto)
        stall_growth = L->prm->until == PK_EDMD_UNTIL_JAMMED
            ? fmin(1e-12, 1e-2 * L->gam_now / fmax(L->pressure, 1))
            : 1e-12;
    return L->stall_acc * L->gam_now < stall_growth;
}

/* Progress to the monitor; its stop (cancel, wall time) as a criterion. */
static pk_edmd_criterion progress(const edmd_state *s, run_loop *L)
{
    const pk_edmd_params *prm = L->prm;
    const pk_edmd_stats *st = L->st;
    pk_progress *pr = &L->pr;
    pr->done = (size_t)st->events;
    if (isfinite(L->t_stop)) {
        pr->fraction = fmin(1, (L->t_base + s->t) / L->t_stop);
        /* from the rate of the last second or more, not the average: a run
         * slows as the grains crowd (collisions per unit of growth rise) */
        double w = pk_wall_seconds() - L->w0;
        if (w - L->eta_w >= 1.0) {
            double r = (pr->fraction - L->eta_f) / (w - L->eta_w);
            L->rate = L->eta_w > 0 && r > 0 ? r : L->rate;
            L->eta_w = w;
            L->eta_f = pr->fraction;
        }
        pr->eta_s = L->rate > 0 ? (1 - pr->fraction) / L->rate
            : pr->fraction > 0  ? w * (1 - pr->fraction) / pr->fraction
                                : -1;
    } else { /* until jammed: the reduced pressure on its way to p_max, on a log scale */
        double f = L->pressure > 1 && prm->p_max > 1 ? log(L->pressure) / log(prm->p_max) : 0;
        if (prm->max_events)
            f = fmax(f, (double)st->events / (double)prm->max_events);
        pr->fraction = fmax(pr->fraction, fmin(f, 0.99));
    }
    pr->delta_d = s->h1 > 0 ? 2 * (s->h0 + s->h1 * s->t) : 0;
    snprintf(L->msg, sizeof L->msg, "events=%llu collisions=%llu reduced_pressure=%.4g",
             (unsigned long long)st->events, (unsigned long long)st->pair, L->pressure);
    pr->message = L->msg;
    int m = pk_monitor_tick(L->mon, pr, 0);
    return m ? monitor_criterion(m) : PK_EDMD_CRIT_NONE;
}

/* The end of a pressure window: the reduced pressure, the history, the
 * jamming criteria, the skins, the slowdown, a checkpoint.  -1 out of
 * memory; *crit set when the run ends. */
static int window(edmd_state *s, run_loop *L, pk_edmd_criterion *crit)
{
    const pk_edmd_params *prm = L->prm;
    pk_edmd_stats *st = L->st;
    L->next_check = st->events + L->c_win;
    double phi = phi_true(s, s->t);
    double phis = phi_sim(s, s->t); /* grows in both modes (shell: φ_true is fixed) */
    L->pressure = s->kint > 0 ? 1 + s->virial / (2 * s->kint) : 0;
    s->virial = s->kint = 0;
    L->pr.phi = phi;
    if (++L->hist_count % L->hist_stride == 0)
        hist_push(st, &L->hist_stride, st->events, L->t_base + s->t, phi, L->pressure);
    if (prm->until == PK_EDMD_UNTIL_JAMMED) {
        if (L->pressure >= prm->p_max) {
            *crit = PK_EDMD_CRIT_PRESSURE;
            return 0;
        }
        /* Meier Eq. 3.11; only in a dense state (p > 10^3): from zero radii
         * φ ∝ t^d barely moves over the first windows */
        if (prm->dphi_crit > 0 && L->pressure > 1e3 && phis - L->phi_prev < prm->dphi_crit) {
            *crit = PK_EDMD_CRIT_DELTA_PHI;
            return 0;
        }
    }
    /* near jamming the grains rattle in cages of width ~ d/p: shrink the
     * skins with the pressure (shorter lists, fewer pair predictions; the
     * lists stay exact for any skin), and rebuild all lists when they have
     * halved since the last full build */
    s->skin_scale = L->pressure > SKIN_P0 ? fmax(SKIN_P0 / L->pressure, SKIN_MIN) : 1;
    if (s->skin_scale < 0.5 * L->skin_built) {
        L->skin_built = s->skin_scale;
        int rb = rebuild_all(s, crit);
        if (rb != 0)
            return rb < 0 ? -1 : 0;
    }
    L->phi_prev = phis;
    /* past the structural arrest the growth slows (Lubachevsky–Stillinger,
     * Skoge et al. 2006): at a fast rate the pressure reaches 10^12 on a
     * hypostatic network the growth drives (3D mono N = 500, γ = 0.02:
     * z = 5.59 on 7 % rattlers), at a tenth of it the backbone is isostatic
     * (z = 5.95, 2.4 %) */
    if (prm->until == PK_EDMD_UNTIL_JAMMED && !L->slowed && L->pressure > JAM_SLOW_P) {
        scale_growth(s, prm->jam_rate_factor);
        L->gam_now *= prm->jam_rate_factor;
        L->slowed = 1;
        st->growth_changes++;
    } else if (L->slowed == 1 && L->pressure > prm->jam_full_rate_p &&
               prm->until == PK_EDMD_UNTIL_JAMMED && prm->jam_rate_factor > 0 &&
               prm->jam_rate_factor < 1) {
        /* the network the certificate counts is closed by then: the last
         * decades of pressure at the full rate (docs/perf/edmd.md) */
        scale_growth(s, 1 / prm->jam_rate_factor);
        L->gam_now /= prm->jam_rate_factor;
        L->slowed = 2;
        st->growth_changes++;
    }
    if (edmd_checkpoint_due(L->ckpt)) { /* re-based first: the snapshot starts at t = 0 */
        L->t_base += s->t;
        rebase(s);
        st->rebases++;
        L->last_rebase = st->events;
        edmd_ckpt_loop now = {L->t_base,      L->K0,         L->pressure, L->pr.fraction,
                              L->hist_stride, L->hist_count, L->gam_now,  L->slowed};
        edmd_checkpoint_take(s, L->perm, st, &now, L->ckpt);
    }
    return 0;
}

/* Everything after an event, each on its own schedule: rescaling, the stall
 * and event limits, progress, the pressure window, the clock's re-base, the
 * Z-order re-sort.  -1 out of memory; *crit set when the run ends. */
static int after_event(edmd_state *s, run_loop *L, pk_edmd_criterion *crit)
{
    const pk_edmd_params *prm = L->prm;
    pk_edmd_stats *st = L->st;
    if (prm->rescale && (s->K > L->K_hi || s->K < L->K_lo)) {
        rescale(s, L->K0);
        st->rescales++;
    }
    if (st->events - L->stall_ev >= L->stall_win) {
        if (stalled(L)) {
            *crit = PK_EDMD_CRIT_STALL;
            return 0;
        }
        L->stall_ev = st->events;
        L->stall_acc = 0;
    }
    if (prm->max_events && st->events >= prm->max_events) {
        *crit = PK_EDMD_CRIT_MAX_EVENTS;
        return 0;
    }
    if ((st->events & 1023) == 0 && (*crit = progress(s, L)) != PK_EDMD_CRIT_NONE)
        return 0;
    if (st->events >= L->next_check && (window(s, L, crit) != 0 || *crit))
        return *crit ? 0 : -1;
    if (st->events - L->last_rebase >= L->rebase_win) {
        /* positions are p + v·t: keep |v·t| small */
        L->t_base += s->t;
        rebase(s);
        st->rebases++;
        L->last_rebase = st->events;
    }
    if (L->resort_win && st->events >= L->next_resort) {
        L->next_resort = st->events + L->resort_win;
        if (edmd_reorder(s, L->perm, L->hcell) != 0)
            return -1;
        st->resorts++;
        return rebuild_all(s, crit) < 0 ? -1 : 0;
    }
    return 0;
}

/* The engine's copy q of the grains, in Z-order (or the snapshot's order on
 * resume), set up and predicted; L's windows and schedules started.  0, or
 * -1 on bad input or out of memory. */
static int open_run(const pk_box *b, pk_particles *p, pk_particles *q, edmd_state *s, run_loop *L)
{
    const pk_edmd_params *prm = L->prm;
    pk_edmd_stats *st = L->st;
    s->box = *b;
    s->dim = b->dim;
    for (int k = 0; k < 3; k++) {
        s->Lp[k] = k < b->dim && b->periodic[k] ? b->L[k] : 0;
        s->inv_Lp[k] = s->Lp[k] > 0 ? 1 / s->Lp[k] : 0;
        if (k < b->dim && !b->periodic[k])
            s->walled = 1;
    }
    s->n = p->n;
    s->rule = prm->rule;
    if (state_alloc(s, s->n) != 0)
        return -1;
    /* zero start: uniform positions (stream 3) */
    if (prm->start_zero) {
        pk_rng rng;
        pk_rng_seed(&rng, prm->seed, 3);
        for (size_t i = 0; i < p->n; i++)
            for (int k = 0; k < 3; k++)
                p->x[3 * i + k] = k < b->dim ? pk_rng_range(&rng, 0, b->L[k]) : 0;
    }
    double hcell = 0;
    for (size_t i = 0; i < p->n; i++)
        hcell += 2 * p->r[i] / (double)p->n;
    L->hcell = hcell > 0 ? hcell : 1;
    L->perm = malloc(p->n * sizeof *L->perm);
    /* a resumed run takes the engine order of its snapshot */
    const pk_edmd_snapshot *from = L->ckpt ? L->ckpt->resume : NULL;
    if (!L->perm || pk_particles_init(q, p->dim, p->n) != 0 ||
        (from ? edmd_checkpoint_perm(from, p->n, p->dim, L->perm)
              : edmd_spatial_order(b, p->x, p->n, L->hcell, L->perm)) != 0)
        return -1;
    for (size_t k = 0; k < p->n; k++)
        pk_particles_push(q, &p->x[3 * L->perm[k]], p->r[L->perm[k]], p->species[L->perm[k]]);
    L->t_stop = setup(s, q, prm, st);
    if (isnan(L->t_stop))
        return -1;
    s->skin_scale = 1;
    edmd_ckpt_loop c = {.hist_stride = 1, .fraction = -1};
    if (from)
        edmd_checkpoint_restore(s, st, &c, L->ckpt);
    L->skin_built = s->skin_scale;
    if (edmd_nlist_build_all(s) != 0)
        return -1;
    s->K = kinetic(s);
    L->K0 = from ? c.K0 : s->K;
    L->K_hi = L->K0 * (1 + prm->rescale_tol);
    L->K_lo = L->K0 / (1 + prm->rescale_tol);
    predict_all(s);

    L->c_win = prm->dphi_events ? prm->dphi_events : (uint64_t)s->n;
    /* stall window: at least one event per grain (Titscher: 1000 events) */
    L->stall_win = prm->stall_events ? prm->stall_events : 1000;
    if (L->stall_win < (uint64_t)s->n)
        L->stall_win = (uint64_t)s->n;
    L->gam_now = from ? c.growth_rate : prm->growth_rate;
    /* 0 full rate, 1 slowed past JAM_SLOW_P, 2 back at the full rate past jam_full_rate_p */
    L->slowed =
        from && c.slowed ? c.slowed : !(prm->jam_rate_factor > 0 && prm->jam_rate_factor < 1);
    L->stall_auto = isnan(prm->stall_growth);
    L->next_check = st->events + L->c_win;
    L->hist_stride = c.hist_stride;
    L->hist_count = c.hist_count;
    L->stall_ev = L->last_rebase = st->events;
    L->rebase_win = REBASE_WINDOWS * (uint64_t)s->n;
    L->resort_win = s->n >= RESORT_MIN_N ? RESORT_WINDOWS * (uint64_t)s->n : 0;
    L->next_resort = st->events + L->resort_win;
    L->t_base = c.t_base;
    L->phi_prev = phi_sim(s, 0);
    L->pressure = c.pressure;
    L->pr =
        (pk_progress){.stage = "edmd", .fraction = c.fraction, .phi = phi_true(s, 0), .eta_s = -1};
    pk_monitor_begin(L->mon);
    s->mon = L->mon; /* ticked inside the full list builds from here on */
    s->pr = &L->pr;
    if (!from)
        hist_push(st, &L->hist_stride, 0, 0, L->pr.phi, 0);
    return 0;
}

/* The engine's final state back into the caller's p (its own order), and the
 * run's figures into st. */
static void close_run(const pk_box *b, pk_particles *p, edmd_state *s, run_loop *L,
                      pk_edmd_criterion crit)
{
    pk_edmd_stats *st = L->st;
    if (s->kint > 0)
        L->pressure = 1 + s->virial / (2 * s->kint);
    for (size_t i = 0; i < s->n; i++) {
        double *x = &p->x[3 * L->perm[i]], xi[3];
        edmd_pos(s, i, xi);
        for (int k = 0; k < 3; k++)
            x[k] = k < s->dim ? xi[k] : 0;
        pk_box_wrap(b, x);
        for (int k = 0; k < s->dim; k++) /* walled axes: keep round-off inside */
            if (!b->periodic[k])
                x[k] = fmin(fmax(x[k], 0), b->L[k]);
        p->r[L->perm[i]] = true_radius(s, i, s->t);
    }
    st->criterion = crit;
    switch (crit) {
    case PK_EDMD_CRIT_TARGET: st->reason = PK_STOP_COMPLETE; break;
    case PK_EDMD_CRIT_PRESSURE:
    case PK_EDMD_CRIT_DELTA_PHI: st->reason = PK_STOP_JAMMED; break;
    case PK_EDMD_CRIT_STALL: /* growing until jammed, a stall is the jam (Titscher §6.4) */
        st->reason = L->prm->until == PK_EDMD_UNTIL_JAMMED ? PK_STOP_JAMMED : PK_STOP_STALLED;
        break;
    case PK_EDMD_CRIT_MAX_EVENTS: st->reason = PK_STOP_STALLED; break;
    case PK_EDMD_CRIT_CANCEL: st->reason = PK_STOP_CANCELLED; break;
    case PK_EDMD_CRIT_WALL_TIME: st->reason = PK_STOP_WALL_TIME; break;
    default: st->reason = PK_STOP_ERROR; break;
    }
    st->phi = phi_true(s, s->t);
    st->phi_sim = phi_sim(s, s->t);
    st->pressure = L->pressure;
    st->phi_jam_estimate = L->pressure > s->dim ? st->phi / (1 - s->dim / L->pressure) : NAN;
    st->delta_d = 2 * (s->h0 + s->h1 * s->t);
    st->t_stop = L->t_base + s->t;
    st->overlaps = s->n_overlap;
    st->max_overlap_rel = s->max_overlap_rel;
    st->kinetic_ratio = L->K0 > 0 ? kinetic(s) / L->K0 : NAN;
    hist_push(st, &L->hist_stride, st->events, L->t_base + s->t, st->phi, L->pressure);
}

int pk_edmd_run(const pk_box *b, pk_particles *p, const pk_edmd_params *prm, pk_monitor *mon,
                pk_edmd_stats *st)
{
    memset(st, 0, sizeof *st);
    st->reason = PK_STOP_ERROR;
    st->criterion = PK_EDMD_CRIT_ERROR;
    if (!b || !p || !prm || p->dim != b->dim || p->n == 0 || p->n > INT32_MAX)
        return -1;
    edmd_state s = {0};
    pk_particles q = {0};
    run_loop L = {
        .prm = prm, .st = st, .mon = mon, .ckpt = prm->checkpoint, .w0 = pk_wall_seconds()};
    pk_edmd_criterion crit = PK_EDMD_CRIT_NONE;
    int rc = open_run(b, p, &q, &s, &L);
    /* take the first event, carry it out, then whatever is due after it */
    while (rc == 0 && !crit && (rc = step(&s, &L, &crit)) == 0 && !crit)
        rc = after_event(&s, &L, &crit);
    if (rc == 0)
        close_run(b, p, &s, &L, crit);
    st->seconds = pk_wall_seconds() - L.w0;
    state_free(&s);
    pk_particles_free(&q);
    free(L.perm);
    return rc;
}
