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
    edmd_sync(s, i);
    edmd_sync(s, j);
    double xi[3], xj[3], n[3] = {0, 0, 0};
    edmd_pos(s, i, xi);
    edmd_pos(s, j, xj);
    for (int k = 0; k < s->dim; k++)
        n[k] = xj[k] - xi[k];
    edmd_min_image_near(s, n);
    double dist = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (!(dist > 0))
        return 0;
    double *vi = s->k[i].v, *vj = s->k[j].v;
    double w = 0;
    for (int k = 0; k < s->dim; k++) {
        n[k] /= dist;
        w += (vj[k] - vi[k]) * n[k];
    }
    double G = s->k[i].g + s->k[j].g;
    double target = G + s->eps_v;
    if (w >= target)
        return 0; /* already separating fast enough (round-off prediction) */
    double w_new = fmax(-w, target);
    double mi = s->m[i], mj = s->m[j];
    double P = mi * mj / (mi + mj) * (w_new - w); /* normal impulse on j */
    double k_before = 0, k_after = 0;
    for (int k = 0; k < s->dim; k++)
        k_before += mi * vi[k] * vi[k] + mj * vj[k] * vj[k];
    for (int k = 0; k < s->dim; k++) {
        vi[k] -= P / mi * n[k];
        vj[k] += P / mj * n[k];
        k_after += mi * vi[k] * vi[k] + mj * vj[k] * vj[k];
    }
    edmd_pin(s, i, xi);
    edmd_pin(s, j, xj);
    s->K += 0.5 * (k_after - k_before);
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
