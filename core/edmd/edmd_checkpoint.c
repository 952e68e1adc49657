/* edmd_checkpoint.c — copy an EDMD run's state out and back in
 * (core/edmd/edmd_checkpoint.h). */
#include "edmd_checkpoint.h"

#include <stdlib.h>
#include <string.h>

#include "edmd_state.h"

int pk_edmd_snapshot_alloc(pk_edmd_snapshot *s, size_t n, int dim)
{
    memset(s, 0, sizeof *s);
    s->n = n;
    s->dim = dim;
    s->kin = malloc((n ? n : 1) * PK_EDMD_SNAP_KIN * sizeof *s->kin);
    s->perm = malloc((n ? n : 1) * sizeof *s->perm);
    if (!s->kin || !s->perm) {
        pk_edmd_snapshot_free(s);
        return -1;
    }
    return 0;
}

void pk_edmd_snapshot_free(pk_edmd_snapshot *s)
{
    free(s->kin);
    free(s->perm);
    s->kin = NULL;
    s->perm = NULL;
}

int edmd_checkpoint_due(pk_edmd_checkpoint *c)
{
    if (!c || !(c->interval_s > 0) || !c->save)
        return 0;
    double now = pk_wall_seconds();
    if (c->last_s == 0)
        c->last_s = now; /* the first call starts the clock */
    return now - c->last_s >= c->interval_s;
}

void edmd_checkpoint_take(const edmd_state *s, const size_t *perm, const pk_edmd_stats *st,
                          const edmd_ckpt_loop *l, pk_edmd_checkpoint *c)
{
    pk_edmd_snapshot snap;
    c->last_s = pk_wall_seconds();
    if (pk_edmd_snapshot_alloc(&snap, s->n, s->dim) != 0) {
        c->save_failures++;
        return;
    }
    for (size_t i = 0; i < s->n; i++) {
        const edmd_kin *k = &s->k[i];
        double *o = &snap.kin[PK_EDMD_SNAP_KIN * i];
        o[0] = k->p[0], o[1] = k->p[1], o[2] = k->p[2], o[3] = k->a;
        o[4] = k->v[0], o[5] = k->v[1], o[6] = k->v[2], o[7] = k->g;
        snap.perm[i] = (int64_t)perm[i];
    }
    /* (the caller re-based: s->t = 0, flights and shell start at t_base) */
    snap.scal[PK_EDMD_SNAP_T_BASE] = l->t_base;
    snap.scal[PK_EDMD_SNAP_H0] = s->h0;
    snap.scal[PK_EDMD_SNAP_H1] = s->h1;
    snap.scal[PK_EDMD_SNAP_K0] = l->K0;
    snap.scal[PK_EDMD_SNAP_PRESSURE] = l->pressure;
    snap.scal[PK_EDMD_SNAP_SKIN_SCALE] = s->skin_scale;
    snap.scal[PK_EDMD_SNAP_MAX_OVERLAP] = s->max_overlap_rel;
    snap.scal[PK_EDMD_SNAP_FRACTION] = l->fraction;
    snap.scal[PK_EDMD_SNAP_GROWTH_RATE] = l->growth_rate;
    const uint64_t cnt[PK_EDMD_SNAP_NCNT] = {[PK_EDMD_SNAP_EVENTS] = st->events,
                                             [PK_EDMD_SNAP_PAIR] = st->pair,
                                             [PK_EDMD_SNAP_WALL] = st->wall,
                                             [PK_EDMD_SNAP_NLIST] = st->nlist,
                                             [PK_EDMD_SNAP_INVALID] = st->invalid,
                                             [PK_EDMD_SNAP_RESCALES] = st->rescales,
                                             [PK_EDMD_SNAP_REBASES] = st->rebases,
                                             [PK_EDMD_SNAP_OVERLAPS] = s->n_overlap,
                                             [PK_EDMD_SNAP_RESORTS] = st->resorts,
                                             [PK_EDMD_SNAP_SECOND] = st->second,
                                             [PK_EDMD_SNAP_HIST_STRIDE] = l->hist_stride,
                                             [PK_EDMD_SNAP_HIST_COUNT] = l->hist_count,
                                             [PK_EDMD_SNAP_SLOWED] = (uint64_t)l->slowed,
                                             [PK_EDMD_SNAP_GROWTH_CHANGES] = st->growth_changes};
    for (int k = 0; k < PK_EDMD_SNAP_NCNT; k++)
        snap.cnt[k] = (int64_t)cnt[k];
    snap.nhist = st->nhist;
    memcpy(snap.hist[0], st->hist_events, st->nhist * sizeof(double));
    memcpy(snap.hist[1], st->hist_t, st->nhist * sizeof(double));
    memcpy(snap.hist[2], st->hist_phi, st->nhist * sizeof(double));
    memcpy(snap.hist[3], st->hist_p, st->nhist * sizeof(double));
    if (c->save(&snap, c->ctx) == 0)
        c->saved++;
    else
        c->save_failures++;
    pk_edmd_snapshot_free(&snap);
}

int edmd_checkpoint_perm(const pk_edmd_snapshot *r, size_t n, int dim, size_t *perm)
{
    if (!r || r->n != n || r->dim != dim || r->nhist > PK_EDMD_HIST_MAX)
        return -1;
    unsigned char *seen = calloc(n ? n : 1, 1);
    if (!seen)
        return -1;
    int rc = 0;
    for (size_t i = 0; i < n && rc == 0; i++) {
        int64_t g = r->perm[i];
        if (g < 0 || (uint64_t)g >= n || seen[g])
            rc = -1;
        else
            seen[g] = 1, perm[i] = (size_t)g;
    }
    free(seen);
    return rc;
}

void edmd_checkpoint_restore(edmd_state *s, pk_edmd_stats *st, edmd_ckpt_loop *l,
                             pk_edmd_checkpoint *c)
{
    const pk_edmd_snapshot *r = c->resume;
    for (size_t i = 0; i < s->n; i++) {
        edmd_kin *k = &s->k[i];
        const double *o = &r->kin[PK_EDMD_SNAP_KIN * i];
        k->p[0] = o[0], k->p[1] = o[1], k->p[2] = o[2], k->a = o[3];
        k->v[0] = o[4], k->v[1] = o[5], k->v[2] = o[6], k->g = o[7];
    }
    s->t = 0;
    s->h0 = r->scal[PK_EDMD_SNAP_H0];
    s->h1 = r->scal[PK_EDMD_SNAP_H1];
    s->skin_scale = r->scal[PK_EDMD_SNAP_SKIN_SCALE];
    s->max_overlap_rel = r->scal[PK_EDMD_SNAP_MAX_OVERLAP];
    s->n_overlap = (uint64_t)r->cnt[PK_EDMD_SNAP_OVERLAPS];
    l->t_base = r->scal[PK_EDMD_SNAP_T_BASE];
    l->K0 = r->scal[PK_EDMD_SNAP_K0];
    l->pressure = r->scal[PK_EDMD_SNAP_PRESSURE];
    l->fraction = r->scal[PK_EDMD_SNAP_FRACTION];
    l->hist_stride = (uint64_t)r->cnt[PK_EDMD_SNAP_HIST_STRIDE];
    l->hist_count = (uint64_t)r->cnt[PK_EDMD_SNAP_HIST_COUNT];
    l->growth_rate = r->scal[PK_EDMD_SNAP_GROWTH_RATE];
    l->slowed = r->cnt[PK_EDMD_SNAP_SLOWED] == 2 ? 2 : r->cnt[PK_EDMD_SNAP_SLOWED] != 0;
    st->growth_changes = (uint64_t)r->cnt[PK_EDMD_SNAP_GROWTH_CHANGES];
    if (l->hist_stride < 1)
        l->hist_stride = 1;
    st->events = (uint64_t)r->cnt[PK_EDMD_SNAP_EVENTS];
    st->pair = (uint64_t)r->cnt[PK_EDMD_SNAP_PAIR];
    st->wall = (uint64_t)r->cnt[PK_EDMD_SNAP_WALL];
    st->nlist = (uint64_t)r->cnt[PK_EDMD_SNAP_NLIST];
    st->invalid = (uint64_t)r->cnt[PK_EDMD_SNAP_INVALID];
    st->rescales = (uint64_t)r->cnt[PK_EDMD_SNAP_RESCALES];
    st->rebases = (uint64_t)r->cnt[PK_EDMD_SNAP_REBASES];
    st->resorts = (uint64_t)r->cnt[PK_EDMD_SNAP_RESORTS];
    st->second = (uint64_t)r->cnt[PK_EDMD_SNAP_SECOND];
    st->nhist = r->nhist;
    memcpy(st->hist_events, r->hist[0], r->nhist * sizeof(double));
    memcpy(st->hist_t, r->hist[1], r->nhist * sizeof(double));
    memcpy(st->hist_phi, r->hist[2], r->nhist * sizeof(double));
    memcpy(st->hist_p, r->hist[3], r->nhist * sizeof(double));
    c->resumed = 1;
    c->resumed_events = st->events;
    c->resumed_time = l->t_base;
}
