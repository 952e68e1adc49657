/* dem_eval_loops.c — the contact loops: geometry, forces (4.8)–(4.10), energy
 * (4.7) and S per candidate, scalar and in AVX2 lanes; contract: dem_internal.h. */
#include "dem_internal.h"

#include <math.h>
#include <stdint.h>
#include <string.h>

/* Forces are scattered with the sum on i kept in registers while the pairs
 * of one i follow each other (the build lists them by i): the read-modify-
 * write chain through f[i] was the latency bound of the loop. */
#define FLUSH_I(dim_)                                                                              \
    do {                                                                                           \
        if (f && icur != SIZE_MAX)                                                                 \
            for (int a_ = 0; a_ < (dim_); a_++)                                                    \
                f[3 * icur + a_] += fi[a_];                                                        \
    } while (0)

/* The block geometry: l ([n][3]), |l| and ε of the candidates from p0 on,
 * candidate p at index p − p0 — the pair arrays of pk_dem_pairs from p0, or
 * buffers of one block (pk_dem_eval_forces). */
typedef struct geom_out {
    double *l, *len, *eps;
} geom_out;

/* The geometry of candidates [ps, pe) in 2D (l = x_j − x_i plus the pair's
 * lattice shift when periodic, then |l| and the overlap (4.1)) into o
 * (block from p0); the contacts (4.2; coincident centres carry no
 * direction) are listed in idx (when not NULL), in pair order.  Returns
 * their number.  per is a constant at each call, so the compiler drops the
 * branch. */
static inline size_t geom_2d_scalar(const pk_dem_pairs *c, const double *x, const double *r,
                                    size_t p0, size_t ps, size_t pe, geom_out o, int32_t *idx,
                                    const int per)
{
    const int32_t *pi = c->i, *pj = c->j;
    const double *sh = c->sh;
    size_t nc = 0;
    for (size_t p = ps; p < pe; p++) {
        size_t i = (size_t)pi[p], j = (size_t)pj[p], q = p - p0;
        double d0 = x[3 * j] - x[3 * i], d1 = x[3 * j + 1] - x[3 * i + 1];
        if (per)
            d0 += sh[3 * p], d1 += sh[3 * p + 1];
        o.l[3 * q] = d0, o.l[3 * q + 1] = d1, o.l[3 * q + 2] = 0;
        double len = sqrt(d0 * d0 + d1 * d1);
        double eps = r[i] + r[j] - len; /* (4.1) */
        o.len[q] = len;
        o.eps[q] = eps;
        if (idx && eps >= 0 && len > 0)
            idx[nc++] = (int32_t)p;
    }
    return nc;
}

int pk_dem_scalar_only = 0;

#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>
#define HAVE_GEOM_LANES4 1

/* geom_2d_scalar with four candidates per step (AVX2, chosen at run time),
 * which also gives the contacts' force factors t = E_n ε/|l| in tq (the one
 * division of (4.8), four at a time).  The pairs' x_j − x_i (+ shift) and r
 * are transposed to lanes (faster than vgatherdpd here), then every lane
 * does the scalar operations in their order — no FMA (-std=c17 contracts
 * nothing and the target has none) — so l, len, eps and the contact list
 * are bit-identical to the scalar loop (tests/unit/test_dem_lanes.c).
 * keep = 0 (block buffers, pk_dem_eval_forces): only l's two components
 * are stored for the lanes (the force pass reads nothing else of them). */
__attribute__((target("avx2"))) static size_t geom_2d_lanes4(const pk_dem_pairs *c, const double *x,
                                                             const double *r, double E, size_t p0,
                                                             size_t pe, geom_out o, int32_t *idx,
                                                             double *tq, const int per,
                                                             const int keep)
{
    const double *kf = c->kf, *sh = c->sh;
    const __m256d EV = _mm256_set1_pd(E);
    const __m256d ZERO = _mm256_setzero_pd();
    const int32_t *pi = c->i, *pj = c->j;
    size_t nc = 0, p = p0;
    for (; p + 4 <= pe; p += 4) {
        const size_t i0 = (size_t)pi[p], i1 = (size_t)pi[p + 1], i2 = (size_t)pi[p + 2],
                     i3 = (size_t)pi[p + 3];
        const size_t j0 = (size_t)pj[p], j1 = (size_t)pj[p + 1], j2 = (size_t)pj[p + 2],
                     j3 = (size_t)pj[p + 3];
        /* (x_j − x_i) (+ shift) of each pair in 128 bits, then transposed to lanes */
        __m128d e0 = _mm_sub_pd(_mm_loadu_pd(&x[3 * j0]), _mm_loadu_pd(&x[3 * i0]));
        __m128d e1 = _mm_sub_pd(_mm_loadu_pd(&x[3 * j1]), _mm_loadu_pd(&x[3 * i1]));
        __m128d e2 = _mm_sub_pd(_mm_loadu_pd(&x[3 * j2]), _mm_loadu_pd(&x[3 * i2]));
        __m128d e3 = _mm_sub_pd(_mm_loadu_pd(&x[3 * j3]), _mm_loadu_pd(&x[3 * i3]));
        if (per) {
            e0 = _mm_add_pd(e0, _mm_loadu_pd(&sh[3 * p]));
            e1 = _mm_add_pd(e1, _mm_loadu_pd(&sh[3 * p + 3]));
            e2 = _mm_add_pd(e2, _mm_loadu_pd(&sh[3 * p + 6]));
            e3 = _mm_add_pd(e3, _mm_loadu_pd(&sh[3 * p + 9]));
        }
        const __m256d e02 = _mm256_insertf128_pd(_mm256_castpd128_pd256(e0), e2, 1);
        const __m256d e13 = _mm256_insertf128_pd(_mm256_castpd128_pd256(e1), e3, 1);
        const __m256d d0 = _mm256_unpacklo_pd(e02, e13), d1 = _mm256_unpackhi_pd(e02, e13);
        /* l rows (d0 d1 0) of the four pairs */
        const __m256d lo = _mm256_unpacklo_pd(d0, d1), hi = _mm256_unpackhi_pd(d0, d1);
        double *lp = &o.l[3 * (p - p0)];
        _mm_storeu_pd(lp, _mm256_castpd256_pd128(lo));
        _mm_storeu_pd(lp + 3, _mm256_castpd256_pd128(hi));
        _mm_storeu_pd(lp + 6, _mm256_extractf128_pd(lo, 1));
        _mm_storeu_pd(lp + 9, _mm256_extractf128_pd(hi, 1));
        if (keep)
            lp[2] = lp[5] = lp[8] = lp[11] = 0;
        const __m256d len =
            _mm256_sqrt_pd(_mm256_add_pd(_mm256_mul_pd(d0, d0), _mm256_mul_pd(d1, d1)));
        const __m256d eps = _mm256_sub_pd(_mm256_add_pd(_mm256_setr_pd(r[i0], r[i1], r[i2], r[i3]),
                                                        _mm256_setr_pd(r[j0], r[j1], r[j2], r[j3])),
                                          len);
        if (keep) {
            _mm256_storeu_pd(&o.len[p - p0], len);
            _mm256_storeu_pd(&o.eps[p - p0], eps);
        }
        int m = _mm256_movemask_pd(_mm256_and_pd(_mm256_cmp_pd(eps, ZERO, _CMP_GE_OQ),
                                                 _mm256_cmp_pd(len, ZERO, _CMP_GT_OQ)));
        const __m256d k = kf ? _mm256_mul_pd(EV, _mm256_loadu_pd(&kf[p])) : EV;
        double t[4];
        _mm256_storeu_pd(t, _mm256_div_pd(_mm256_mul_pd(k, eps), len));
        for (; m; m &= m - 1) {
            const int l = __builtin_ctz((unsigned)m);
            idx[nc] = (int32_t)(p + (size_t)l);
            tq[nc++] = t[l];
        }
    }
    const size_t nl = nc;
    nc += geom_2d_scalar(c, x, r, p0, p, pe, o, idx + nc, per);
    for (size_t q = nl; q < nc; q++) {
        size_t b = (size_t)idx[q] - p0;
        tq[q] = (kf ? E * kf[idx[q]] : E) * o.eps[b] / o.len[b];
    }
    return nc;
}

static int geom_lanes4_ok(void) { return __builtin_cpu_supports("avx2") && !pk_dem_scalar_only; }
#endif

int pk_dem_lanes_available(void)
{
#ifdef HAVE_GEOM_LANES4
    return geom_lanes4_ok();
#else
    return 0;
#endif
}

/* Candidates are evaluated in blocks of this many: the geometry of the
 * block, then the forces of its contacts while l, len, eps are in L1. */
#define EVAL_BLOCK 512

/* pk_dem_eval for 2D: the same operations as the generic loop with the
 * vanishing third components dropped (x·0 terms), so the same numbers
 * (tests/unit/test_homog_newton.c) at a fraction of the cost — this loop is
 * most of the cost of a DR iteration.  The flags are constants at each call
 * (eval_2d and pk_dem_eval_part below, lanes = 1 when the AVX2 geometry is
 * in use), so the compiler drops the branches of what is not asked.
 * Two passes per block: the geometry of every candidate (a dependent chain
 * per pair: x_j − x_i + shift, √, overlap), then the forces of the contacts —
 * short loop bodies keep more pairs in flight; with the lanes the force pass
 * runs over their contact list (no unpredictable branch, t precomputed).
 * keep = 0 (pk_dem_eval_forces, with the lanes only): the geometry goes to
 * buffers of one block instead of c's pair arrays.  split = 1 (phase A of
 * the threaded evaluation, dem_eval_par.c): each candidate's force on i goes
 * to c->fa (+0 when open) instead of being scattered to f[j]. */
#if defined(__GNUC__)
__attribute__((always_inline)) /* one copy per call below: the flags constants */
#endif
static inline size_t
eval_2d_loop(pk_dem_pairs *c, const pk_dem_geom *g, const double *x, const double *r, double E,
             double *f, double *phi_out, double S[9], size_t pa, size_t pb, const int per,
             const int want_phi, const int want_S, const int lanes, const int keep, const int split)
{
    const double *kf = c->kf;
    const int32_t *pi = c->i, *pj = c->j;
    double *fa = c->fa;
    double phi = 0, fi0 = 0, fi1 = 0, S0 = 0, S1 = 0, S3 = 0, S4 = 0;
    size_t nc = 0, icur = SIZE_MAX;
    int32_t idx[EVAL_BLOCK];
    double tq[EVAL_BLOCK];
    double bl[3 * EVAL_BLOCK], blen[EVAL_BLOCK], beps[EVAL_BLOCK]; /* keep = 0: L1-resident */
    for (size_t p0 = pa; p0 < pb; p0 += EVAL_BLOCK) {
        size_t pe = pb - p0 < EVAL_BLOCK ? pb : p0 + EVAL_BLOCK, m = pe - p0;
        const geom_out o =
            keep ? (geom_out){&c->l[3 * p0], &c->len[p0], &c->eps[p0]} : (geom_out){bl, blen, beps};
#ifdef HAVE_GEOM_LANES4
        if (lanes)
            nc += m = geom_2d_lanes4(c, x, r, E, p0, pe, o, idx, tq, per, keep);
        else
#endif
            geom_2d_scalar(c, x, r, p0, p0, pe, o, NULL, per);
        if (split) /* the open candidates' fa */
            memset(&fa[2 * p0], 0, 2 * (pe - p0) * sizeof *fa);
        /* the lanes list the contacts; the scalar loop tests every candidate
         * (cheaper there than the indirection) */
        for (size_t q = 0; q < m; q++) {
            size_t p = lanes ? (size_t)idx[q] : p0 + q, b = p - p0;
            if (!lanes) {
                if (!(o.eps[b] >= 0) || !(o.len[b] > 0))
                    continue;
                nc++;
            }
            size_t i = (size_t)pi[p], j = (size_t)pj[p];
            double d0 = o.l[3 * b], d1 = o.l[3 * b + 1];
            double t = lanes ? tq[q] : (kf ? E * kf[p] : E) * o.eps[b] / o.len[b]; /* (4.8) */
            if (want_phi) {
                double k = kf ? E * kf[p] : E, eps = o.eps[b]; /* pk_dem_pair_E */
                phi += 0.5 * k * eps * eps;                    /* (4.3) */
            }
            double fa0 = -t * d0, fa1 = -t * d1;
            if (f) {
                if (i != icur) {
                    if (icur != SIZE_MAX)
                        f[3 * icur] += fi0, f[3 * icur + 1] += fi1;
                    icur = i, fi0 = fi1 = 0;
                }
                fi0 += fa0, fi1 += fa1;
                if (split) /* parallel phase A: j's share comes in phase B */
                    fa[2 * p] = fa0, fa[2 * p + 1] = fa1;
                else
                    f[3 * j] -= fa0, f[3 * j + 1] -= fa1;
            }
            if (want_S) {
                S0 += fa0 * d0, S1 += fa0 * d1;
                S3 += fa1 * d0, S4 += fa1 * d1;
            }
        }
    }
    if (f && icur != SIZE_MAX)
        f[3 * icur] += fi0, f[3 * icur + 1] += fi1;
    if (want_S)
        S[0] = S0, S[1] = S1, S[3] = S3, S[4] = S4;
    if (phi_out)
        *phi_out = phi;
    return nc;
}

/* keep = 0 only for the forces alone (no energy, no S): the lanes do not
 * store ε for the force pass. */
static size_t eval_2d(pk_dem_pairs *c, const pk_dem_geom *g, const double *x, const double *r,
                      double E, double *f, double *energy, double S[9], int keep)
{
#ifdef HAVE_GEOM_LANES4
    if (geom_lanes4_ok()) {
        if (!g->periodic)
            return eval_2d_loop(c, g, x, r, E, f, energy, S, 0, c->n, 0, 1, S != NULL, 1, 1, 0);
        if (S || energy)
            return eval_2d_loop(c, g, x, r, E, f, energy, S, 0, c->n, 1, 1, S != NULL, 1, 1, 0);
        if (!keep) /* the DR/FIRE iteration */
            return eval_2d_loop(c, g, x, r, E, f, NULL, NULL, 0, c->n, 1, 0, 0, 1, 0, 0);
        return eval_2d_loop(c, g, x, r, E, f, NULL, NULL, 0, c->n, 1, 0, 0, 1, 1, 0);
    }
#endif
    if (!g->periodic)
        return eval_2d_loop(c, g, x, r, E, f, energy, S, 0, c->n, 0, 1, S != NULL, 0, 1, 0);
    if (S || energy)
        return eval_2d_loop(c, g, x, r, E, f, energy, S, 0, c->n, 1, 1, S != NULL, 0, 1, 0);
    return eval_2d_loop(c, g, x, r, E, f, NULL, NULL, 0, c->n, 1, 0, 0, 0, 1, 0);
}

/* The geometry of candidate p (any dim) into c's pair arrays: the branch
 * vector with the pair's image, |l|, ε (4.1); 1 when in contact (4.2;
 * coincident centres carry no direction). */
static inline int geom_generic(pk_dem_pairs *c, const pk_dem_geom *g, const double *x,
                               const double *r, size_t p)
{
    size_t i = (size_t)c->i[p], j = (size_t)c->j[p];
    double *l = &c->l[3 * p];
    for (int k = 0; k < 3; k++)
        l[k] = x[3 * j + k] - x[3 * i + k] + (g->periodic ? c->sh[3 * p + k] : 0);
    double len = sqrt(l[0] * l[0] + l[1] * l[1] + l[2] * l[2]);
    double eps = r[i] + r[j] - len;
    c->len[p] = len;
    c->eps[p] = eps;
    return eps >= 0 && len > 0;
}

/* Phase A in 3D over candidates [pa, pb) (whole runs): the serial loop's
 * geometry, fa and the runs' sums added to f. */
static size_t pair_forces_3d(pk_dem_pairs *c, const pk_dem_geom *g, const double *x,
                             const double *r, double E, double *f, size_t pa, size_t pb)
{
    double fi[3] = {0, 0, 0};
    size_t nc = 0, icur = SIZE_MAX;
    for (size_t p = pa; p < pb; p++) {
        double *fa = &c->fa[3 * p];
        if (!geom_generic(c, g, x, r, p)) {
            fa[0] = fa[1] = fa[2] = 0;
            continue;
        }
        nc++;
        size_t i = (size_t)c->i[p];
        double t = pk_dem_pair_E(c, p, E) * c->eps[p] / c->len[p]; /* (4.8) */
        if (i != icur) {
            for (int a = 0; a < 3 && icur != SIZE_MAX; a++)
                f[3 * icur + a] += fi[a];
            icur = i, fi[0] = fi[1] = fi[2] = 0;
        }
        for (int a = 0; a < 3; a++) {
            fa[a] = -t * c->l[3 * p + a];
            fi[a] += fa[a];
        }
    }
    for (int a = 0; a < 3 && icur != SIZE_MAX; a++)
        f[3 * icur + a] += fi[a];
    return nc;
}

/* 2D: eval_2d; 3D: the generic loop (the same sums in the same order). */
size_t pk_dem_eval_serial(pk_dem_pairs *c, const pk_dem_geom *g, const double *x, const double *r,
                          double E, double *f, double *energy, double S[9], int keep)
{
    const int dim = g->dim;
    if (dim == 2)
        return eval_2d(c, g, x, r, E, f, energy, S, keep);
    double phi = 0, fi[3] = {0, 0, 0};
    size_t nc = 0, icur = SIZE_MAX;
    for (size_t p = 0; p < c->n; p++) {
        size_t i = (size_t)c->i[p], j = (size_t)c->j[p];
        if (!geom_generic(c, g, x, r, p))
            continue;
        const double *l = &c->l[3 * p];
        double len = c->len[p], eps = c->eps[p];
        nc++;
        double k = pk_dem_pair_E(c, p, E);
        phi += 0.5 * k * eps * eps; /* (4.3), each contact once (4.7) */
        double t = k * eps / len;   /* f_ij = −E ε n_ij = −t l on i (4.8) */
        if (i != icur) {
            FLUSH_I(dim);
            icur = i, fi[0] = fi[1] = fi[2] = 0;
        }
        for (int a = 0; a < dim; a++) {
            double fa = -t * l[a];
            fi[a] += fa;
            if (f)
                f[3 * j + a] -= fa;
            if (S)
                for (int b = 0; b < dim; b++)
                    S[3 * a + b] += fa * l[b];
        }
    }
    FLUSH_I(dim);
    if (energy)
        *energy = phi;
    return nc;
}
#undef FLUSH_I

size_t pk_dem_eval_part(pk_dem_pairs *c, const pk_dem_geom *g, const double *x, const double *r,
                        double E, double *f, size_t pa, size_t pb, int keep)
{
    if (g->dim != 2)
        return pair_forces_3d(c, g, x, r, E, f, pa, pb);
#ifdef HAVE_GEOM_LANES4
    if (geom_lanes4_ok()) {
        if (!g->periodic)
            return keep ? eval_2d_loop(c, g, x, r, E, f, NULL, NULL, pa, pb, 0, 0, 0, 1, 1, 1)
                        : eval_2d_loop(c, g, x, r, E, f, NULL, NULL, pa, pb, 0, 0, 0, 1, 0, 1);
        return keep ? eval_2d_loop(c, g, x, r, E, f, NULL, NULL, pa, pb, 1, 0, 0, 1, 1, 1)
                    : eval_2d_loop(c, g, x, r, E, f, NULL, NULL, pa, pb, 1, 0, 0, 1, 0, 1);
    }
#endif
    if (!g->periodic)
        return eval_2d_loop(c, g, x, r, E, f, NULL, NULL, pa, pb, 0, 0, 0, 0, 1, 1);
    return eval_2d_loop(c, g, x, r, E, f, NULL, NULL, pa, pb, 1, 0, 0, 0, 1, 1);
}
