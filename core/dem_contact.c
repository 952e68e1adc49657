#include "dem_contact.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "grid.h"
#include "homog_tensor.h"

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
                                  double S[9], const int per, const int want_phi, const int want_S,
                                  const int lanes, const int keep)
{
    const double *kf = c->kf;
    const int32_t *pi = c->i, *pj = c->j;
    double phi = 0, fi0 = 0, fi1 = 0, S0 = 0, S1 = 0, S3 = 0, S4 = 0;
    size_t nc = 0, icur = SIZE_MAX;
    int32_t idx[EVAL_BLOCK];
    double tq[EVAL_BLOCK];
    double bl[3 * EVAL_BLOCK], blen[EVAL_BLOCK], beps[EVAL_BLOCK]; /* keep = 0: L1-resident */
    for (size_t p0 = 0; p0 < c->n; p0 += EVAL_BLOCK) {
        size_t pe = c->n - p0 < EVAL_BLOCK ? c->n : p0 + EVAL_BLOCK, m = pe - p0;
        const geom_out o = keep ? (geom_out){&c->l[3 * p0], &c->len[p0], &c->eps[p0]}
                                : (geom_out){bl, blen, beps};
#ifdef HAVE_GEOM_LANES4
        if (lanes)
            nc += m = geom_2d_lanes4(c, x, r, E, p0, pe, o, idx, tq, per, keep);
        else
#endif
            geom_2d_scalar(c, x, r, p0, p0, pe, o, NULL, per);
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
            return eval_2d_loop(c, g, x, r, E, f, energy, S, 0, 1, S != NULL, 1, 1);
        if (S || energy)
            return eval_2d_loop(c, g, x, r, E, f, energy, S, 1, 1, S != NULL, 1, 1);
        if (!keep) /* the DR/FIRE iteration */
            return eval_2d_loop(c, g, x, r, E, f, NULL, NULL, 1, 0, 0, 1, 0);
        return eval_2d_loop(c, g, x, r, E, f, NULL, NULL, 1, 0, 0, 1, 1);
    }
#endif
    if (!g->periodic)
        return eval_2d_loop(c, g, x, r, E, f, energy, S, 0, 1, S != NULL, 0, 1);
    if (S || energy)
        return eval_2d_loop(c, g, x, r, E, f, energy, S, 1, 1, S != NULL, 0, 1);
    return eval_2d_loop(c, g, x, r, E, f, NULL, NULL, 1, 0, 0, 0, 1);
}

static size_t eval(pk_dem_pairs *c, const pk_dem_geom *g, const double *x, const double *r,
                   size_t np, double E, double *f, double *energy, double S[9], int keep)
{
    const int dim = g->dim;
    if (f)
        memset(f, 0, 3 * np * sizeof *f);
    if (S)
        memset(S, 0, 9 * sizeof *S);
    if (g->periodic && !shifts_match(c, g))
        pair_shifts(c, g, x); /* another F̄ (or L) than the list's images were formed under */
    if (dim == 2)
        return eval_2d(c, g, x, r, E, f, energy, S, keep || energy || S);
    double phi = 0, fi[3] = {0, 0, 0};
    size_t nc = 0, icur = SIZE_MAX;
    for (size_t p = 0; p < c->n; p++) {
        size_t i = (size_t)c->i[p], j = (size_t)c->j[p];
        double *l = &c->l[3 * p];
        for (int k = 0; k < 3; k++) /* the branch vector with the pair's image */
            l[k] = x[3 * j + k] - x[3 * i + k] + (g->periodic ? c->sh[3 * p + k] : 0);
        double len = sqrt(l[0] * l[0] + l[1] * l[1] + l[2] * l[2]);
        double eps = r[i] + r[j] - len; /* (4.1) */
        c->len[p] = len;
        c->eps[p] = eps;
        if (!(eps >= 0) || !(len > 0)) /* (4.2); coincident centres carry no direction */
            continue;
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
