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
    if (A < 0)
        return (B + sqrt(fmax(B * B - A * C, 0))) / -A;
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
    double sq = sqrt(fmax(B * B - A * C, 0));
    if (B >= 0)
        return C / -(B + sq);        /* C < 0: positive, no cancellation (+inf at rest, g = 0) */
    if (A > 0)
        return (-B + sq) / A;
    return 0;                        /* B < 0 with A <= 0 is impossible inside; rebuild now */
}

/* Keeps periodic coordinates in [0, L) so that a displacement between two
 * grains (each within a list skin of its synced position) is within 1.5 L
 * and one conditional shift gives the minimum image. */
void edmd_sync(edmd_state *s, size_t i)
{
    double dt = s->t - s->t0[i];
    if (dt != 0)
        for (int k = 0; k < s->dim; k++) {
            double x = s->x0[3 * i + k] + s->v[3 * i + k] * dt;
            if (s->box.periodic[k]) {
                if (x < 0)
                    x += s->box.L[k];
                else if (x >= s->box.L[k])
                    x -= s->box.L[k];
            }
            s->x0[3 * i + k] = x;
        }
    s->t0[i] = s->t;
}

/* Earliest wall contact of i from now (i synced); code = 2k + side. */
double edmd_wall_time(const edmd_state *s, size_t i, int *code)
{
    double best = INFINITY;
    double rho = s->a[i] + s->g[i] * s->t, g = s->g[i];
    for (int k = 0; k < s->dim; k++) {
        if (s->box.periodic[k])
            continue;
        double x = s->x0[3 * i + k], vk = s->v[3 * i + k];
        double lo_rate = vk - g, hi_rate = -vk - g; /* gap rates */
        if (lo_rate < 0) {
            double tau = fmax(x - rho, 0) / -lo_rate;
            if (tau < best) {
                best = tau;
                *code = 2 * k;
            }
        }
        if (hi_rate < 0) {
            double tau = fmax(s->box.L[k] - x - rho, 0) / -hi_rate;
            if (tau < best) {
                best = tau;
                *code = 2 * k + 1;
            }
        }
    }
    return best;
}

void edmd_predict(edmd_state *s, size_t i)
{
    edmd_sync(s, i);
    const double t = s->t;
    const double *xi = &s->x0[3 * i], *vi = &s->v[3 * i];
    const double ri = s->a[i] + s->g[i] * t, gi = s->g[i];
    double best;
    int code = -1;
    uint8_t kind = EV_NONE;
    int32_t partner = -1;
    uint32_t stamp = 0;

    /* leaving the bounding sphere */
    {
        double q[3] = {0, 0, 0};
        for (int k = 0; k < s->dim; k++)
            q[k] = xi[k] - s->bs.x[3 * i + k];
        edmd_min_image_near(s, q);
        best = pk_edmd_exit_time(q, vi, ri, gi, s->bs.r[i]);
        if (best < INFINITY)
            kind = EV_NLIST;
    }
    double tw = edmd_wall_time(s, i, &code);
    if (tw < best) {
        best = tw;
        kind = EV_WALL;
        partner = code;
    }
    /* x0/v carry 0 beyond dim (2D), so all three components are computed */
    const double xi0 = xi[0], xi1 = xi[1], xi2 = xi[2];
    const double vi0 = vi[0], vi1 = vi[1], vi2 = vi[2];
    const edmd_nlist *L = &s->nl[i];
    for (uint32_t q = 0; q < L->n; q++) {
        size_t j = (size_t)L->nb[q];
        const double dtj = t - s->t0[j];
        const double *xj = &s->x0[3 * j], *vj = &s->v[3 * j];
        double dp[3] = {xi0 - (xj[0] + vj[0] * dtj), xi1 - (xj[1] + vj[1] * dtj),
                        xi2 - (xj[2] + vj[2] * dtj)};
        const double dv0 = vi0 - vj[0], dv1 = vi1 - vj[1], dv2 = vi2 - vj[2];
        edmd_min_image_near(s, dp);
        const double R = ri + s->a[j] + s->g[j] * t, G = gi + s->g[j];
        const double A = dv0 * dv0 + dv1 * dv1 + dv2 * dv2 - G * G;
        const double B = dp[0] * dv0 + dp[1] * dv1 + dp[2] * dv2 - R * G;
        const double C = dp[0] * dp[0] + dp[1] * dp[1] + dp[2] * dp[2] - R * R;
        if (C < -1e-9 * R * R) { /* overlap by more than round-off: record it */
            double d = sqrt(dp[0] * dp[0] + dp[1] * dp[1] + dp[2] * dp[2]);
            double rel = (R - d) / R;
            s->n_overlap++;
            if (rel > s->max_overlap_rel)
                s->max_overlap_rel = rel;
        }
        double tau = pair_root(A, B, C, best);
        if (tau < best) {
            best = tau;
            kind = EV_PAIR;
            partner = (int32_t)j;
            stamp = s->ncoll[j];
        }
    }
    s->ev_t[i] = t + best;
    s->ev_kind[i] = kind;
    s->ev_partner[i] = partner;
    s->ev_stamp[i] = stamp;
}
