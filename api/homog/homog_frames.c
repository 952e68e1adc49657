/* homog_frames.c — the deformed grains per load step (contract in
 * homog_frames.h). */
#include "homog_frames.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/base/grow.h"

#include "core/dem/dem_contact.h"

void pk_homog_frames_init(pk_homog_frames *fr, const pk_homog_rve *rve, size_t nstep)
{
    memset(fr, 0, sizeof *fr);
    fr->dim = rve->dim;
    fr->n = rve->n;
    fr->keep =
        rve->n > 0 && nstep <= PK_HOMOG_FRAMES_MAX_STEPS && nstep <= PK_HOMOG_FRAMES_MAX / rve->n;
}

/* Σ_j |f_n,ij| per grain at s (the normal law of (4.3), E_n,ij per pair). */
static int grain_forces(const pk_homog_rve *rve, const pk_homog_opts *o, const pk_homog_state *s,
                        double *out)
{
    pk_dem_geom g = {.dim = rve->dim, .periodic = rve->periodic};
    memcpy(g.L, rve->L, sizeof g.L);
    pk_dem_geom_set_F(&g, s->F);
    pk_dem_pairs c = {0};
    pk_homog_pairs_setup(&c, rve, o);
    int rc = pk_dem_pairs_build(&c, &g, s->x, rve->r, rve->n, o->dr.skin);
    memset(out, 0, rve->n * sizeof *out);
    if (rc == 0) {
        pk_dem_eval(&c, &g, s->x, rve->r, rve->n, o->E_n, NULL, NULL, NULL);
        for (size_t p = 0; p < c.n; p++) {
            if (!(c.eps[p] >= 0) || !(c.len[p] > 0))
                continue;
            double f = o->E_n * (c.kf ? c.kf[p] : 1) * c.eps[p];
            out[c.i[p]] += f;
            out[c.j[p]] += f;
        }
    }
    pk_dem_pairs_free(&c);
    return rc;
}

int pk_homog_frames_add(pk_homog_frames *fr, const pk_homog_rve *rve, const pk_homog_opts *o,
                        const pk_homog_state *s, size_t k, size_t nstep)
{
    if (!fr->keep)
        return 0;
    const size_t n = fr->n, dim = (size_t)fr->dim;
    if (fr->count == fr->cap) {
        const size_t cap = pk_grow_cap(fr->cap, fr->count + 1, 8);
        const pk_grow_item arrays[] = {PK_GROW_ITEM(fr->step, 1), PK_GROW_ITEM(fr->time, 1),
                                       PK_GROW_ITEM(fr->x, n * dim), PK_GROW_ITEM(fr->force, n)};
        if (pk_grow(arrays, 4, cap) != 0)
            return -1;
        fr->cap = cap;
    }
    const size_t c = fr->count;
    fr->step[c] = (int64_t)k;
    fr->time[c] = (double)(k + 1) / (double)nstep;
    for (size_t i = 0; i < n; i++)
        for (size_t a = 0; a < dim; a++)
            fr->x[(c * n + i) * dim + a] = s->x[3 * i + a];
    if (grain_forces(rve, o, s, &fr->force[c * n]) != 0)
        return -1;
    fr->count++;
    return 0;
}

int pk_homog_frames_write(pk_h5 *h, const pk_homog_frames *fr, const pk_homog_rve *rve,
                          const pk_units *u)
{
    const char *unit = u->length[0] ? u->length : NULL;
    const size_t n = rve->n, c = fr->count;
    int rc = pk_h5_link(h, "/particles/grains/box", "/particles/rve/box");
    pk_h5_write_array(h, "/particles/rve/radius", PK_H5_F64, 1, &n, rve->r, unit);
    pk_h5_write_array(h, "/particles/rve/grain", PK_H5_I32, 1, &n, rve->grain, NULL);
    pk_h5_write_array(h, "/particles/rve/species", PK_H5_I32, 1, &n, rve->species, NULL);
    int64_t *id = malloc((n ? n : 1) * sizeof *id);
    if (!id)
        return -1;
    for (size_t i = 0; i < n; i++)
        id[i] = (int64_t)i;
    pk_h5_write_array(h, "/particles/rve/id", PK_H5_I64, 1, &n, id, NULL);
    free(id);
    if (!c)
        return rc ? -1 : 0;
    /* H5MD time-dependent elements: step, time (shared), value (the XDMF
     * sidecar reads a step as a row of value, by its byte offset) */
    size_t dx[3] = {c, n, (size_t)fr->dim}, df[2] = {c, n};
    pk_h5_time_element(h, "/particles/rve/position", NULL, fr->step, fr->time, NULL, PK_H5_F64, 3,
                       dx, fr->x, unit);
    pk_h5_time_element(h, "/particles/rve/contact_force", "/particles/rve/position", NULL, NULL,
                       NULL, PK_H5_F64, 2, df, fr->force, "N");
    return rc ? -1 : 0;
}

void pk_homog_frames_free(pk_homog_frames *fr)
{
    free(fr->step);
    free(fr->time);
    free(fr->x);
    free(fr->force);
    memset(fr, 0, sizeof *fr);
}
