/* edmd_predict.c — event times: pair collisions (Titscher & Unger Eqs. 21–22, cancellation-free
 * roots), walls (§3.3b), leaving the neighbour-list bounding sphere (§3.3c).
 * Contract: core/edmd/edmd.h (pk_edmd_pair_time, pk_edmd_exit_time) and the
 * edmd_predict declarations in core/edmd/edmd_state.h. */
#include <math.h>

#include "edmd_state.h"

/* Root of A τ² − 2(−B) τ + C = 0 for the quadratic of pk_edmd_pair_time.
 * bound: the caller only wants roots below it; pairs that provably collide
 * no earlier are dismissed (INFINITY) without the sqrt and the division —
 * for A >= 0, B < 0 the root C/(−B + √D) >= C/(−2B) as √D <= −B. */
static inline double pair_root(double A, double B, double C, double bound)
{
    if (C > 0) {
        if (A < 0) { /* growth outruns the relative speed: one positive root */
            double sq = sqrt(B * B - A * C);
            return B < 0 ? C / (-B + sq) : (B + sq) / -A;
        }
        if (B >= 0 || C >= -2 * B * bound)
            return INFINITY;
        double D = B * B - A * C;
        if (D < 0)
            return INFINITY;
        return C / (-B + sqrt(D)); /* also A = 0: −C/(2B) */
    }
    /* touching or overlapping by round-off */
    if (B < 0)
        return 0; /* gap shrinking: collide now */
    if (A < 0) {
        const double D = B * B - A * C;
        return (B + sqrt(D > 0 ? D : 0)) / -A;
    }
    return INFINITY;
}

double pk_edmd_pair_time(const double dp[3], const double dv[3], double R, double G, int *overlap)
{
    double A = dv[0] * dv[0] + dv[1] * dv[1] + dv[2] * dv[2] - G * G;
    double B = dp[0] * dv[0] + dp[1] * dv[1] + dp[2] * dv[2] - R * G;
    double C = dp[0] * dp[0] + dp[1] * dp[1] + dp[2] * dp[2] - R * R;
    if (overlap)
        *overlap = C < -1e-9 * R * R;
    return pair_root(A, B, C, INFINITY);
}

double pk_edmd_exit_time(const double q[3], const double v[3], double rho0, double g, double sigma)
{
    double S0 = sigma - rho0;
    double A = v[0] * v[0] + v[1] * v[1] + v[2] * v[2] - g * g;
    double B = q[0] * v[0] + q[1] * v[1] + q[2] * v[2] + S0 * g;
    double C = q[0] * q[0] + q[1] * q[1] + q[2] * q[2] - S0 * S0;
    if (!(S0 > 0) || C >= 0)
        return 0;
    const double D = B * B - A * C; /* >= 0 inside (C < 0, A >= 0); round-off aside */
    double sq = sqrt(D > 0 ? D : 0);
    if (B >= 0)
        return C / -(B + sq); /* C < 0: positive, no cancellation (+inf at rest, g = 0) */
    if (A > 0)
        return (-B + sq) / A;
    return 0; /* B < 0 with A <= 0 is impossible inside; rebuild now */
}

/* Earliest wall contact of i from now; code = 2k + side. */
double edmd_wall_time(const edmd_state *s, size_t i, int *code)
{
    double best = INFINITY, x[3];
    edmd_pos(s, i, x);
    const double rho = edmd_rho(s, i, s->t), g = s->k[i].g;
    for (int k = 0; k < s->dim; k++) {
        if (s->box.periodic[k])
            continue;
        double vk = s->k[i].v[k];
        double lo_rate = vk - g, hi_rate = -vk - g; /* gap rates */
        if (lo_rate < 0) {
            double tau = fmax(x[k] - rho, 0) / -lo_rate;
            if (tau < best) {
                best = tau;
                *code = 2 * k;
            }
        }
        if (hi_rate < 0) {
            double tau = fmax(s->box.L[k] - x[k] - rho, 0) / -hi_rate;
            if (tau < best) {
                best = tau;
                *code = 2 * k + 1;
            }
        }
    }
    return best;
}

/* Prefetch distance in a neighbour list: the grains' records are scattered
 * (mono 3D N = 4000 to jamming: about −10 % run time; docs/perf/edmd.md). */
#define PREFETCH_AHEAD 4

/* edmd_prefetch_list: lists up to this long whole; longer lists (coarse
 * grains) their first PREFETCH_AHEAD records, the loop's own prefetch
 * covers the rest. */
#define PREFETCH_LIST_MAX 16

/* The earliest two candidates (first, runner-up) of a prediction. */
typedef struct pred {
    double best, second;
    int32_t with, with2;
    uint32_t stamp, stamp2;
} pred;

static inline void offer(pred *pr, double tau, int32_t with, uint32_t stamp)
{
    if (tau < pr->best) {
        pr->second = pr->best;
        pr->with2 = pr->with;
        pr->stamp2 = pr->stamp;
        pr->best = tau;
        pr->with = with;
        pr->stamp = stamp;
    } else if (tau < pr->second) {
        pr->second = tau;
        pr->with2 = with;
        pr->stamp2 = stamp;
    }
}

/* One neighbour j: quadratic A τ² + 2B τ + C (dd = |Δx|², R = ρ_i + ρ_j). */
static inline void pair_take(edmd_state *s, pred *pr, size_t j, double A, double B, double C,
                             double R, double dd)
{
    if (C < -1e-9 * R * R) { /* overlap by more than round-off: record it */
        double rel = (R - sqrt(dd)) / R;
        s->n_overlap++;
        if (rel > s->max_overlap_rel)
            s->max_overlap_rel = rel;
    }
    double tau = pair_root(A, B, C, pr->second);
    if (tau < pr->second)
        offer(pr, tau, (int32_t)j, s->ncoll[j]);
}

/* What every neighbour of i is compared with (p/v carry 0 beyond dim in 2D,
 * so all three components are computed; minimum image as pk_min_image3). */
typedef struct self {
    double t, r, g;
    double x[3], v[3], L[3], iL[3];
} self;

#define MIN_IMAGE_M 6755399441055744.0

/* Neighbour j, scalar. */
static inline void pair_one(edmd_state *s, pred *pr, const self *c, size_t j)
{
    const edmd_kin *kj = &s->k[j];
    const double t = c->t, M = MIN_IMAGE_M;
    double d0 = c->x[0] - (kj->p[0] + kj->v[0] * t), d1 = c->x[1] - (kj->p[1] + kj->v[1] * t),
           d2 = c->x[2] - (kj->p[2] + kj->v[2] * t);
    d0 -= c->L[0] * ((d0 * c->iL[0] + M) - M);
    d1 -= c->L[1] * ((d1 * c->iL[1] + M) - M);
    d2 -= c->L[2] * ((d2 * c->iL[2] + M) - M);
    const double dv0 = c->v[0] - kj->v[0], dv1 = c->v[1] - kj->v[1], dv2 = c->v[2] - kj->v[2];
    const double R = c->r + kj->a + kj->g * t, G = c->g + kj->g;
    const double B = d0 * dv0 + d1 * dv1 + d2 * dv2 - R * G;
    const double dd = d0 * d0 + d1 * d1 + d2 * d2;
    const double A = dv0 * dv0 + dv1 * dv1 + dv2 * dv2 - G * G;
    pair_take(s, pr, j, A, B, dd - R * R, R, dd);
}

#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>

/* pair_one's arithmetic on lanes of a GCC vector type VT, in pair_one's
 * operation order (so every path gives bit-identical results), from the
 * neighbours' columns p0..p2, v0..v2, ra, rg and the grain's broadcast terms
 * (X, V, L, I, RI, GI, T, VM) to R, B, dd, C, A and the discriminant D.
 * One text for the 4- and 8-lane loops. */
#define LANE_TERMS(VT)                                                                             \
    VT d0 = X0 - (p0 + v0 * T), d1 = X1 - (p1 + v1 * T), d2 = X2 - (p2 + v2 * T);                  \
    d0 -= L0 * ((d0 * I0 + VM) - VM);                                                              \
    d1 -= L1 * ((d1 * I1 + VM) - VM);                                                              \
    d2 -= L2 * ((d2 * I2 + VM) - VM);                                                              \
    const VT dv0 = V0 - v0, dv1 = V1 - v1, dv2 = V2 - v2;                                          \
    const VT R = RI + ra + rg * T, G = GI + rg;                                                    \
    const VT B = d0 * dv0 + d1 * dv1 + d2 * dv2 - R * G;                                           \
    const VT dd = d0 * d0 + d1 * d1 + d2 * d2;                                                     \
    const VT C = dd - R * R;                                                                       \
    const VT A = dv0 * dv0 + dv1 * dv1 + dv2 * dv2 - G * G;                                        \
    const VT D = B * B - A * C

/* The lanes in `lanes` that the vector tests did not dismiss, in ascending
 * lane (= list) order so that ties resolve as in the scalar loop: a common
 * root (a lane in `hit`) is offered when it lies before the current
 * runner-up, any other lane goes to pair_take.  The vectors are read as
 * arrays of doubles. */
static inline void lane_offers(edmd_state *s, pred *pr, const int32_t *ix, unsigned lanes,
                               unsigned hit, const double *tau, const double *A, const double *B,
                               const double *C, const double *R, const double *dd)
{
    for (unsigned m = lanes; m; m &= m - 1) {
        const int l = __builtin_ctz(m);
        if (hit >> l & 1) {
            if (tau[l] < pr->second)
                offer(pr, tau[l], ix[l], s->ncoll[ix[l]]);
        } else {
            pair_take(s, pr, (size_t)ix[l], A[l], B[l], C[l], R[l], dd[l]);
        }
    }
}
#define HAVE_LANES4 1

/* Four neighbours at once (AVX2, chosen at run time): each grain's record
 * is one 64-byte line (p, a | v, g), so two aligned loads per neighbour and
 * a 4×4 transpose give the lanes.  Every lane does pair_one's operations in
 * its order (no FMA: -std=c17 contracts nothing, and the target has none),
 * so the results are bit-identical to the scalar code.  The common root (gap
 * open, approaching, A >= 0: C/(−B + √D), as pair_root) is taken in the
 * lanes; touching, overlapping or A < 0 lanes go to pair_take.  A short last
 * group repeats its first neighbour in the empty lanes and masks them
 * (lanes passed on, per run: docs/perf/edmd.md). */
__attribute__((target("avx2"))) static void pair_lanes4(edmd_state *s, pred *pr, const self *c,
                                                        const int32_t *nb, uint32_t nq)
{
    typedef double v4d __attribute__((vector_size(32)));
    typedef long long v4m __attribute__((vector_size(32)));
    const edmd_kin *K = s->k;
    const v4d T = _mm256_set1_pd(c->t), VM = _mm256_set1_pd(MIN_IMAGE_M);
    const v4d RI = _mm256_set1_pd(c->r), GI = _mm256_set1_pd(c->g);
    const v4d X0 = _mm256_set1_pd(c->x[0]), X1 = _mm256_set1_pd(c->x[1]),
              X2 = _mm256_set1_pd(c->x[2]);
    const v4d V0 = _mm256_set1_pd(c->v[0]), V1 = _mm256_set1_pd(c->v[1]),
              V2 = _mm256_set1_pd(c->v[2]);
    const v4d L0 = _mm256_set1_pd(c->L[0]), L1 = _mm256_set1_pd(c->L[1]),
              L2 = _mm256_set1_pd(c->L[2]);
    const v4d I0 = _mm256_set1_pd(c->iL[0]), I1 = _mm256_set1_pd(c->iL[1]),
              I2 = _mm256_set1_pd(c->iL[2]);
    const v4d ZERO = _mm256_setzero_pd(), TWO = _mm256_set1_pd(2);
    const v4d NEG_TOL = _mm256_set1_pd(-1e-9);
    for (uint32_t q = 0; q < nq; q += 4) {
        const int32_t *ix = nb + q;
        int32_t tail[4];
        int lanes = 0xf;
        if (q + 4 > nq) {
            const uint32_t left = nq - q; /* 1..3 */
            lanes = (1 << left) - 1;
            tail[0] = tail[3] = nb[q]; /* nb[q + l] for l < left, else nb[q] */
            tail[1] = nb[q + (left > 1)];
            tail[2] = nb[q + 2 * (left > 2)];
            ix = tail;
        } else if (q + PREFETCH_AHEAD + 3 < nq) {
            /* unrolled (gcc keeps a 4-step loop of 7 instructions
             * otherwise): −3 % instructions per collision, same events */
            const int32_t *pf = nb + q + PREFETCH_AHEAD;
            __builtin_prefetch(&K[pf[0]]);
            __builtin_prefetch(&K[pf[1]]);
            __builtin_prefetch(&K[pf[2]]);
            __builtin_prefetch(&K[pf[3]]);
        }
        const edmd_kin *ka = &K[ix[0]], *kb = &K[ix[1]], *kc = &K[ix[2]], *kd = &K[ix[3]];
        /* rows (p0 p1 p2 a) and (v0 v1 v2 g) of the four grains → columns */
        const v4d Pa = _mm256_load_pd(ka->p), Pb = _mm256_load_pd(kb->p),
                  Pc = _mm256_load_pd(kc->p), Pd = _mm256_load_pd(kd->p);
        const v4d Wa = _mm256_load_pd(ka->v), Wb = _mm256_load_pd(kb->v),
                  Wc = _mm256_load_pd(kc->v), Wd = _mm256_load_pd(kd->v);
        v4d lo = _mm256_unpacklo_pd(Pa, Pb), hi = _mm256_unpackhi_pd(Pa, Pb);
        v4d lo2 = _mm256_unpacklo_pd(Pc, Pd), hi2 = _mm256_unpackhi_pd(Pc, Pd);
        const v4d p0 = _mm256_permute2f128_pd(lo, lo2, 0x20),
                  p2 = _mm256_permute2f128_pd(lo, lo2, 0x31);
        const v4d p1 = _mm256_permute2f128_pd(hi, hi2, 0x20),
                  ra = _mm256_permute2f128_pd(hi, hi2, 0x31);
        lo = _mm256_unpacklo_pd(Wa, Wb), hi = _mm256_unpackhi_pd(Wa, Wb);
        lo2 = _mm256_unpacklo_pd(Wc, Wd), hi2 = _mm256_unpackhi_pd(Wc, Wd);
        const v4d v0 = _mm256_permute2f128_pd(lo, lo2, 0x20),
                  v2 = _mm256_permute2f128_pd(lo, lo2, 0x31);
        const v4d v1 = _mm256_permute2f128_pd(hi, hi2, 0x20),
                  rg = _mm256_permute2f128_pd(hi, hi2, 0x31);
        LANE_TERMS(v4d);
        const v4d BOUND = _mm256_set1_pd(pr->second);
        /* common lanes: gap open, A >= 0, approaching; pair_root dismisses
         * them when the root lies beyond the runner-up (C >= −2B·bound) or
         * there is none (D < 0), and touching lanes (C <= 0, no overlap
         * beyond round-off) that separate with A >= 0 */
        const v4m grow_slower = A >= ZERO;
        const v4m common = (C > ZERO) & grow_slower;
        const v4m hit = common & (B < ZERO) & (C < -TWO * B * BOUND) & (D >= ZERO);
        const v4m parting = (C <= ZERO) & (B >= ZERO) & grow_slower & (C >= NEG_TOL * R * R);
        const int m_hit = _mm256_movemask_pd((__m256d)hit) & lanes;
        const int m_other = ~_mm256_movemask_pd((__m256d)(common | parting)) & lanes;
        if (!(m_hit | m_other))
            continue;
        v4d tau = ZERO;
        if (m_hit)
            tau = C / (-B + _mm256_sqrt_pd(_mm256_max_pd(D, ZERO)));
        lane_offers(s, pr, ix, (unsigned)(m_hit | m_other), (unsigned)m_hit, (const double *)&tau,
                    (const double *)&A, (const double *)&B, (const double *)&C, (const double *)&R,
                    (const double *)&dd);
    }
}

/* Eight neighbours at once (AVX-512F, chosen at run time): groups of eight
 * while at least LANES8_MIN neighbours are left (a short last group repeats
 * its first neighbour in the empty lanes, masked); returns how many it did,
 * the caller passes the rest to pair_lanes4.  Same operations per lane as
 * pair_one (bit-identical); the eight records (one 64-byte line each: p0 p1
 * p2 a v0 v1 v2 g) are loaded whole and transposed (unpack, then two rounds
 * of 128-bit lane shuffles) into the eight columns.  One runner-up bound for
 * the pre-filter of eight lanes: it may pass more lanes than the 4-lane
 * loop, but each offer is tested against the current pr->second, in list
 * order.
 * LANES8_MIN: below 7 neighbours one 8-lane group costs more than a 4-lane
 * group and 1–2 scalar ones (ns per prediction 8-lane/4-lane: 33+ 0.75–0.80,
 * 5–6 1.04–1.09; docs/perf/edmd.md). */
#define LANES8_MIN 7
__attribute__((target("avx512f"))) static uint32_t pair_lanes8(edmd_state *s, pred *pr,
                                                               const self *c, const int32_t *nb,
                                                               uint32_t nq)
{
    typedef double v8d __attribute__((vector_size(64)));
    const edmd_kin *K = s->k;
    const v8d T = _mm512_set1_pd(c->t), VM = _mm512_set1_pd(MIN_IMAGE_M);
    const v8d RI = _mm512_set1_pd(c->r), GI = _mm512_set1_pd(c->g);
    const v8d X0 = _mm512_set1_pd(c->x[0]), X1 = _mm512_set1_pd(c->x[1]),
              X2 = _mm512_set1_pd(c->x[2]);
    const v8d V0 = _mm512_set1_pd(c->v[0]), V1 = _mm512_set1_pd(c->v[1]),
              V2 = _mm512_set1_pd(c->v[2]);
    const v8d L0 = _mm512_set1_pd(c->L[0]), L1 = _mm512_set1_pd(c->L[1]),
              L2 = _mm512_set1_pd(c->L[2]);
    const v8d I0 = _mm512_set1_pd(c->iL[0]), I1 = _mm512_set1_pd(c->iL[1]),
              I2 = _mm512_set1_pd(c->iL[2]);
    const v8d ZERO = _mm512_setzero_pd(), TWO = _mm512_set1_pd(2);
    const v8d NEG_TOL = _mm512_set1_pd(-1e-9);
    uint32_t q = 0;
    for (; q + LANES8_MIN <= nq; q += 8) {
        const int32_t *ix = nb + q;
        int32_t tail[8];
        unsigned lanes = 0xffu;
        if (q + 8 > nq) {
            /* a short last group repeats its first neighbour, masked */
            const uint32_t left = nq - q; /* LANES8_MIN..7 */
            lanes = (1u << left) - 1;
            for (uint32_t l = 0; l < 8; l++)
                tail[l] = nb[q + (l < left ? l : 0)];
            ix = tail;
        } else if (q + 16 <= nq) {
            const int32_t *pf = ix + 8;
            for (int l = 0; l < 8; l++)
                __builtin_prefetch(&K[pf[l]]);
        }
        const v8d r0 = _mm512_load_pd(K[ix[0]].p), r1 = _mm512_load_pd(K[ix[1]].p),
                  r2 = _mm512_load_pd(K[ix[2]].p), r3 = _mm512_load_pd(K[ix[3]].p),
                  r4 = _mm512_load_pd(K[ix[4]].p), r5 = _mm512_load_pd(K[ix[5]].p),
                  r6 = _mm512_load_pd(K[ix[6]].p), r7 = _mm512_load_pd(K[ix[7]].p);
        /* t0 = (r0.0 r1.0 | r0.2 r1.2 | r0.4 r1.4 | r0.6 r1.6), t1 the odd ones */
        const v8d t0 = _mm512_unpacklo_pd(r0, r1), t1 = _mm512_unpackhi_pd(r0, r1),
                  t2 = _mm512_unpacklo_pd(r2, r3), t3 = _mm512_unpackhi_pd(r2, r3),
                  t4 = _mm512_unpacklo_pd(r4, r5), t5 = _mm512_unpackhi_pd(r4, r5),
                  t6 = _mm512_unpacklo_pd(r6, r7), t7 = _mm512_unpackhi_pd(r6, r7);
        /* 0x88: 128-bit lanes 0, 2 of each source; 0xDD: lanes 1, 3.
         * u0 = (r0.0 r1.0 | r0.4 r1.4 | r2.0 r3.0 | r2.4 r3.4) */
        const v8d u0 = _mm512_shuffle_f64x2(t0, t2, 0x88), u1 = _mm512_shuffle_f64x2(t0, t2, 0xDD),
                  u2 = _mm512_shuffle_f64x2(t1, t3, 0x88), u3 = _mm512_shuffle_f64x2(t1, t3, 0xDD),
                  u4 = _mm512_shuffle_f64x2(t4, t6, 0x88), u5 = _mm512_shuffle_f64x2(t4, t6, 0xDD),
                  u6 = _mm512_shuffle_f64x2(t5, t7, 0x88), u7 = _mm512_shuffle_f64x2(t5, t7, 0xDD);
        const v8d p0 = _mm512_shuffle_f64x2(u0, u4, 0x88), v0 = _mm512_shuffle_f64x2(u0, u4, 0xDD);
        const v8d p2 = _mm512_shuffle_f64x2(u1, u5, 0x88), v2 = _mm512_shuffle_f64x2(u1, u5, 0xDD);
        const v8d p1 = _mm512_shuffle_f64x2(u2, u6, 0x88), v1 = _mm512_shuffle_f64x2(u2, u6, 0xDD);
        const v8d ra = _mm512_shuffle_f64x2(u3, u7, 0x88), rg = _mm512_shuffle_f64x2(u3, u7, 0xDD);
        LANE_TERMS(v8d);
        const v8d BOUND = _mm512_set1_pd(pr->second);
        /* the lane classes of pair_lanes4 */
        const __mmask8 grow_slower = _mm512_cmp_pd_mask(A, ZERO, _CMP_GE_OQ);
        const __mmask8 common = _mm512_cmp_pd_mask(C, ZERO, _CMP_GT_OQ) & grow_slower;
        const __mmask8 hit = common & _mm512_cmp_pd_mask(B, ZERO, _CMP_LT_OQ) &
            _mm512_cmp_pd_mask(C, -TWO * B * BOUND, _CMP_LT_OQ) &
            _mm512_cmp_pd_mask(D, ZERO, _CMP_GE_OQ);
        const __mmask8 parting = _mm512_cmp_pd_mask(C, ZERO, _CMP_LE_OQ) &
            _mm512_cmp_pd_mask(B, ZERO, _CMP_GE_OQ) & grow_slower &
            _mm512_cmp_pd_mask(C, NEG_TOL * R * R, _CMP_GE_OQ);
        const unsigned m_hit = hit & lanes, m_other = ~(unsigned)(common | parting) & lanes;
        if (!(m_hit | m_other))
            continue;
        v8d tau = ZERO;
        if (m_hit)
            tau = C / (-B + _mm512_sqrt_pd(_mm512_max_pd(D, ZERO)));
        lane_offers(s, pr, ix, (unsigned)(m_hit | m_other), (unsigned)m_hit, (const double *)&tau,
                    (const double *)&A, (const double *)&B, (const double *)&C, (const double *)&R,
                    (const double *)&dd);
    }
    return q;
}

/* (no cached flag: workers may predict in several threads; the builtin
 * reads the CPU model libgcc filled in at start-up) */
static int lanes4_ok(void) { return __builtin_cpu_supports("avx2") && !edmd_scalar_only; }

static int lanes8_ok(void)
{
    return __builtin_cpu_supports("avx512f") && !edmd_scalar_only && !edmd_lanes4_only;
}
#endif

int edmd_scalar_only = 0;
int edmd_lanes4_only = 0;

int edmd_lanes_available(void)
{
#ifdef HAVE_LANES4
    return lanes4_ok();
#else
    return 0;
#endif
}

int edmd_lanes8_available(void)
{
#ifdef HAVE_LANES4
    return lanes8_ok();
#else
    return 0;
#endif
}

/* Issued at a collision for both grains before the first prediction, so j's
 * neighbours load while i's are processed (a list of ~9 is too short for
 * the loop's PREFETCH_AHEAD).  Same events; mono 3D N = 10^4 to jamming
 * −5..−8 % CPU (docs/perf/edmd.md). */
void edmd_prefetch_list(const edmd_state *s, size_t i)
{
    /* four a step (gcc keeps a 7-instruction loop otherwise) */
    const edmd_kin *K = s->k;
    const int32_t *nb = s->nl_pool + s->nl[i].off;
    const uint32_t nq = s->nl[i].n <= PREFETCH_LIST_MAX ? s->nl[i].n : PREFETCH_AHEAD;
    uint32_t q = 0;
    for (; q + 4 <= nq; q += 4) {
        __builtin_prefetch(&K[nb[q]]);
        __builtin_prefetch(&K[nb[q + 1]]);
        __builtin_prefetch(&K[nb[q + 2]]);
        __builtin_prefetch(&K[nb[q + 3]]);
    }
    if (q < nq)
        __builtin_prefetch(&K[nb[q]]);
    if (q + 1 < nq)
        __builtin_prefetch(&K[nb[q + 1]]);
    if (q + 2 < nq)
        __builtin_prefetch(&K[nb[q + 2]]);
}

void edmd_prefetch_grain(const edmd_state *s, size_t i)
{
    __builtin_prefetch(&s->k[i]);
    __builtin_prefetch(&s->ev[i]);
    __builtin_prefetch(&s->nl[i]);
    __builtin_prefetch(&s->ncoll[i]);
    __builtin_prefetch(&s->bs.x[3 * i]);
    __builtin_prefetch(&s->bs.r[i]);
    __builtin_prefetch(&s->q.node[i]);
}

void edmd_predict(edmd_state *s, size_t i)
{
    const edmd_kin *ki = &s->k[i];
    self c = {.t = s->t, .r = edmd_rho(s, i, s->t), .g = ki->g};
    edmd_sync_pos(s, i, c.x);
    for (int k = 0; k < 3; k++) {
        c.v[k] = ki->v[k];
        c.L[k] = s->Lp[k];
        c.iL[k] = s->inv_Lp[k];
    }
    pred pr = {INFINITY, INFINITY, EDMD_EV_NONE, EDMD_EV_NONE, 0, 0};

    /* leaving the bounding sphere */
    {
        /* pk_min_image3 written out on the copies in c (same operations,
         * no loop through s) */
        const double *bx = &s->bs.x[3 * i], M = MIN_IMAGE_M;
        double q[3] = {c.x[0] - bx[0], c.x[1] - bx[1], c.x[2] - bx[2]}; /* 0 beyond dim */
        q[0] -= c.L[0] * ((q[0] * c.iL[0] + M) - M);
        q[1] -= c.L[1] * ((q[1] * c.iL[1] + M) - M);
        q[2] -= c.L[2] * ((q[2] * c.iL[2] + M) - M);
        offer(&pr, pk_edmd_exit_time(q, c.v, c.r, c.g, s->bs.r[i]), EDMD_EV_NLIST, 0);
    }
    if (s->walled) {
        int code = -1;
        double tw = edmd_wall_time(s, i, &code);
        offer(&pr, tw, EDMD_EV_WALL0 - code, 0);
    }
    const int32_t *nb = s->nl_pool + s->nl[i].off;
    const uint32_t nq = s->nl[i].n;
#ifdef HAVE_LANES4
    if (nq >= LANES8_MIN && lanes8_ok()) {
        const uint32_t done = pair_lanes8(s, &pr, &c, nb, nq);
        if (done < nq)
            pair_lanes4(s, &pr, &c, nb + done, nq - done);
    } else if (lanes4_ok()) {
        pair_lanes4(s, &pr, &c, nb, nq);
    } else
#endif
    {
        for (uint32_t q = 0; q < nq; q++)
            pair_one(s, &pr, &c, (size_t)nb[q]);
    }
    s->ev[i] = (edmd_event){c.t + pr.best, c.t + pr.second, pr.with, pr.with2, pr.stamp, pr.stamp2};
}
