/* edmd_walls.c — EDMD in a box widened by the part of the shell the walls
 * must not see (core/edmd/edmd_walls.h; Titscher §6.3). */
#include <math.h>

#include "edmd_walls.h"

static void shift_walled(const pk_box *b, pk_particles *p, double by)
{
    for (size_t i = 0; i < p->n; i++)
        for (int k = 0; k < b->dim; k++)
            if (!b->periodic[k])
                p->x[3 * i + k] += by;
}

int pk_edmd_run_shell_in_walls(const pk_box *b, double w, pk_particles *p,
                               const pk_edmd_params *prm, pk_monitor *mon, pk_edmd_stats *st)
{
    if (!b || !p || !prm || !(w >= 0))
        return -1;
    if (w == 0)
        return pk_edmd_run(b, p, prm, mon, st);
    pk_box wide = *b;
    for (int k = 0; k < b->dim; k++)
        if (!b->periodic[k])
            wide.L[k] += 2 * w;
    /* φ of the engine refers to the widened box: f = V_wide / V */
    const double f = pk_box_measure(&wide) / pk_box_measure(b);
    pk_edmd_params q = *prm;
    if (q.phi_target > 0)
        q.phi_target /= f;
    shift_walled(b, p, w);
    int rc = pk_edmd_run(&wide, p, &q, mon, st);
    shift_walled(b, p, -w);
    for (size_t i = 0; i < p->n; i++) /* round-off of a grain touching a wall */
        for (int k = 0; k < b->dim; k++)
            if (!b->periodic[k])
                p->x[3 * i + k] = fmin(fmax(p->x[3 * i + k], 0), b->L[k]);
    st->phi *= f;
    st->phi_sim *= f;
    st->phi_jam_estimate *= f;
    for (size_t k = 0; k < st->nhist; k++)
        st->hist_phi[k] *= f;
    return rc;
}

double pk_edmd_pull_inside(const pk_box *b, pk_particles *p)
{
    double smin = 1;
    for (int k = 0; k < b->dim; k++) {
        if (b->periodic[k])
            continue;
        const double c = 0.5 * b->L[k];
        double s = 1;
        for (size_t i = 0; i < p->n; i++) { /* |x − c| + r <= c after scaling by s */
            const double off = fabs(p->x[3 * i + k] - c), room = c - p->r[i];
            if (off > room)
                s = fmin(s, fmax(room, 0) / off);
        }
        if (s < 1)
            for (size_t i = 0; i < p->n; i++) {
                double x = c + s * (p->x[3 * i + k] - c);
                p->x[3 * i + k] = fmin(fmax(x, p->r[i]), b->L[k] - p->r[i]); /* round-off */
            }
        smin = fmin(smin, s);
    }
    return smin;
}
