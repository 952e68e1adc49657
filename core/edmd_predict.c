/* edmd_predict.c — event times: pair collisions (spec §3.3a, cancellation-free
 * roots), walls (§3.3b), leaving the neighbour-list bounding sphere (§3.3c). */
#include <math.h>

#include "edmd_state.h"

/* Root of A τ² − 2(−B) τ + C = 0 for the quadratic of pk_edmd_pair_time.
 * bound: the caller only wants roots below it; pairs that provably collide
 * no earlier are dismissed (INFINITY) without the sqrt and the division —
 * for A >= 0, B < 0 the root C/(−B + √D) >= C/(−2B) as √D <= −B. */
static inline double pair_root(double A, double B, double C, double bound)
{
    if (C > 0) {
        if (A < 0) {                 /* growth outruns the relative speed: one positive root */
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
        return 0;                    /* gap shrinking: collide now */
    if (A < 0) {
        const double D = B * B - A * C;
        return (B + sqrt(D > 0 ? D : 0)) / -A;
    }
    return INFINITY;
}

double pk_edmd_pair_time(const double dp[3], const double dv[3], double R, double G,
                         int *overlap)
{
    double A = dv[0] * dv[0] + dv[1] * dv[1] + dv[2] * dv[2] - G * G;
    double B = dp[0] * dv[0] + dp[1] * dv[1] + dp[2] * dv[2] - R * G;
    double C = dp[0] * dp[0] + dp[1] * dp[1] + dp[2] * dp[2] - R * R;
    if (overlap)
        *overlap = C < -1e-9 * R * R;
    return pair_root(A, B, C, INFINITY);
}

double pk_edmd_exit_time(const double q[3], const double v[3], double rho0, double g,
                         double sigma)
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
        return C / -(B + sq);        /* C < 0: positive, no cancellation (+inf at rest, g = 0) */
    if (A > 0)
        return (-B + sq) / A;
    return 0;                        /* B < 0 with A <= 0 is impossible inside; rebuild now */
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
 * (mono 3D N = 4000 to jamming: about −10 % run time at 3, none at 1). */
#define PREFETCH_AHEAD 4

/* Two lanes of doubles (GCC/Clang vector extension, SSE2 on x86-64): the
 * neighbour loop evaluates the quadratics of two neighbours at once.  Every
 * lane does the scalar code's operations in the scalar code's order (no FMA
 * contraction under -std=c17), so the results are bit-identical. */
typedef double v2d __attribute__((vector_size(16)));
typedef long long v2m __attribute__((vector_size(16)));

typedef struct pred {
    double best;
    uint8_t kind;
    int32_t partner;
    uint32_t stamp;
} pred;

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
    double tau = pair_root(A, B, C, pr->best);
    if (tau < pr->best) {
        pr->best = tau;
        pr->kind = EV_PAIR;
        pr->partner = (int32_t)j;
        pr->stamp = s->ncoll[j];
    }
}

void edmd_predict(edmd_state *s, size_t i)
{
    edmd_sync(s, i);
    const double t = s->t;
    double xi[3];
    edmd_pos(s, i, xi);
    const double *vi = s->k[i].v;
    const double ri = edmd_rho(s, i, t), gi = s->k[i].g;
    pred pr = {INFINITY, EV_NONE, -1, 0};
    int code = -1;

    /* leaving the bounding sphere */
    {
        double q[3] = {0, 0, 0};
        for (int k = 0; k < s->dim; k++)
            q[k] = xi[k] - s->bs.x[3 * i + k];
        edmd_min_image_near(s, q);
        pr.best = pk_edmd_exit_time(q, vi, ri, gi, s->bs.r[i]);
        if (pr.best < INFINITY)
            pr.kind = EV_NLIST;
    }
    double tw = s->walled ? edmd_wall_time(s, i, &code) : INFINITY;
    if (tw < pr.best) {
        pr.best = tw;
        pr.kind = EV_WALL;
        pr.partner = code;
    }
    /* p/v carry 0 beyond dim (2D), so all three components are computed;
     * minimum image as pk_min_image3, inlined with the box in registers */
    const double M = 6755399441055744.0;
    const edmd_kin *K = s->k;
    const edmd_nlist *L = &s->nl[i];
    const int32_t *nb = L->nb;
    const uint32_t nq = L->n;
    uint32_t q = 0;
    {
        const v2d T = {t, t}, VM = {M, M}, RI = {ri, ri}, GI = {gi, gi};
        const v2d X0 = {xi[0], xi[0]}, X1 = {xi[1], xi[1]}, X2 = {xi[2], xi[2]};
        const v2d V0 = {vi[0], vi[0]}, V1 = {vi[1], vi[1]}, V2 = {vi[2], vi[2]};
        const v2d L0 = {s->Lp[0], s->Lp[0]}, L1 = {s->Lp[1], s->Lp[1]}, L2 = {s->Lp[2], s->Lp[2]};
        const v2d I0 = {s->inv_Lp[0], s->inv_Lp[0]}, I1 = {s->inv_Lp[1], s->inv_Lp[1]},
                  I2 = {s->inv_Lp[2], s->inv_Lp[2]};
        const v2d ZERO = {0, 0}, TWO = {2, 2};
        for (; q + 2 <= nq; q += 2) {
            if (q + PREFETCH_AHEAD + 1 < nq) {
                __builtin_prefetch(&K[nb[q + PREFETCH_AHEAD]]);
                __builtin_prefetch(&K[nb[q + PREFETCH_AHEAD + 1]]);
            }
            const edmd_kin *a = &K[nb[q]], *b = &K[nb[q + 1]];
            const v2d p0 = {a->p[0], b->p[0]}, p1 = {a->p[1], b->p[1]}, p2 = {a->p[2], b->p[2]};
            const v2d v0 = {a->v[0], b->v[0]}, v1 = {a->v[1], b->v[1]}, v2 = {a->v[2], b->v[2]};
            const v2d ra = {a->a, b->a}, rg = {a->g, b->g};
            v2d d0 = X0 - (p0 + v0 * T), d1 = X1 - (p1 + v1 * T), d2 = X2 - (p2 + v2 * T);
            d0 -= L0 * ((d0 * I0 + VM) - VM);
            d1 -= L1 * ((d1 * I1 + VM) - VM);
            d2 -= L2 * ((d2 * I2 + VM) - VM);
            const v2d dv0 = V0 - v0, dv1 = V1 - v1, dv2 = V2 - v2;
            const v2d R = RI + ra + rg * T, G = GI + rg;
            const v2d B = d0 * dv0 + d1 * dv1 + d2 * dv2 - R * G;
            const v2d dd = d0 * d0 + d1 * d1 + d2 * d2;
            const v2d C = dd - R * R;
            const v2d A = dv0 * dv0 + dv1 * dv1 + dv2 * dv2 - G * G;
            const v2d BEST = {pr.best, pr.best};
            /* lanes pair_root certainly dismisses (INFINITY, no overlap) */
            const v2m skip = (C > ZERO) & (A >= ZERO) & ((B >= ZERO) | (C >= -TWO * B * BEST));
            if (skip[0] & skip[1])
                continue;
            if (!skip[0])
                pair_take(s, &pr, (size_t)nb[q], A[0], B[0], C[0], R[0], dd[0]);
            if (!skip[1])
                pair_take(s, &pr, (size_t)nb[q + 1], A[1], B[1], C[1], R[1], dd[1]);
        }
    }
    if (q < nq) { /* odd list: the last neighbour */
        const size_t j = (size_t)nb[q];
        const edmd_kin *kj = &K[j];
        double d0 = xi[0] - (kj->p[0] + kj->v[0] * t), d1 = xi[1] - (kj->p[1] + kj->v[1] * t),
               d2 = xi[2] - (kj->p[2] + kj->v[2] * t);
        d0 -= s->Lp[0] * ((d0 * s->inv_Lp[0] + M) - M);
        d1 -= s->Lp[1] * ((d1 * s->inv_Lp[1] + M) - M);
        d2 -= s->Lp[2] * ((d2 * s->inv_Lp[2] + M) - M);
        const double dv0 = vi[0] - kj->v[0], dv1 = vi[1] - kj->v[1], dv2 = vi[2] - kj->v[2];
        const double R = ri + kj->a + kj->g * t, G = gi + kj->g;
        const double B = d0 * dv0 + d1 * dv1 + d2 * dv2 - R * G;
        const double dd = d0 * d0 + d1 * d1 + d2 * d2;
        const double A = dv0 * dv0 + dv1 * dv1 + dv2 * dv2 - G * G;
        pair_take(s, &pr, j, A, B, dd - R * R, R, dd);
    }
    s->ev_t[i] = t + pr.best;
    s->ev_kind[i] = pr.kind;
    s->ev_partner[i] = pr.partner;
    s->ev_stamp[i] = pr.stamp;
}
