#include "rsa.h"

#include <math.h>

#include "grid.h"
#include "rng.h"

int pk_rsa_place(const pk_box *b, const double *diameters, const int32_t *species, size_t n,
                 const pk_rsa_params *prm, pk_monitor *mon, pk_particles *out,
                 pk_rsa_stats *st)
{
    pk_rsa_stats local = {0};
    if (!st)
        st = &local;
    *st = (pk_rsa_stats){.reason = PK_STOP_ERROR, .requested = n};
    if (!b || !prm || !out || out->dim != b->dim || (n && (!diameters || !species)))
        return -1;
    if (!(prm->delta_d >= 0) || prm->max_failed_draws == 0)
        return -1;
    for (size_t i = 0; i < n; i++)
        if (!(diameters[i] > 0) || (i && diameters[i] > diameters[i - 1]))
            return -1; /* sizes must be positive and sorted largest first */

    double t0 = pk_wall_seconds();
    st->reason = PK_STOP_COMPLETE;
    if (n == 0)
        return 0;
    if (pk_particles_reserve(out, out->n + n) != 0)
        return -1;

    const double gap = prm->delta_d;
    pk_grid grid;
    if (pk_grid_init(&grid, b, 0.5 * diameters[n - 1], 0.5 * diameters[0], gap, out->n + n) != 0)
        return -1;
    for (size_t j = 0; j < out->n; j++) /* grains already present stay obstacles */
        pk_grid_insert(&grid, out, j);

    pk_rng rng;
    pk_rng_seed(&rng, prm->seed, 1);
    pk_monitor_begin(mon);
    double box_measure = pk_box_measure(b);
    double solid = pk_particles_solid_measure(out);
    pk_progress pg = {.stage = "rsa", .total = n, .eta_s = -1};

    for (size_t i = 0; i < n; i++) {
        double r = 0.5 * diameters[i];
        /* Draw range per axis: walls keep the grain Δd/2 away (spec §2.1). */
        double lo[PK_MAXDIM] = {0, 0, 0}, span[PK_MAXDIM] = {0, 0, 0};
        int fits = 1;
        for (int k = 0; k < b->dim; k++) {
            if (b->periodic[k]) {
                lo[k] = 0;
                span[k] = b->L[k];
            } else {
                lo[k] = r + 0.5 * gap;
                span[k] = b->L[k] - 2 * lo[k];
                if (span[k] < 0)
                    fits = 0;
            }
        }
        if (!fits) {
            st->reason = PK_STOP_NO_ROOM;
            break;
        }
        uint64_t failed = 0;
        double x[PK_MAXDIM] = {0, 0, 0};
        for (;;) {
            for (int k = 0; k < b->dim; k++)
                x[k] = lo[k] + span[k] * pk_rng_uniform(&rng);
            st->draws++;
            if (!pk_grid_overlaps(&grid, out, x, r))
                break;
            if (++failed >= prm->max_failed_draws)
                break;
            if ((failed & 0xffff) == 0 && pk_monitor_tick(mon, &pg, 0))
                break;
        }
        if (failed >= prm->max_failed_draws) {
            st->reason = PK_STOP_MAX_FAILED_DRAWS;
            break;
        }
        if (mon && mon->cancelled) {
            st->reason = mon->cancelled == 2 ? PK_STOP_WALL_TIME : PK_STOP_CANCELLED;
            break;
        }
        size_t j = pk_particles_push(out, x, r, species[i]);
        if (j == (size_t)-1 || pk_grid_insert(&grid, out, j) != 0) {
            st->reason = PK_STOP_ERROR;
            break;
        }
        st->placed++;
        solid += pk_ball_measure(b->dim, r);
        if ((i & 0x3ff) == 0) {
            pg.done = st->placed;
            pg.fraction = (double)st->placed / (double)n;
            pg.phi = solid / box_measure;
            int c = pk_monitor_tick(mon, &pg, 0);
            if (c) {
                st->reason = c == 2 ? PK_STOP_WALL_TIME : PK_STOP_CANCELLED;
                break;
            }
        }
    }
    pg.done = st->placed;
    pg.fraction = (double)st->placed / (double)n;
    pg.phi = solid / box_measure;
    if (mon && !mon->cancelled)
        pk_monitor_tick(mon, &pg, 1);
    pk_grid_free(&grid);
    st->seconds = pk_wall_seconds() - t0;
    return st->reason == PK_STOP_ERROR ? -1 : 0;
}
