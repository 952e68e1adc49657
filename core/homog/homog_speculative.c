/* homog_speculative.c — the Newton/DR hybrid with its attempts made
 * speculatively on a second thread, a wrapper of the serial hybrid's step.
 * Contract: homog_speculative.h; the parts it wraps: homog_hybrid.h.
 *
 * An attempt that fails leaves DR's path as it was, so the path is that of
 * a hybrid whose attempts all fail until one converges: the relaxation runs
 * on along it on the calling thread while a worker thread makes the Newton
 * phase from the step's start and then the attempts, in order, each from a
 * copy of the point DR (or FIRE) had reached when it asked.  The first that
 * converges wins: the relaxation stops (pk_dr_hook.poll), and the step ends
 * as the serial hybrid ends there — its point, statistics and DR's pair list
 * as they were at that point (the list rebuilt where it had been built).
 * Without a winner the relaxation's own end stands.  Same bits as the
 * serial hybrid, on any machine (tests/unit/test_homog_speculative.c); the
 * time is about the longer of the two threads' work instead of the sum.
 * A point copies 6·N doubles (x and the list's build positions); at most
 * SPEC_QUEUE wait, beyond that the relaxation waits for the worker.  On two
 * threads the relaxation's evaluations are serial: the second core is the
 * worker's (docs/perf/homog.md). */
#include "homog_speculative.h"
#include "homog_hybrid.h"

#include "core/base/par.h"

#if !defined(__STDC_NO_THREADS__)
#include <stdlib.h>
#include <string.h>
#include <threads.h>
#include <time.h>

#define SPEC_QUEUE 8

typedef struct spec_point {
    double *x;      /* the point (a copy); the solution when solved */
    double *xb;     /* where the relaxation's pair list was built then */
    pk_dr_stats st; /* the relaxation's statistics then (DR's or FIRE's) */
    int fire;       /* a point of FIRE's (else DR's) */
    int first;      /* the Newton phase from the step's start */
    double fres;    /* the residual at the solution */
} spec_point;

typedef struct spec {
    mtx_t m;
    cnd_t cv;
    spec_point **pt;
    size_t n, cap, done; /* points queued, room, finished (in order) */
    int closed;          /* no more points: the relaxation has ended */
    int worker_done;
    int worker_rc;         /* < 0: the worker's error */
    atomic_int stop;       /* the worker solved the step or failed: the relaxation stops */
    atomic_int abort;      /* the relaxation was cancelled or failed: the worker stops */
    size_t solved;         /* 1 + the index of the point solved; 0: none */
    attempt_ctx *a;        /* the worker's: its own pair list, work, budget, statistics */
    const pk_dem_pairs *c; /* the relaxation's pair list */
    pk_dr_hook *hook;
    size_t points; /* attempt points so far (fire_after) */
    size_t fire_after;
    int fire;        /* the relaxation is FIRE */
    double phi0, f0; /* the first phase's start (w->f holds its forces) */
    size_t stall_first;
    double target;
} spec;

static void point_free(spec_point *p)
{
    if (p) {
        free(p->x);
        free(p->xb);
        free(p);
    }
}

/* A point: x and the build positions xb copied (xb NULL: none yet). */
static spec_point *point_new(size_t np, const double *x, const double *xb)
{
    spec_point *p = calloc(1, sizeof *p);
    if (!p)
        return NULL;
    p->x = malloc(3 * (np ? np : 1) * sizeof *p->x);
    p->xb = malloc(3 * (np ? np : 1) * sizeof *p->xb);
    if (!p->x || !p->xb) {
        point_free(p);
        return NULL;
    }
    memcpy(p->x, x, 3 * np * sizeof *x);
    if (xb)
        memcpy(p->xb, xb, 3 * np * sizeof *xb);
    return p;
}

/* Queue p (the worker takes it in turn); -1 when out of memory. */
static int spec_push(spec *s, spec_point *p)
{
    mtx_lock(&s->m);
    while (s->n - s->done >= SPEC_QUEUE && !s->worker_done)
        cnd_wait(&s->cv, &s->m);
    if (s->n == s->cap) {
        size_t cap = s->cap ? 2 * s->cap : 16;
        spec_point **q = realloc(s->pt, cap * sizeof *q);
        if (!q) {
            mtx_unlock(&s->m);
            return -1;
        }
        s->pt = q;
        s->cap = cap;
    }
    s->pt[s->n++] = p;
    cnd_broadcast(&s->cv);
    mtx_unlock(&s->m);
    return 0;
}

/* The Newton phase from the step's start on p->x: 1 converged, 0 not, < 0
 * an error; p->xb := where its pair list was built last (the serial
 * hybrid's list at its end). */
static int spec_first(spec *s, spec_point *p)
{
    attempt_ctx *a = s->a;
    double phi = s->phi0, fn = s->f0;
    int rc = pk_hybrid_newton_phase(&a->sy, a->w, p->x, &phi, &fn, a->target, s->stall_first, 0,
                                    a->budget, a->ns, a->st);
    if (rc < 0)
        return rc;
    memcpy(p->xb, a->sy.s.c->xb, 3 * a->sy.s.np * sizeof *p->xb);
    p->fres = fn;
    return rc == 0 && a->ns->exit == PK_NEWTON_CONVERGED;
}

static int spec_worker(void *arg)
{
    spec *s = arg;
    for (size_t k = 0;; k++) {
        mtx_lock(&s->m);
        while (k >= s->n && !s->closed && !atomic_load(&s->abort))
            cnd_wait(&s->cv, &s->m);
        spec_point *p = k < s->n && !atomic_load(&s->abort) ? s->pt[k] : NULL;
        mtx_unlock(&s->m);
        if (!p)
            break;
        int r = p->first ? spec_first(s, p) : pk_hybrid_attempt_from(s->a, p->x, &p->fres);
        mtx_lock(&s->m);
        s->done = k + 1;
        if (r == 1)
            s->solved = k + 1;
        if (r < 0)
            s->worker_rc = r;
        if (r != 0)
            atomic_store(&s->stop, 1);
        cnd_broadcast(&s->cv);
        mtx_unlock(&s->m);
        if (r != 0)
            break;
    }
    mtx_lock(&s->m);
    s->worker_done = 1;
    cnd_broadcast(&s->cv);
    mtx_unlock(&s->m);
    return 0;
}

/* The relaxation's hook: the point queued, the answer of an unsolved one. */
static int spec_hook(void *vctx, double *x, double *fres, double *at)
{
    (void)fres;
    spec *s = vctx;
    pk_hybrid_next_threshold(at, s->target);
    spec_point *p = point_new(s->a->sy.s.np, x, s->c->xb);
    if (!p)
        return -1;
    p->st = *s->hook->running;
    p->fire = s->fire;
    if (spec_push(s, p) != 0) {
        point_free(p);
        return -1;
    }
    return s->fire_after && ++s->points >= s->fire_after ? 2 : 0;
}

static int spec_poll(void *vctx)
{
    spec *s = vctx;
    return atomic_load_explicit(&s->stop, memory_order_relaxed);
}

/* Wait for the worker (the monitor ticked meanwhile: a cancel stops it). */
static void spec_wait(spec *s, pk_monitor *mon)
{
    mtx_lock(&s->m);
    s->closed = 1;
    cnd_broadcast(&s->cv);
    while (!s->worker_done) {
        struct timespec ts;
        timespec_get(&ts, TIME_UTC);
        ts.tv_nsec += 100000000L; /* 0.1 s */
        if (ts.tv_nsec >= 1000000000L) {
            ts.tv_sec++;
            ts.tv_nsec -= 1000000000L;
        }
        cnd_timedwait(&s->cv, &s->m, &ts);
        if (!s->worker_done && mon) {
            mtx_unlock(&s->m);
            pk_progress pr = {.stage = "newton", .fraction = -1, .phi = -1, .eta_s = -1};
            if (pk_monitor_tick(mon, &pr, 0))
                atomic_store(&s->abort, 1);
            mtx_lock(&s->m);
        }
    }
    mtx_unlock(&s->m);
}

/* The step as the serial hybrid ends at the point solved, p: x, st, ns's
 * FIRE iterations and the relaxation's pair list c (rebuilt where it had
 * been built then; its geometry is the caller's to evaluate at x). */
static int spec_apply(const spec *s, const spec_point *p, const newton_run *sy, double *x,
                      const pk_dr_stats *st_dr, pk_dr_stats *st, pk_newton_stats *ns)
{
    const pk_dr_params *prm = sy->prm;
    const size_t np = sy->s.np;
    memcpy(x, p->x, 3 * np * sizeof *x);
    int rc = pk_dem_pairs_build(sy->s.c, sy->s.g, p->xb, sy->s.r, np, prm->skin);
    if (rc != 0)
        return rc;
    ns->fire_iterations = 0; /* unless the point is FIRE's (pk_hybrid_fire_merge) */
    if (p->first) {
        memset(st, 0, sizeof *st);
        st->f0 = s->f0;
        st->f = p->fres;
        st->stop = p->fres <= prm->tol * s->f0 ? PK_DR_CONVERGED : PK_DR_CONVERGED_ABS;
        return 0;
    }
    if (!p->fire) {
        *st = p->st;
        pk_relax_hook_solved(st, prm, p->fres);
    } else {
        *st = *st_dr;
        pk_dr_params fp = pk_hybrid_fire_params(prm, s->target, st);
        pk_dr_stats fs = p->st;
        pk_relax_hook_solved(&fs, &fp, p->fres);
        pk_hybrid_fire_merge(st, &fs, prm, ns);
    }
    return 0;
}

/* The hybrid after pk_hybrid_begin with its attempts made speculatively on
 * a second thread: the serial step's result (pk_hybrid_step), bit for bit. */
static int speculative(pk_hybrid *h, double *x, const pk_hybrid_plan *plan, pk_dr_stats *st,
                       pk_newton_stats *ns)
{
    const newton_run *sy = &h->sy;
    newton_work *w = &h->w;
    pk_dem_pairs *c2 = &h->c2;
    const double phi0 = h->phi0, f0 = h->f0, target = h->target;
    size_t *budget = &h->budget;
    pk_dem_pairs *c = sy->s.c;
    const size_t np = sy->s.np;
    pk_par *par = c->par;
    if (pk_par_threads(par) <= 2) /* the two threads are the relaxation's and the worker's */
        c->par = c2->par = NULL;
    /* c2 := c (the same build, the same geometry) for the first phase */
    int rc = pk_dem_pairs_build(c2, sy->s.g, x, sy->s.r, np, sy->prm->skin);
    if (rc == 0)
        pk_dem_eval(c2, sy->s.g, x, sy->s.r, np, sy->s.E, NULL, NULL, NULL);
    pk_newton_stats nsw = *ns;
    pk_dr_stats stw = {0}, st_dr = {0};
    spec s = {.f0 = f0,
              .phi0 = phi0,
              .target = target,
              .c = c,
              .fire_after = plan->fire_after,
              .stall_first = plan->stall_first};
    atomic_init(&s.stop, 0);
    atomic_init(&s.abort, 0);
    attempt_ctx a = {*sy, w, target, budget, &nsw, &stw, plan->fire_after, 0};
    a.sy.s.c = c2;
    a.sy.mon = NULL; /* the relaxation ticks the monitor; the worker stops on s.abort */
    a.sy.abort = &s.abort;
    s.a = &a;
    pk_dr_hook hook = {
        .fn = spec_hook, .ctx = &s, .poll = spec_poll, .at = plan->at, .crawl = plan->crawl};
    s.hook = &hook;
    spec_point *first = rc == 0 ? point_new(np, x, NULL) : NULL;
    if (rc != 0 || !first) {
        c->par = par;
        return rc != 0 ? rc : -1;
    }
    first->first = 1;
    thrd_t th;
    if (mtx_init(&s.m, mtx_plain) != thrd_success) {
        point_free(first);
        c->par = par;
        return -1;
    }
    if (cnd_init(&s.cv) != thrd_success) {
        mtx_destroy(&s.m);
        point_free(first);
        c->par = par;
        return -1;
    }
    int started = spec_push(&s, first) == 0 && thrd_create(&th, spec_worker, &s) == thrd_success;
    if (!started) {
        if (s.n == 0)
            point_free(first);
        rc = -1;
    } else {
        rc =
            pk_hybrid_relax_then_fire(sy, x, target, &hook, &s.fire_after, &s.fire, st, &st_dr, ns);
        /* the points queued are the serial hybrid's all the same (it made
         * them before the end the relaxation reached alone) — unless this
         * was a cancel or an error */
        if (rc != 0 || st->stop == PK_DR_CANCELLED || st->stop == PK_DR_WALL_TIME)
            atomic_store(&s.abort, 1);
        spec_wait(&s, sy->mon);
        thrd_join(th, NULL);
    }
    c->par = c2->par = par;
    size_t fire_iterations = ns->fire_iterations;
    *ns = nsw;
    ns->fire_iterations = fire_iterations; /* the relaxation's (FIRE's) */
    if (rc == 0 && s.worker_rc < 0)
        rc = s.worker_rc;
    const spec_point *won = rc == 0 && s.solved ? s.pt[s.solved - 1] : NULL;
    if (won)
        rc = spec_apply(&s, won, sy, x, &st_dr, st, ns);
    /* as the serial hybrid: after the relaxation (and an attempt from one of
     * its points) c is refreshed where x left it; not after the first phase */
    if (rc == 0 && !(won && won->first) && pk_dem_pairs_stale(c, x, sy->s.g->dim))
        rc = pk_dem_pairs_build(c, sy->s.g, x, sy->s.r, np, sy->prm->skin);
    for (size_t k = 0; k < s.n; k++)
        point_free(s.pt[k]);
    free(s.pt);
    cnd_destroy(&s.cv);
    mtx_destroy(&s.m);
    return rc;
}
#endif

int pk_homog_newton_speculative(const pk_dem_system *s, double *x, const pk_dr_params *prm,
                                const pk_newton_opts *no, pk_monitor *mon, pk_dr_stats *st,
                                pk_newton_stats *ns)
{
    pk_hybrid h;
    int rc = pk_hybrid_begin(&h, s, x, prm, no, mon, st, ns);
#if !defined(__STDC_NO_THREADS__)
    if (rc == 0 && pk_par_threads(s->c->par) >= 2 && h.f0 > h.target) {
        pk_hybrid_plan plan = pk_hybrid_plan_of(&h);
        rc = speculative(&h, x, &plan, st, ns);
        pk_hybrid_end(&h);
        return rc;
    }
#endif
    if (rc == 0)
        rc = pk_hybrid_step(&h, x, st, ns);
    pk_hybrid_end(&h);
    return rc;
}
