/* edmd_collide.c — growth-aware collision rules (spec §3.4).
 *
 * Titscher's elastic rule (Eq. 27) alone leaves a growing pair approaching
 * whenever its separation speed w < G = g_i + g_j; Meier's Eq. 3.9 adds the
 * growth rates but conserves momentum only for equal masses and rates.  The
 * rule here: elastic reversal w' = −w, then lift w' to at least G + ε_v with
 * a momentum-conserving impulse (mass-weighted generalisation of Eq. 3.9),
 * so the gap opens after every collision and the pair is never re-predicted
 * at t = 0. */
#include <math.h>

#include "edmd_state.h"

double edmd_collide_pair(edmd_state *s, size_t i, size_t j)
{
    /* p/v carry 0 beyond dim (2D): three components throughout */
    double xi[3], xj[3], n[3];
    edmd_sync_pos(s, i, xi);
    edmd_sync_pos(s, j, xj);
    for (int k = 0; k < 3; k++)
        n[k] = xj[k] - xi[k];
    edmd_min_image_near(s, n);
    const double dist = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (!(dist > 0))
        return 0;
    double *vi = s->k[i].v, *vj = s->k[j].v;
    const double inv = 1 / dist;
    for (int k = 0; k < 3; k++)
        n[k] *= inv;
    const double w = (vj[0] - vi[0]) * n[0] + (vj[1] - vi[1]) * n[1] + (vj[2] - vi[2]) * n[2];
    const double target = s->k[i].g + s->k[j].g + s->eps_v;
    if (w >= target)
        return 0; /* already separating fast enough (round-off prediction) */
    const double w_new = -w > target ? -w : target;
    const double mi = s->m[i], mj = s->m[j], mu = mi * mj / (mi + mj);
    const double P = mu * (w_new - w); /* normal impulse on j */
    const double di = P / mi, dj = P / mj;
    for (int k = 0; k < 3; k++) {
        vi[k] -= di * n[k];
        vj[k] += dj * n[k];
    }
    edmd_pin(s, i, xi);
    edmd_pin(s, j, xj);
    /* ΔK = P·w + P²/(2μ): the normal relative speed goes from w to w_new */
    s->K += P * (w + 0.5 * (w_new - w));
    return dist * P;
}

void edmd_collide_wall(edmd_state *s, size_t i, int code)
{
    double x[3];
    edmd_pos(s, i, x);
    int k = code / 2;
    double *vk = &s->k[i].v[k];
    double min_out = s->k[i].g + s->eps_v; /* admissible: outward speed > growth (spec §3.4) */
    double before = *vk;
    if (code % 2 == 0)
        *vk = fmax(-*vk, min_out);
    else
        *vk = fmin(-*vk, -min_out);
    edmd_pin(s, i, x);
    s->K += 0.5 * s->m[i] * (*vk * *vk - before * before);
}
