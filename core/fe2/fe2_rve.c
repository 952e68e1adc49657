/* fe2_rve.c — the DEM RVE at the Gauss points of FE²: trial evaluation,
 * audit, tangent, commit.  Contract: fe2_rve.h. */
#include "fe2_rve.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/homog/homog_audit.h"
#include "core/homog/homog_tangent.h"

/* The injected sparse solvers are called from several Gauss points at once
 * (a pool of threads); CHOLMOD over Debian's serial OpenBLAS is not
 * reentrant — two concurrent factorisations of a supernodal block return
 * wrong solutions now and then (relative errors up to 10 in a 900-dof test,
 * docs/perf/fe2.md) — so every call into a solver from an evaluation holds
 * the adapter's lock.  The vtables have no context: the evaluating thread
 * names its lock and the wrapped solvers in thread-local pointers for the
 * duration of its call. */
#ifndef __STDC_NO_THREADS__
#include <threads.h>

static _Thread_local mtx_t *tl_lock;
static _Thread_local const pk_sparse_solver *tl_tangent, *tl_newton;

#define LOCKED(solver, call)                                                                       \
    do {                                                                                           \
        if (tl_lock)                                                                               \
            mtx_lock(tl_lock);                                                                     \
        const pk_sparse_solver *s_ = (solver);                                                     \
        call;                                                                                      \
        if (tl_lock)                                                                               \
            mtx_unlock(tl_lock);                                                                   \
    } while (0)

/* One wrapper family per solver slot (the tangent's, the relaxation's). */
#define LOCKED_SOLVER(slot, tl)                                                                    \
    static pk_sparse_factor *slot##_factor(const pk_sparse_sym *A, pk_sparse_info *info)           \
    {                                                                                              \
        pk_sparse_factor *f;                                                                       \
        LOCKED(tl, f = s_->factor(A, info));                                                       \
        return f;                                                                                  \
    }                                                                                              \
    static pk_sparse_factor *slot##_factor_pd(const pk_sparse_sym *A, pk_sparse_info *info)        \
    {                                                                                              \
        pk_sparse_factor *f;                                                                       \
        LOCKED(tl, f = s_->factor_pd(A, info));                                                    \
        return f;                                                                                  \
    }                                                                                              \
    static pk_sparse_factor *slot##_factor_pd_ctx(pk_sparse_ctx *c, const pk_sparse_sym *A,        \
                                                  pk_sparse_info *info)                            \
    {                                                                                              \
        pk_sparse_factor *f;                                                                       \
        LOCKED(tl, f = s_->factor_pd_ctx(c, A, info));                                             \
        return f;                                                                                  \
    }                                                                                              \
    static pk_sparse_ctx *slot##_ctx_new(void)                                                     \
    {                                                                                              \
        pk_sparse_ctx *c;                                                                          \
        LOCKED(tl, c = s_->ctx_new());                                                             \
        return c;                                                                                  \
    }                                                                                              \
    static void slot##_ctx_free(pk_sparse_ctx *c) { LOCKED(tl, s_->ctx_free(c)); }                 \
    static int slot##_solve(pk_sparse_factor *f, size_t nrhs, const double *B, double *X)          \
    {                                                                                              \
        int rc;                                                                                    \
        LOCKED(tl, rc = s_->solve(f, nrhs, B, X));                                                 \
        return rc;                                                                                 \
    }                                                                                              \
    static void slot##_release(pk_sparse_factor *f) { LOCKED(tl, s_->release(f)); }                \
    static const pk_sparse_solver slot##_locked = {                                                \
        "locked",       slot##_factor,   slot##_factor_pd, slot##_factor_pd_ctx,                   \
        slot##_ctx_new, slot##_ctx_free, slot##_solve,     slot##_release};

LOCKED_SOLVER(tangent, tl_tangent)
LOCKED_SOLVER(newton, tl_newton)
#endif

/* in-plane index (11, 12, 21, 22) → the 3D-embedded index a·3 + b */
static const int EMB[4] = {0, 1, 3, 4};

size_t pk_fe2_rve_index(const pk_fe2_rve *m, size_t g) { return g % m->nrve; }

static const char *eval_error(int rc)
{
    switch (rc) {
    case -1: return "out of memory";
    case -2: return "periodic box too small for this F";
    case -3: return "det F <= 0 or not finite";
    default: return "evaluation refused";
    }
}

static int rve_eval(void *ctx, size_t g, const double F[4], double P[4], double A[16],
                    pk_fe2_gp_info *info, char *why, size_t whylen)
{
    pk_fe2_rve *m = ctx;
    if (g < m->lo || g >= m->hi) {
        snprintf(why, whylen, "Gauss point %zu is not held here (block %zu..%zu)", g, m->lo, m->hi);
        return 1;
    }
    const pk_homog_rve *rve = &m->rve[pk_fe2_rve_index(m, g)];
    const double F3[9] = {F[0], F[1], 0, F[2], F[3], 0, 0, 0, 1};
    pk_homog_step st;
    pk_homog_opts o = m->o;
    const pk_sparse_solver *tsolver = m->solver;
#ifndef __STDC_NO_THREADS__
    tl_lock = m->lock, tl_tangent = m->solver, tl_newton = m->o.newton;
    tsolver = &tangent_locked;
    if (o.newton)
        o.newton = &newton_locked;
#endif
    int rc = pk_homog_eval(rve, &o, &m->committed[g], F3, &m->trial[g], &st, NULL);
    if (rc != 0) {
        snprintf(why, whylen, "RVE: %s", eval_error(rc));
        return 1;
    }
    pk_homog_audit au;
    if (pk_homog_audit_step(rve, &o, &m->trial[g], &st, &au)) {
        char what[200];
        pk_homog_audit_describe(&au, &st, what, sizeof what);
        snprintf(why, whylen, "RVE relaxation: %s", what);
        return 1;
    }
    double A3[81];
    pk_tangent_info ti;
    rc = pk_homog_tangent(rve, &o, &m->trial[g], tsolver, A3, &ti);
    if (rc != 0) {
        if (rc == 1)
            snprintf(why, whylen, "RVE tangent: jammed block %s",
                     pk_sparse_status_name(ti.block.status));
        else
            snprintf(why, whylen, "RVE tangent: %s",
                     rc == -3 ? "friction (no analytic tangent)" : eval_error(rc));
        return 1;
    }
    for (int I = 0; I < 4; I++) {
        P[I] = st.P[EMB[I]];
        for (int J = 0; J < 4; J++)
            A[4 * I + J] = A3[9 * EMB[I] + EMB[J]];
    }
    if (info) {
        memset(info, 0, sizeof *info);
        info->energy = st.energy_density;
        info->coordination = st.coordination;
        info->rattlers = st.rattlers;
        info->relax_iter = st.dr.iterations + (st.used_newton ? st.newton.iterations : 0);
    }
    return 0;
}

static int rve_commit(void *ctx, size_t g)
{
    pk_fe2_rve *m = ctx;
    if (g < m->lo || g >= m->hi)
        return -1;
    return pk_homog_commit(&m->committed[g], &m->trial[g]) == 0 ? 0 : -1;
}

pk_fe2_material pk_fe2_rve_material(pk_fe2_rve *m)
{
    pk_fe2_material mat = {"rve", m, rve_eval, rve_commit};
    return mat;
}

int pk_fe2_rve_init(pk_fe2_rve *m, const pk_homog_rve *rve, size_t nrve, const pk_homog_opts *o,
                    const pk_sparse_solver *solver, size_t ngp, pk_monitor *mon, char *err,
                    size_t errlen)
{
    return pk_fe2_rve_init_block(m, rve, nrve, o, solver, ngp, 0, ngp, mon, err, errlen);
}

int pk_fe2_rve_init_block(pk_fe2_rve *m, const pk_homog_rve *rve, size_t nrve,
                          const pk_homog_opts *o, const pk_sparse_solver *solver, size_t ngp,
                          size_t lo, size_t hi, pk_monitor *mon, char *err, size_t errlen)
{
    memset(m, 0, sizeof *m);
    if (nrve == 0 || lo > hi || hi > ngp) {
        if (nrve == 0)
            snprintf(err, errlen, "no RVE");
        else
            snprintf(err, errlen, "Gauss points %zu..%zu of %zu", lo, hi, ngp);
        return -1;
    }
    m->nrve = nrve, m->ngp = ngp, m->rve = rve, m->o = *o, m->solver = solver;
    m->lo = lo, m->hi = hi;
    m->committed = calloc(ngp ? ngp : 1, sizeof *m->committed);
    m->trial = calloc(ngp ? ngp : 1, sizeof *m->trial);
    m->start = calloc(nrve, sizeof *m->start);
    m->P0 = calloc(4 * nrve, sizeof *m->P0);
    pk_homog_state s0 = {0}, relaxed = {0};
    if (!m->committed || !m->trial || !m->start || !m->P0) {
        snprintf(err, errlen, "out of memory");
        goto fail;
    }
    const double I3[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    for (size_t k = 0; k < nrve; k++) {
        if (pk_homog_state_init(&rve[k], o, &s0) != 0) {
            snprintf(err, errlen, "out of memory");
            goto fail;
        }
        int rc = pk_homog_eval(&rve[k], o, &s0, I3, &relaxed, &m->start[k], mon);
        pk_homog_state_free(&s0);
        if (rc != 0) {
            snprintf(err, errlen, "RVE %zu at F = 1: %s", k, eval_error(rc));
            goto fail;
        }
        if (m->start[k].dr.stop == PK_DR_CANCELLED || m->start[k].dr.stop == PK_DR_WALL_TIME) {
            snprintf(err, errlen, "RVE %zu at F = 1: %s", k, pk_dr_stop_name(m->start[k].dr.stop));
            goto fail;
        }
        pk_homog_audit au;
        if (pk_homog_audit_step(&rve[k], o, &relaxed, &m->start[k], &au)) {
            char what[200];
            pk_homog_audit_describe(&au, &m->start[k], what, sizeof what);
            snprintf(err, errlen, "RVE %zu relaxed at F = 1: %s", k, what);
            goto fail;
        }
        for (int I = 0; I < 4; I++)
            m->P0[4 * k + I] = m->start[k].P[EMB[I]];
        for (size_t g = lo + (k + nrve - lo % nrve) % nrve; g < hi; g += nrve)
            if (pk_homog_state_copy(&m->committed[g], &relaxed) != 0) {
                snprintf(err, errlen, "out of memory");
                goto fail;
            }
    }
    pk_homog_state_free(&relaxed);
    m->o.par = NULL;
    m->o.newton_ctx = NULL;
#ifndef __STDC_NO_THREADS__
    mtx_t *lock = malloc(sizeof *lock);
    if (!lock || mtx_init(lock, mtx_plain) != thrd_success) {
        free(lock);
        snprintf(err, errlen, "out of memory (lock)");
        goto fail;
    }
    m->lock = lock;
#endif
    return 0;
fail:
    pk_homog_state_free(&s0);
    pk_homog_state_free(&relaxed);
    pk_fe2_rve_free(m);
    return -1;
}

void pk_fe2_rve_free(pk_fe2_rve *m)
{
    for (size_t g = 0; m->committed && g < m->ngp; g++)
        pk_homog_state_free(&m->committed[g]);
    for (size_t g = 0; m->trial && g < m->ngp; g++)
        pk_homog_state_free(&m->trial[g]);
    free(m->committed), free(m->trial), free(m->start), free(m->P0);
#ifndef __STDC_NO_THREADS__
    if (m->lock)
        mtx_destroy(m->lock);
#endif
    free(m->lock);
    memset(m, 0, sizeof *m);
}
