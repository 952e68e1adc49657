/* dem_eval_par.c — the threaded assembly of the contact forces on c->par;
 * contract: dem_internal.h (pk_dem_eval_threaded), knobs in dem_contact.h. */
#include "dem_internal.h"

#include <stdatomic.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "core/base/par.h"

/* The evaluation on c->par reproduces the serial loops' sums operation for
 * operation.  Serially, f is zeroed; the candidates come sorted by i, one run
 * per i, j > i (pk_dem_pairs_build lists them grain by grain; csr_build
 * checks it); each
 * contact does f[j] −= fa in pair order, and i's run sums its fa from 0 in
 * fi, added to f[i] when i changes.  So f_k = J_k + I_k with
 * J_k = ((0 − a₁) − a₂)… over the contacts with j = k (they have i < k: all
 * before k's run) and I_k = ((0 + b₁) + b₂)… over k's run (0 + I_k or J_k
 * alone when one side is empty; I_k is never −0, a sum from +0).
 * Phase A, candidate ranges cut at run boundaries, in parallel: the serial
 * loop itself (pk_dem_eval_part, dem_eval_loops.c: the lanes, the L1 buffers,
 * the runs' sums added to the zeroed f as serially) stores fa of each candidate
 * (+0 when open) instead of scattering it to f[j].  Phase B, grain ranges
 * in parallel: f_k = J_k + f_k, J_k over the candidates with j = k in pair
 * order; an open candidate's +0 changes no bit of J (v − (+0) = v for
 * v ≠ −0, NaN included, and J is never −0), and grains without such
 * candidates are already final (0 + I_k).  Phase B's part P takes phase
 * A's grains of part P sorted by their count of j-candidates (ord): the
 * inner loop's trip count is the same for long stretches (predicted) and
 * the grains' chains independent.  The energy and S are chains over pair
 * order: one part walks them after phase A, in the serial order.  Both
 * phases are one job of the pool (job_forces).  Phase B in grain order was
 * slower (docs/perf/dem.md). */
size_t pk_dem_par_min_pairs = 4096;

/* Start of part t of nt among [0, m): equal shares of the work ofs[m] + m
 * (ofs non-decreasing: candidates before each index). */
static size_t split_at(const int32_t *ofs, size_t m, int t, int nt)
{
    size_t target = ((size_t)ofs[m] + m) * (size_t)t / (size_t)nt, lo = 0, hi = m;
    while (lo < hi) {
        size_t k = lo + (hi - lo) / 2;
        if ((size_t)ofs[k] + k < target)
            lo = k + 1;
        else
            hi = k;
    }
    return lo;
}

/* The per-grain lists of c's candidates for nparts parts (csr_state 1), or
 * csr_state −1 when the list is not in build order or memory fails (the
 * serial code then). */
static void csr_build(pk_dem_pairs *c, size_t np, int dim, int nparts)
{
    const size_t n = c->n;
    c->csr_state = -1;
    c->csr_n = n;
    c->csr_np = np;
    c->csr_dim = dim;
    c->csr_parts = nparts;
    if (n > INT32_MAX || np > INT32_MAX)
        return;
    for (size_t p = 0; p < n; p++)
        if (c->i[p] < 0 || c->i[p] >= c->j[p] || (size_t)c->j[p] >= np ||
            (p && c->i[p] < c->i[p - 1]))
            return;
    if (n > c->csr_pcap) {
        free(c->fa), free(c->jq);
        c->fa = malloc(3 * n * sizeof *c->fa);
        c->jq = malloc(n * sizeof *c->jq);
        c->csr_pcap = c->fa && c->jq ? n : 0;
        if (!c->csr_pcap)
            return;
    }
    if (np + 1 > c->csr_gcap) {
        free(c->ord), free(c->jofs), free(c->iofs);
        c->ord = malloc(np * sizeof *c->ord);
        c->jofs = malloc((np + 1) * sizeof *c->jofs);
        c->iofs = malloc((np + 1) * sizeof *c->iofs);
        c->csr_gcap = c->ord && c->jofs && c->iofs ? np + 1 : 0;
        if (!c->csr_gcap)
            return;
    }
    free(c->bofs);
    c->bofs = malloc(((size_t)nparts + 1) * sizeof *c->bofs);
    int32_t *cnt = calloc(2 * np + 1, sizeof *cnt); /* per grain: count, then cursor */
    if (!c->bofs || !cnt) {
        free(cnt);
        return;
    }
    int32_t *at = cnt + np;
    int32_t *ord = c->ord, *jofs = c->jofs, *iofs = c->iofs;
    size_t p = 0, cmax = 0;
    for (size_t k = 0; k < np; k++) { /* the runs */
        iofs[k] = (int32_t)p;
        while (p < n && (size_t)c->i[p] == k)
            p++;
    }
    iofs[np] = (int32_t)n;
    for (size_t q = 0; q < n; q++)
        cnt[c->j[q]]++;
    for (size_t k = 0; k < np; k++)
        cmax = (size_t)cnt[k] > cmax ? (size_t)cnt[k] : cmax;
    int32_t *first = malloc((cmax + 2) * sizeof *first);
    if (!first) {
        free(cnt);
        return;
    }
    /* ord: per part (the grains of phase A's part P), its grains with
     * cnt >= 1 by cnt (counting sort, stable in k) */
    size_t m = 0;
    for (int P = 0; P < nparts; P++) {
        size_t k0 = split_at(iofs, np, P, nparts), k1 = split_at(iofs, np, P + 1, nparts);
        c->bofs[P] = (int32_t)m;
        memset(first, 0, (cmax + 2) * sizeof *first);
        for (size_t k = k0; k < k1; k++)
            if (cnt[k])
                first[cnt[k] + 1]++;
        first[1] = (int32_t)m;
        for (size_t d = 1; d <= cmax; d++)
            first[d + 1] += first[d];
        for (size_t k = k0; k < k1; k++)
            if (cnt[k])
                ord[first[cnt[k]]++] = (int32_t)k;
        m = (size_t)first[cmax + 1];
    }
    c->bofs[nparts] = (int32_t)m;
    free(first);
    jofs[0] = 0;
    for (size_t q = 0; q < m; q++) {
        jofs[q + 1] = jofs[q] + cnt[ord[q]];
        at[ord[q]] = jofs[q]; /* fill cursor of grain ord[q] */
    }
    for (size_t q = 0; q < n; q++)
        c->jq[at[c->j[q]]++] = (int32_t)q;
    free(cnt);
    c->csr_state = 1;
}

/* The parallel path for this call?  (Lists in build order only.) */
static int par_ready(pk_dem_pairs *c, size_t np, int dim, const double *f, int nparts)
{
    if (!c->par || !f || c->n == 0 || c->n < pk_dem_par_min_pairs || pk_par_threads(c->par) < 2)
        return 0;
    if (c->csr_state == 0 || c->csr_n != c->n || c->csr_np != np || c->csr_dim != dim ||
        c->csr_parts != nparts)
        csr_build(c, np, dim, nparts);
    return c->csr_state == 1;
}

#if defined(__GNUC__)
#define PREFETCH(a) __builtin_prefetch(a)
#else
#define PREFETCH(a) ((void)0)
#endif

/* Phase B over ord[ma, mb): f_k = J_k + f_k.  The gathers (fa of random
 * candidates, f of random grains, half of them last written by the other
 * thread) are prefetched 16 grains and 32 candidates ahead (docs/perf/dem.md). */
static inline void grain_forces(const pk_dem_pairs *c, double *f, size_t ma, size_t mb,
                                const int dim)
{
    const double *fa = c->fa;
    const int32_t *jq = c->jq, *jofs = c->jofs, *ord = c->ord, qend = jofs[mb];
    for (size_t m = ma; m < mb; m++) {
        double J0 = 0, J1 = 0, J2 = 0;
        if (m + 16 < mb)
            PREFETCH(&f[3 * (size_t)ord[m + 16]]);
        for (int32_t q = jofs[m]; q < jofs[m + 1]; q++) {
            if (q + 32 < qend)
                PREFETCH(&fa[(size_t)dim * (size_t)jq[q + 32]]);
            const double *a = &fa[(size_t)dim * (size_t)jq[q]];
            J0 -= a[0];
            J1 -= a[1];
            if (dim == 3)
                J2 -= a[2];
        }
        double *fk = &f[3 * (size_t)ord[m]];
        fk[0] = J0 + fk[0];
        fk[1] = J1 + fk[1];
        if (dim == 3)
            fk[2] = J2 + fk[2];
    }
}

/* The energy (4.7) and the contact sum S: the serial chains, pair order. */
static inline void pair_chains(const pk_dem_pairs *c, double E, double *energy, double S[9],
                               const int dim)
{
    double phi = 0;
    for (size_t p = 0; p < c->n; p++) {
        double eps = c->eps[p];
        if (!(eps >= 0) || !(c->len[p] > 0))
            continue;
        double k = pk_dem_pair_E(c, p, E);
        phi += 0.5 * k * eps * eps; /* (4.3) */
        if (S)
            for (int a = 0; a < dim; a++)
                for (int b = 0; b < dim; b++)
                    S[3 * a + b] += c->fa[(size_t)dim * p + (size_t)a] * c->l[3 * p + b];
    }
    if (energy)
        *energy = phi;
}

/* Parts per thread of phase A (and of phase B), claimed as threads come free:
 * the parts' costs and the threads' speeds differ.  4: 2.65–2.69 ns per
 * candidate on 10⁴ random grains, 2 threads (serial 3.9–4.1; docs/perf/dem.md). */
#define PARTS_PER_THREAD 4
#define MAX_PARTS (PARTS_PER_THREAD * PK_PAR_MAX)

typedef struct par_job {
    pk_dem_pairs *c;
    const pk_dem_geom *g;
    const double *x, *r;
    double E;
    double *f, *energy, *S;
    int keep;           /* pk_dem_eval_part's keep */
    int nparts, chains; /* parts of each phase; 1: walk the energy/S chains */
    atomic_size_t nc;   /* contacts */
    atomic_int next;    /* phase A's next part to claim */
    atomic_int chain_taken;
    atomic_int done[MAX_PARTS];  /* phase A's parts finished */
    atomic_int taken[MAX_PARTS]; /* phase B's parts claimed */
} par_job;

/* Phase A's part t: the grains split_at(iofs, t) .. (t + 1), their runs. */
static void pair_forces_part(par_job *e, int t)
{
    pk_dem_pairs *c = e->c;
    const pk_dem_geom *g = e->g;
    const double *x = e->x, *r = e->r, E = e->E;
    double *f = e->f;
    const size_t np = c->csr_np;
    size_t ka = split_at(c->iofs, np, t, e->nparts), kb = split_at(c->iofs, np, t + 1, e->nparts);
    size_t pa = (size_t)c->iofs[ka], pb = (size_t)c->iofs[kb];
    memset(&f[3 * ka], 0, 3 * (kb - ka) * sizeof *f);
    size_t nc = pk_dem_eval_part(c, g, x, r, E, f, pa, pb, e->keep);
    atomic_fetch_add_explicit(&e->nc, nc, memory_order_relaxed);
}

/* Wait until phase A's parts [0, upto) are done (all claimed already). */
static void wait_pair_forces(par_job *e, int upto)
{
    unsigned k = 0;
    for (int q = 0; q < upto; q++)
        while (!atomic_load_explicit(&e->done[q], memory_order_acquire))
            pk_par_wait_step(&k);
}

/* Phase B's part P (after phase A's parts 0 .. P: the candidates j = k of
 * its grains have i < k, and f_k is phase A's part P's). */
static void grain_forces_part(par_job *e, int P)
{
    wait_pair_forces(e, P + 1);
    const pk_dem_pairs *c = e->c;
    if (e->g->dim == 2)
        grain_forces(c, e->f, (size_t)c->bofs[P], (size_t)c->bofs[P + 1], 2);
    else
        grain_forces(c, e->f, (size_t)c->bofs[P], (size_t)c->bofs[P + 1], 3);
}

/* One thread's share of the job (pk_par_run: one per thread, and whoever
 * comes late finds the work taken): phase A's parts as they come, then the
 * chains (one thread, after all of phase A), then phase B — first the parts
 * of the grains whose phase A this thread ran (their f and half of their fa
 * in its cache), then any left.  A part of phase B waits only for phase A's
 * parts, all claimed by then by running threads.  Phase B thus starts while
 * the last parts of phase A run, and one hand-over serves both phases.
 * The evaluation waits for descheduled threads: give the job its cores. */
static void job_forces(void *ctx, int t, int nt)
{
    (void)t, (void)nt;
    par_job *e = ctx;
    uint64_t mine[MAX_PARTS / 64] = {0};
    for (int P; (P = atomic_fetch_add_explicit(&e->next, 1, memory_order_relaxed)) < e->nparts;) {
        pair_forces_part(e, P);
        atomic_store_explicit(&e->done[P], 1, memory_order_release);
        mine[P / 64] |= (uint64_t)1 << (P % 64);
    }
    if (e->chains && !atomic_exchange_explicit(&e->chain_taken, 1, memory_order_relaxed)) {
        wait_pair_forces(e, e->nparts);
        if (e->g->dim == 2)
            pair_chains(e->c, e->E, e->energy, e->S, 2);
        else
            pair_chains(e->c, e->E, e->energy, e->S, 3);
    }
    for (int pass = 0; pass < 2; pass++)
        for (int P = 0; P < e->nparts; P++)
            if ((pass || (mine[P / 64] >> (P % 64) & 1)) &&
                !atomic_load_explicit(&e->taken[P], memory_order_relaxed) &&
                !atomic_exchange_explicit(&e->taken[P], 1, memory_order_relaxed))
                grain_forces_part(e, P);
}

/* pk_dem_eval / pk_dem_eval_forces on c->par (f != NULL, csr built for
 * nparts, S zeroed). */
static size_t eval_par(pk_dem_pairs *c, const pk_dem_geom *g, const double *x, const double *r,
                       double E, double *f, double *energy, double S[9], int keep, int nparts)
{
    par_job e = {.c = c, .g = g, .x = x, .r = r, .E = E, .f = f, .energy = energy, .S = S};
    e.keep = keep;
    e.nparts = nparts;
    e.chains = energy || S;
    atomic_init(&e.nc, 0);
    atomic_init(&e.next, 0);
    atomic_init(&e.chain_taken, 0);
    for (int t = 0; t < nparts; t++) {
        atomic_init(&e.done[t], 0);
        atomic_init(&e.taken[t], 0);
    }
    pk_par_run(c->par, job_forces, &e);
    return atomic_load_explicit(&e.nc, memory_order_relaxed);
}

int pk_dem_eval_threaded(pk_dem_pairs *c, const pk_dem_geom *g, const double *x, const double *r,
                         size_t np, double E, double *f, double *energy, double S[9], int keep,
                         size_t *nc)
{
    const int nparts = PARTS_PER_THREAD * pk_par_threads(c->par);
    if (!par_ready(c, np, g->dim, f, nparts)) /* writes every f entry */
        return 0;
    *nc = eval_par(c, g, x, r, E, f, energy, S, keep, nparts);
    return 1;
}
