/* edmd_collide.c — growth-aware collision rules (Meier et al. Eqs. 9–10,
 * Titscher & Unger Eqs. 24–28; pk_edmd_rule).
 * Contract: edmd_collide_pair / edmd_collide_wall in core/edmd/edmd_state.h.
 *
 * Titscher's elastic rule (Eq. 27) alone leaves a growing pair approaching
 * whenever its separation speed w < G = g_i + g_j.  The default rule
 * reflects the pair in the frame of its growing surfaces (w' = 2G − w, a
 * momentum-conserving impulse: Lubachevsky–Stillinger, Donev), the lift
 * rule adds only what separation needs (w' = max(−w, G + ε_v)), Meier's
 * Eq. (9) swaps the normal speeds and adds the growth rates.  Every rule
 * opens the gap after a collision, so the pair is never re-predicted at
 * t = 0. */
#include <math.h>

#include "edmd_state.h"

/* Meier–Kuhl–Steinmann 2007 Eq. (9): v_ni' = min(v_ni, v_nj) − g_i,
 * v_nj' = max(v_ni, v_nj) + g_j (n from i to j); ε_v is added only when
 * the normal speeds are equal, where Eq. (9) would leave the pair grazing.
 * Returns σ·J with J = ½(m_i|Δv_ni| + m_j|Δv_nj|) (the virial of the reduced pressure). */
static double collide_meier(edmd_state *s, size_t i, size_t j, const double n[3], double dist)
{
    double *vi = s->k[i].v, *vj = s->k[j].v;
    const double vni = vi[0] * n[0] + vi[1] * n[1] + vi[2] * n[2];
    const double vnj = vj[0] * n[0] + vj[1] * n[1] + vj[2] * n[2];
    const double ai = fmin(vni, vnj) - s->k[i].g;
    double aj = fmax(vni, vnj) + s->k[j].g;
    if (fabs(vnj - vni) < s->eps_v)
        aj += s->eps_v;
    const double di = ai - vni, dj = aj - vnj;
    for (int k = 0; k < 3; k++) {
        vi[k] += di * n[k];
        vj[k] += dj * n[k];
    }
    const double mi = s->m[i], mj = s->m[j];
    s->K += 0.5 * mi * (ai * ai - vni * vni) + 0.5 * mj * (aj * aj - vnj * vnj);
    return dist * 0.5 * (mi * fabs(di) + mj * fabs(dj));
}

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
    const double G = s->k[i].g + s->k[j].g;
    if (w >= G + s->eps_v)
        return 0; /* already separating fast enough (round-off prediction) */
    if (s->rule == PK_EDMD_RULE_MEIER) {
        const double sj = collide_meier(s, i, j, n, dist);
        edmd_pin(s, i, xi);
        edmd_pin(s, j, xj);
        return sj;
    }
    double w_new;
    if (s->rule == PK_EDMD_RULE_LIFT)
        w_new = fmax(-w, G + s->eps_v);
    else /* gap rate w − G reversed: w' − G = G − w (≥ 0 at contact) */
        w_new = 2 * G - w + s->eps_v;
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
    const double g = s->k[i].g;
    const double before = *vk;
    /* outward speed u (> g admissible: the gap then opens): the lift rule takes the
     * least admissible one, the others reflect the gap rate u − g */
    const double u = code % 2 == 0 ? -before : before; /* elastic outward speed */
    const double out = s->rule == PK_EDMD_RULE_LIFT ? fmax(u, g + s->eps_v) : u + 2 * g + s->eps_v;
    *vk = code % 2 == 0 ? out : -out;
    edmd_pin(s, i, x);
    s->K += 0.5 * s->m[i] * (*vk * *vk - before * before);
}
