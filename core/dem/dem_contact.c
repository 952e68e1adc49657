#include "dem_contact.h"

#include <math.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include "core/space/grid.h"
#include "core/homog/homog_tensor.h"

double pk_dem_geom_set_F(pk_dem_geom *g, const double F[9])
{
    double Fi[9];
    double d = pk_m3_inv(F, Fi);
    if (d == 0 || !isfinite(d))
        return 0;
    memcpy(g->F, F, sizeof g->F);
    memcpy(g->Finv, Fi, sizeof g->Finv);
    return d;
}

void pk_dem_pairs_free(pk_dem_pairs *c)
{
    free(c->i);
    free(c->j);
    free(c->l);
    free(c->len);
    free(c->eps);
    free(c->xb);
    free(c->kf);
    free(c->sh);
    free(c->fa);
    free(c->ord);
    free(c->bofs);
    free(c->jofs);
    free(c->jq);
    free(c->iofs);
    memset(c, 0, sizeof *c);
}

void pk_dem_pairs_stiffness(pk_dem_pairs *c, const int32_t *kclass, const double *kmat,
                            size_t nclass, double kref)
{
    c->kclass = kmat && nclass && kref > 0 ? kclass : NULL;
    c->kmat = kmat;
    c->nclass = nclass;
    c->kref = kref;
}

static int pairs_push(pk_dem_pairs *c, int32_t i, int32_t j)
{
    if (c->n == c->cap) {
        size_t cap = c->cap ? 2 * c->cap : 1024;
        int32_t *ni = realloc(c->i, cap * sizeof *ni);
        if (ni)
            c->i = ni;
        int32_t *nj = realloc(c->j, cap * sizeof *nj);
        if (nj)
            c->j = nj;
        double *nl = realloc(c->l, 3 * cap * sizeof *nl);
        if (nl)
            c->l = nl;
        double *nn = realloc(c->len, cap * sizeof *nn);
        if (nn)
            c->len = nn;
        double *ne = realloc(c->eps, cap * sizeof *ne);
        if (ne)
            c->eps = ne;
        double *nk = c->kclass ? realloc(c->kf, cap * sizeof *nk) : c->kf;
        if (nk)
            c->kf = nk;
        double *ns = realloc(c->sh, 3 * cap * sizeof *ns);
        if (ns)
            c->sh = ns;
        if (!ni || !nj || !nl || !nn || !ne || (c->kclass && !nk) || !ns)
            return -1;
        c->cap = cap;
    }
    c->i[c->n] = i;
    c->j[c->n] = j;
    if (c->kclass)
        c->kf[c->n] = c->kmat[(size_t)c->kclass[i] * c->nclass + (size_t)c->kclass[j]] / c->kref;
    c->n++;
    return 0;
}

/* Reference-frame difference s_j − s_i = F⁻¹(x_j − x_i), minimum image:
 * ds = s + t with the lattice vector t = −L∘k, k = round(s/L) (t = 0 on an
 * open box). */
static void ref_image(const pk_dem_geom *g, const double *xi, const double *xj, double ds[3],
                      double t[3])
{
    double d[3] = {xj[0] - xi[0], xj[1] - xi[1], g->dim == 3 ? xj[2] - xi[2] : 0};
    pk_m3_vec(g->Finv, d, ds);
    t[0] = t[1] = t[2] = 0;
    if (g->periodic)
        for (int k = 0; k < g->dim; k++) {
            t[k] = -g->L[k] * nearbyint(ds[k] / g->L[k]);
            ds[k] += t[k];
        }
    if (g->dim == 2)
        ds[2] = 0;
}

static void ref_diff(const pk_dem_geom *g, const double *xi, const double *xj, double ds[3])
{
    double t[3];
    ref_image(g, xi, xj, ds, t);
}

/* Candidate p's lattice shift in the current frame, sh = F̄ t (ref_image).
 * Measured and dropped (fifth session, round 12): a uint16 code per pair into
 * a table of the shifts for k in {-2..2}^dim formed once per F̄ (bit-identical,
 * −0 kept; a per-pair fallback beyond |k| = 2): 24 → 2 B per pair read per
 * evaluation, but +1.9 % instructions and no faster (seeds 6–8 of the cached
 * 10⁴ RVEs, alternating runs; a synthetic 10⁴-grain evaluation 3.21 →
 * 3.22–3.30 ns per pair — the shifts are read in order and prefetched). */
static void set_shift(pk_dem_pairs *c, const pk_dem_geom *g, size_t p, const double t[3])
{
    double *sh = &c->sh[3 * p];
    if (t[0] == 0 && t[1] == 0 && t[2] == 0) { /* most pairs: no boundary crossed */
        sh[0] = sh[1] = sh[2] = 0;
        return;
    }
    pk_m3_vec(g->F, t, sh);
    if (g->dim == 2)
        sh[2] = 0;
}

/* The geometry the shifts of c belong to. */
static void shifts_stamp(pk_dem_pairs *c, const pk_dem_geom *g)
{
    memcpy(c->sh_F, g->F, sizeof c->sh_F);
    memcpy(c->sh_L, g->L, sizeof c->sh_L);
    c->sh_dim = g->dim;
    c->sh_periodic = g->periodic;
    c->sh_ok = 1;
}

/* The lattice shift of every candidate at x under g, so that x_j − x_i + sh
 * is the branch vector (the build sets them as it lists the pairs). */
static void pair_shifts(pk_dem_pairs *c, const pk_dem_geom *g, const double *x)
{
    for (size_t p = 0; p < c->n; p++) {
        double ds[3], t[3];
        ref_image(g, &x[3 * (size_t)c->i[p]], &x[3 * (size_t)c->j[p]], ds, t);
        set_shift(c, g, p, t);
    }
    shifts_stamp(c, g);
}

/* The shifts in c belong to g? */
static int shifts_match(const pk_dem_pairs *c, const pk_dem_geom *g)
{
    return c->sh_ok && c->sh_dim == g->dim && c->sh_periodic == g->periodic &&
           memcmp(c->sh_F, g->F, sizeof c->sh_F) == 0 && memcmp(c->sh_L, g->L, sizeof c->sh_L) == 0;
}

typedef struct build_ctx {
    pk_dem_pairs *c;
    const pk_dem_geom *g;
    const double *x, *r;
    size_t i;
    double inv_smin, skin;
    int fail;
} build_ctx;

static int visit(size_t j, const double dx[PK_MAXDIM], double dist2, void *vctx)
{
    (void)dx;
    (void)dist2;
    build_ctx *b = vctx;
    if (j <= b->i)
        return 0;
    double ds[3], t[3];
    ref_image(b->g, &b->x[3 * b->i], &b->x[3 * j], ds, t);
    double lim = (b->r[b->i] + b->r[j] + b->skin) * b->inv_smin;
    if (!(ds[0] * ds[0] + ds[1] * ds[1] + ds[2] * ds[2] < lim * lim))
        return 0;
    if (pairs_push(b->c, (int32_t)b->i, (int32_t)j) != 0) {
        b->fail = 1;
        return 1;
    }
    set_shift(b->c, b->g, b->c->n - 1, t);
    return 0;
}

int pk_dem_pairs_build(pk_dem_pairs *c, const pk_dem_geom *g, const double *x, const double *r,
                       size_t np, double skin)
{
    const int dim = g->dim;
    c->n = 0;
    c->skin = skin;
    c->sh_ok = 0;
    c->csr_state = 0;
    if (c->kclass && !c->kf && c->cap) { /* classes set after an earlier build */
        c->kf = malloc(c->cap * sizeof *c->kf);
        if (!c->kf)
            return -1;
    }
    if (c->np != np || !c->xb) {
        free(c->xb);
        c->xb = malloc(3 * (np ? np : 1) * sizeof *c->xb);
        if (!c->xb)
            return -1;
        c->np = np;
    }
    memcpy(c->xb, x, 3 * np * sizeof *x);
    if (np < 2)
        return 0;
    double rmin = INFINITY, rmax = 0;
    for (size_t i = 0; i < np; i++) {
        rmin = fmin(rmin, r[i]);
        rmax = fmax(rmax, r[i]);
    }
    /* |F ds| >= σ_min |ds|: a contact needs |ds| < (R + skin)/σ_min (σ_min >= 1 is
     * not used to shrink the search: factor 1 then) */
    double smin = pk_m3_sigma_min(g->F, dim);
    if (!(smin > 0))
        return -2;
    double inv_smin = fmax(1.0, 1.0 / smin);
    double reach_max = (2 * rmax + skin) * inv_smin;
    pk_box box = {.dim = dim};
    double off[3] = {0, 0, 0};
    if (g->periodic) {
        for (int k = 0; k < dim; k++) {
            if (!(2 * reach_max < g->L[k]))
                return -2;
            box.L[k] = g->L[k];
            box.periodic[k] = true;
        }
    } else {
        double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        for (size_t i = 0; i < np; i++) {
            double s[3];
            pk_m3_vec(g->Finv, &x[3 * i], s);
            for (int k = 0; k < dim; k++) {
                lo[k] = fmin(lo[k], s[k]);
                hi[k] = fmax(hi[k], s[k]);
            }
        }
        for (int k = 0; k < dim; k++) {
            off[k] = reach_max - lo[k];
            box.L[k] = hi[k] - lo[k] + 2 * reach_max;
        }
    }
    pk_particles ref;
    if (pk_particles_init(&ref, dim, np) != 0)
        return -1;
    for (size_t i = 0; i < np; i++) {
        double s[3];
        pk_m3_vec(g->Finv, &x[3 * i], s);
        for (int k = 0; k < 3; k++)
            s[k] = k < dim ? s[k] + off[k] : 0;
        pk_box_wrap(&box, s);
        pk_particles_push(&ref, s, r[i], 0);
    }
    pk_grid grid;
    if (pk_grid_init(&grid, &box, rmin, rmax, 0, np) != 0) {
        pk_particles_free(&ref);
        return -1;
    }
    int rc = 0;
    for (size_t i = 0; i < np && rc == 0; i++)
        if (pk_grid_insert(&grid, &ref, i) != 0)
            rc = -1;
    build_ctx b = {.c = c, .g = g, .x = x, .r = r, .inv_smin = inv_smin, .skin = skin};
    /* grid contact distance is r_i + r_j + extra in reference units */
    for (size_t i = 0; i < np && rc == 0; i++) {
        b.i = i;
        double extra = (r[i] + rmax + skin) * inv_smin - r[i] - rmax;
        pk_grid_query(&grid, &ref, &ref.x[3 * i], r[i], extra, visit, &b);
        if (b.fail)
            rc = -1;
    }
    pk_grid_free(&grid);
    pk_particles_free(&ref);
    /* Measured (round 8): the images fixed here instead of F̄⁻¹, rounding and
     * F̄ per pair in every evaluation: the DR evaluation 5.5–6.0 → 4.8–5.2 ns
     * per candidate (bench near-jamming 10⁴, seeds 5–9), for +3 % of the
     * build's instructions (set in visit; a pass of its own was +16 %).
     * Dropped: the shifts stored with stride 2 in 2D (no difference
     * measurable), and the lanes listing each contact's i, j and force for a
     * force pass that reads them in sequence (same instructions, 4.5 → 5.0
     * ns per candidate).
     * Dropped (round 9): each grain's candidates sorted by j, so that every
     * sum over the list is the same for any list holding the same contacts
     * (the rebuilds' positions and the neighbour structure's visit order then
     * no longer touch the results — fewer or cheaper rebuilds free).  The
     * reorder itself moves the rounding, and near jamming that moves the
     * plastic events: near-jamming 10⁴ steps, seeds 5–9, CPU s 1.43/2.57/
     * 2.41/2.06/0.83 → 1.36/2.66/3.80/1.87/0.71, seeds 6 and 7 in other
     * minima (ΔΦ/Φ +6.7e-4, −7.8e-6).
     * A candidate's image stays its minimum image until the next build: the
     * box check above gives L_k > 2(2 r_max + skin)/σ_min(F̄); a pair in
     * contact at some later x (grains moved < skin/2 each, so |Δl| < skin)
     * is within (R + 2 skin)/σ_min of its build image in the reference frame
     * and any other image is more than L_k − R/σ_min >= (2 r_max + 2 skin)/σ_min
     * away — the contacts and their l are those of the per-pair minimum image
     * (non-contacts may keep a farther image: still no contact). */
    if (rc == 0)
        shifts_stamp(c, g);
    return rc;
}

/* The skin test with dim a constant (2 or 3): the axis loop unrolled. */
static inline int stale_loop(const pk_dem_pairs *c, const double *x, const int dim)
{
    double lim2 = 0.25 * c->skin * c->skin;
    for (size_t i = 0; i < c->np; i++) {
        double s = 0;
        for (int k = 0; k < dim; k++) {
            double d = x[3 * i + k] - c->xb[3 * i + k];
            s += d * d;
        }
        if (s > lim2)
            return 1;
    }
    return 0;
}

int pk_dem_pairs_stale(const pk_dem_pairs *c, const double *x, int dim)
{
    return dim == 2 ? stale_loop(c, x, 2) : stale_loop(c, x, dim);
}

void pk_dem_branch(const pk_dem_geom *g, const double *xi, const double *xj, double l[3])
{
    if (g->periodic) {
        double ds[3];
        ref_diff(g, xi, xj, ds);
        pk_m3_vec(g->F, ds, l);
    } else {
        for (int k = 0; k < 3; k++)
            l[k] = xj[k] - xi[k];
    }
    if (g->dim == 2)
        l[2] = 0;
}

/* Forces are scattered with the sum on i kept in registers while the pairs
 * of one i follow each other (the build lists them by i): the read-modify-
 * write chain through f[i] was the latency bound of the loop. */
#define FLUSH_I(dim_)                                                                          \
    do {                                                                                       \
        if (f && icur != SIZE_MAX)                                                             \
            for (int a_ = 0; a_ < (dim_); a_++)                                                \
                f[3 * icur + a_] += fi[a_];                                                    \
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
__attribute__((target("avx2"))) static size_t geom_2d_lanes4(const pk_dem_pairs *c,
                                                             const double *x, const double *r,
                                                             double E, size_t p0, size_t pe,
                                                             geom_out o, int32_t *idx, double *tq,
                                                             const int per, const int keep)
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
        const __m256d eps = _mm256_sub_pd(
            _mm256_add_pd(_mm256_setr_pd(r[i0], r[i1], r[i2], r[i3]),
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

static int geom_lanes4_ok(void)
{
    return __builtin_cpu_supports("avx2") && !pk_dem_scalar_only;
}
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
 * (eval_2d below, lanes = 1 when the AVX2 geometry is in use), so the
 * compiler drops the branches of what is not asked.
 * Two passes per block: the geometry of every candidate (a dependent chain
 * per pair: x_j − x_i + shift, √, overlap), then the forces of the contacts —
 * short loop bodies keep more pairs in flight; with the lanes the force pass
 * runs over their contact list (no unpredictable branch, t precomputed).
 * keep = 0 (pk_dem_eval_forces, with the lanes only): the geometry goes to
 * buffers of one block instead of c's pair arrays.
 * Measured (round 11, callgrind, near-jamming 10⁴ step, seed 7): GCC had
 * made ONE clone of this loop for all the calls below, every flag tested
 * per contact at run time; inlined per call (always_inline) the evaluations
 * take 14.6 → 12.6·10⁹ instructions with the forces-only path (eval_2d_loop
 * alone 8.5 → 6.1·10⁹; the block buffers without the inlining had cost
 * +0.5·10⁹ for the indexing from p0). */
#if defined(__GNUC__)
__attribute__((always_inline)) /* one copy per call below: the flags constants */
#endif
static inline size_t eval_2d_loop(pk_dem_pairs *c, const pk_dem_geom *g, const double *x,
                                  const double *r, double E, double *f, double *phi_out,
                                  double S[9], size_t pa, size_t pb, const int per,
                                  const int want_phi, const int want_S, const int lanes,
                                  const int keep, const int split)
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
        const geom_out o = keep ? (geom_out){&c->l[3 * p0], &c->len[p0], &c->eps[p0]}
                                : (geom_out){bl, blen, beps};
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
                phi += 0.5 * k * eps * eps;                   /* (4.3) */
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

/* ---- The parallel evaluation (c->par) ----
 * It reproduces the serial loops' sums operation for operation.  Serially,
 * f is zeroed; the candidates come sorted by i, one run per i, j > i
 * (pk_dem_pairs_build lists them grain by grain; csr_build checks it); each
 * contact does f[j] −= fa in pair order, and i's run sums its fa from 0 in
 * fi, added to f[i] when i changes.  So f_k = J_k + I_k with
 * J_k = ((0 − a₁) − a₂)… over the contacts with j = k (they have i < k: all
 * before k's run) and I_k = ((0 + b₁) + b₂)… over k's run (0 + I_k or J_k
 * alone when one side is empty; I_k is never −0, a sum from +0).
 * Phase A, candidate ranges cut at run boundaries, in parallel: the serial
 * loop itself (eval_2d_loop with split = 1: the lanes, the L1 buffers, the
 * runs' sums added to the zeroed f as serially) stores fa of each candidate
 * (+0 when open) instead of scattering it to f[j].  Phase B, grain ranges
 * in parallel: f_k = J_k + f_k, J_k over the candidates with j = k in pair
 * order; an open candidate's +0 changes no bit of J (v − (+0) = v for
 * v ≠ −0, NaN included, and J is never −0), and grains without such
 * candidates are already final (0 + I_k).  Phase B's part P takes phase
 * A's grains of part P sorted by their count of j-candidates (ord): the
 * inner loop's trip count is the same for long stretches (predicted) and
 * the grains' chains independent.  The energy and S are chains over pair
 * order: one part walks them after phase A, in the serial order.  Both
 * phases are one job of the pool (job_forces).
 * Measured and dropped (10⁴ random grains, 22 000 candidates, one thread):
 * phase B in grain order with two loops per grain (its j-candidates, its
 * run): ~19 000 branch mispredictions per evaluation (trip counts 0–6),
 * 1.7x the serial time; in grain order as one flat loop, the chain reset at
 * each grain by a bit mask: no mispredictions, but one dependent chain
 * through all grains (latency-bound), 1.45x. */
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
    int32_t *cnt = calloc(2 * np + 1, sizeof *cnt), *at = cnt + np; /* per grain */
    if (!c->bofs || !cnt) {
        free(cnt);
        return;
    }
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

#if defined(__GNUC__)
#define PREFETCH(a) __builtin_prefetch(a)
#else
#define PREFETCH(a) ((void)0)
#endif

/* Phase B over ord[ma, mb): f_k = J_k + f_k.  The gathers (fa of random
 * candidates, f of random grains, half of them last written by the other
 * thread) are prefetched ahead (16 grains, 32 candidates; 8 and 16 were
 * 3 % slower): measured 10⁴ random grains, 2 threads, phase B 22 → 17 µs
 * per evaluation.  Measured and dropped: each part's
 * candidates with j in it listed in pair order, J summed in a part-local
 * block while fa is read with rising addresses: 10 % slower in all (both
 * builds in one process, 6 runs of 12 alternating rounds: 2.8–3.4 against
 * 3.1–3.8 ns per candidate, serial 3.9–4.1). */
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

/* Parts per thread of phase A (and as many of phase B), claimed as the
 * threads come free: the parts' costs differ (a grain's run holds its
 * neighbours j > i, so low grain numbers have the longer runs, and locality
 * differs) and so do the threads' speeds on a shared machine.  Measured
 * (10⁴ random grains, 2 threads; one part per thread: phase A's halves took
 * 50 and 35 µs one after the other): builds side by side in one process,
 * 4 runs of 12 alternating rounds, 2/4/8/16 parts per thread 2.65–2.69/
 * 2.65–2.69/2.77–2.97/2.85–2.90 ns per candidate (serial 3.9–4.1). */
#define PARTS_PER_THREAD 4
#define MAX_PARTS (PARTS_PER_THREAD * PK_PAR_MAX)

typedef struct par_job {
    pk_dem_pairs *c;
    const pk_dem_geom *g;
    const double *x, *r;
    double E;
    double *f, *energy, *S;
    int mode;                 /* phase A variant: 0–3 lanes (2·per + keep), 4–5 scalar 2D
                                 (4 + per), 6 3D */
    int nparts, chains;       /* parts of each phase; 1: walk the energy/S chains */
    atomic_size_t nc;         /* contacts */
    atomic_int next;          /* phase A's next part to claim */
    atomic_int chain_taken;
    atomic_int done[MAX_PARTS]; /* phase A's parts finished */
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
    size_t pa = (size_t)c->iofs[ka], pb = (size_t)c->iofs[kb], nc = 0;
    memset(&f[3 * ka], 0, 3 * (kb - ka) * sizeof *f);
    switch (e->mode) {
#ifdef HAVE_GEOM_LANES4
    case 0: nc = eval_2d_loop(c, g, x, r, E, f, NULL, NULL, pa, pb, 0, 0, 0, 1, 0, 1); break;
    case 1: nc = eval_2d_loop(c, g, x, r, E, f, NULL, NULL, pa, pb, 0, 0, 0, 1, 1, 1); break;
    case 2: nc = eval_2d_loop(c, g, x, r, E, f, NULL, NULL, pa, pb, 1, 0, 0, 1, 0, 1); break;
    case 3: nc = eval_2d_loop(c, g, x, r, E, f, NULL, NULL, pa, pb, 1, 0, 0, 1, 1, 1); break;
#endif
    case 4: nc = eval_2d_loop(c, g, x, r, E, f, NULL, NULL, pa, pb, 0, 0, 0, 0, 1, 1); break;
    case 5: nc = eval_2d_loop(c, g, x, r, E, f, NULL, NULL, pa, pb, 1, 0, 0, 0, 1, 1); break;
    default: nc = pair_forces_3d(c, g, x, r, E, f, pa, pb); break;
    }
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
 * Measured (10⁴ random grains, 2 threads, builds side by side in one
 * process, best of 12 alternating rounds): phases as two jobs against one,
 * no worse, one hand-over less; phase B's parts claimed in order against
 * own-first 2.60–3.29 against 2.50–3.26 ns per candidate in 7 runs (never
 * slower; serial 3.9–4.1); phase B's parts fixed to the thread that ran
 * phase A's (no stealing), 2.49 when both cores are free but 3.6–4.0 when
 * one is shared (claims: 3.2).  With a CPU hog beside (3 runnable threads
 * on 2 cores) 2.7–5.0 against serial 4.0–4.2: the evaluation then waits for
 * descheduled threads — give the job its cores. */
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
    int lanes = 0;
#ifdef HAVE_GEOM_LANES4
    lanes = g->dim == 2 && geom_lanes4_ok();
#endif
    e.mode = g->dim != 2 ? 6 : lanes ? 2 * (g->periodic != 0) + (keep != 0)
                                    : 4 + (g->periodic != 0);
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

static size_t eval(pk_dem_pairs *c, const pk_dem_geom *g, const double *x, const double *r,
                   size_t np, double E, double *f, double *energy, double S[9], int keep)
{
    const int dim = g->dim;
    if (S)
        memset(S, 0, 9 * sizeof *S);
    if (g->periodic && !shifts_match(c, g))
        pair_shifts(c, g, x); /* another F̄ (or L) than the list's images were formed under */
    const int nparts = PARTS_PER_THREAD * pk_par_threads(c->par);
    if (par_ready(c, np, dim, f, nparts)) /* writes every f entry */
        return eval_par(c, g, x, r, E, f, energy, S, keep || energy || S, nparts);
    if (f)
        memset(f, 0, 3 * np * sizeof *f);
    if (dim == 2)
        return eval_2d(c, g, x, r, E, f, energy, S, keep || energy || S);
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

size_t pk_dem_eval(pk_dem_pairs *c, const pk_dem_geom *g, const double *x, const double *r,
                   size_t np, double E, double *f, double *energy, double S[9])
{
    return eval(c, g, x, r, np, E, f, energy, S, 1);
}

int pk_dem_forces_store = 0;

size_t pk_dem_eval_forces(pk_dem_pairs *c, const pk_dem_geom *g, const double *x, const double *r,
                          size_t np, double E, double *f)
{
    return eval(c, g, x, r, np, E, f, NULL, NULL, pk_dem_forces_store);
}

/* k_ij·d with k_ij = E/|l| [ε 1 − R n⊗n] (4.12)₁ (pk_dem_kblock_coef) */
static inline void kblock_apply(int dim, double E, double len, double eps, const double *l,
                                const double *d, double *out)
{
    double a, b, ld = 0;
    pk_dem_kblock_coef(E, len, eps, &a, &b);
    for (int k = 0; k < dim; k++)
        ld += l[k] * d[k];
    for (int k = 0; k < dim; k++)
        out[k] = a * d[k] - b * ld * l[k];
}

/* The K·v loop; pk_dem_kv calls it with dim a constant (2 or 3), so the
 * compiler unrolls the axis loops — the same operations in the same order,
 * at fewer instructions (it runs 40 times per DR estimate refresh). */
static inline void kv_loop(const pk_dem_pairs *c, const int dim, double E, const uint8_t *mask,
                           const double *v, double *out)
{
    for (size_t p = 0; p < c->n; p++) {
        if (!(c->eps[p] >= 0) || !(c->len[p] > 0))
            continue;
        size_t i = (size_t)c->i[p], j = (size_t)c->j[p];
        int mi = mask[i] != 0, mj = mask[j] != 0;
        if (!mi && !mj)
            continue;
        double d[3] = {0, 0, 0}, kd[3];
        for (int a = 0; a < dim; a++)
            d[a] = (mj ? v[3 * j + a] : 0) - (mi ? v[3 * i + a] : 0);
        /* (K v)_i = Σ_j k_ij (v_j − v_i) by (4.14) */
        kblock_apply(dim, pk_dem_pair_E(c, p, E), c->len[p], c->eps[p], &c->l[3 * p], d, kd);
        for (int a = 0; a < dim; a++) {
            if (mi)
                out[3 * i + a] += kd[a];
            if (mj)
                out[3 * j + a] -= kd[a];
        }
    }
}

void pk_dem_kv(const pk_dem_pairs *c, int dim, size_t np, double E, const uint8_t *mask,
               const double *v, double *out)
{
    memset(out, 0, 3 * np * sizeof *out);
    if (dim == 2)
        kv_loop(c, 2, E, mask, v, out);
    else
        kv_loop(c, dim, E, mask, v, out);
}

double pk_dem_gershgorin(const pk_dem_pairs *c, int dim, size_t np, double E, const uint8_t *mask)
{
    double *row = calloc(3 * (np ? np : 1), sizeof *row);
    if (!row)
        return INFINITY;
    for (size_t p = 0; p < c->n; p++) {
        if (!(c->eps[p] >= 0) || !(c->len[p] > 0))
            continue;
        size_t i = (size_t)c->i[p], j = (size_t)c->j[p];
        const double *l = &c->l[3 * p];
        double len = c->len[p], eps = c->eps[p], R = eps + len;
        double cc = pk_dem_pair_E(c, p, E) / len;
        for (int a = 0; a < dim; a++) {
            double s = 0; /* Σ_b |k_ab| */
            for (int b = 0; b < dim; b++)
                s += fabs(cc * ((a == b ? eps : 0) - R * l[a] * l[b] / (len * len)));
            /* the block enters the diagonal of both and the off-diagonal once */
            if (mask[i])
                row[3 * i + a] += s * (mask[j] ? 2 : 1);
            if (mask[j])
                row[3 * j + a] += s * (mask[i] ? 2 : 1);
        }
    }
    double m = 0;
    for (size_t k = 0; k < 3 * np; k++)
        m = fmax(m, row[k]);
    free(row);
    return m;
}
