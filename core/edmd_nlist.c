/* edmd_nlist.c — Donev-style neighbour lists for growing grains (spec §3.3c).
 *
 * At its build time particle i gets a bounding sphere (centre c_i = x_i,
 * radius σ_i = ρ_i + s_i/2); j is in i's list iff the bounding spheres
 * overlap.  Spheres inside disjoint bounding spheres cannot touch, so the
 * lists stay exact while every grain stays inside its sphere; the exit time
 * (motion AND growth) is a per-particle event, after which only that grain's
 * sphere and list are rebuilt (symmetrically).  σ_i uses at least the
 * grain's target radius, so early (small, fast) grains rebuild rarely.  The
 * bounding spheres live in levels of dense cell lists (core/grid_uniform.h:
 * pk_grid's levels without its hash probes — the rebuild queries were a
 * third of the run time), so wide size ratios cost O(1) cells per query. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "edmd_state.h"

/* Offset of a ballistic grain's new sphere centre, as a fraction of its room
 * (bench/edmd: fewer rebuilds in the dilute phase of a zero start). */
#ifndef EDMD_AHEAD
#define EDMD_AHEAD 0.75
#endif

static int push(edmd_nlist *L, int32_t j)
{
    if (L->n == L->cap) {
        uint32_t cap = L->cap ? 2 * L->cap : 16;
        int32_t *nb = realloc(L->nb, cap * sizeof *nb);
        if (!nb)
            return -1;
        L->nb = nb;
        L->cap = cap;
    }
    L->nb[L->n++] = j;
    return 0;
}

static void drop(edmd_nlist *L, int32_t j)
{
    for (uint32_t q = 0; q < L->n; q++)
        if (L->nb[q] == j) {
            L->nb[q] = L->nb[--L->n];
            return;
        }
}

typedef struct visit_ctx {
    edmd_state *s;
    int32_t self;
    int failed;
} visit_ctx;

/* Full builds: every grain queries for itself (one-sided pushes). */
static int visit(size_t j, const double dx[PK_MAXDIM], double dist2, void *ctx)
{
    (void)dx;
    (void)dist2;
    visit_ctx *c = ctx;
    if ((int32_t)j == c->self)
        return 0;
    if (push(&c->s->nl[c->self], (int32_t)j) != 0) {
        c->failed = 1;
        return 1;
    }
    return 0;
}

/* Bounding sphere of i at the current time (i synced).  A grain that made
 * no collision since its last build flies ballistically (dilute phase): its
 * sphere is centred AHEAD along its velocity, by a fraction of the room
 * σ − ρ, so a straight flight crosses (1 + ahead)·room instead of room
 * before the next rebuild.  The grain stays strictly inside (ahead < 1), so
 * the list stays exact (the exit event is computed from the offset centre). */
static void set_sphere(edmd_state *s, size_t i, double ahead)
{
    const double rho = edmd_rho(s, i, s->t);
    /* never smaller than the grain at its reference (target) size: while
     * grains are small and far apart the lists then last much longer */
    const double sig = (rho > s->rref[i] ? rho : s->rref[i]) + 0.5 * s->skin_scale * s->skin[i];
    const double *v = s->k[i].v;
    double x[3];
    edmd_pos(s, i, x);
    double speed = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    double shift = speed > 0 ? ahead * (sig - rho) / speed : 0;
    for (int k = 0; k < 3; k++)
        s->bs.x[3 * i + k] = x[k] + shift * v[k];
    edmd_wrap_near(s, &s->bs.x[3 * i]);
    s->bs.r[i] = sig;
    s->ncoll_nl[i] = s->ncoll[i];
}

int edmd_nlist_build_all(edmd_state *s)
{
    for (size_t i = 0; i < s->n; i++) {
        edmd_sync(s, i);
        set_sphere(s, i, 0);
        s->nl[i].n = 0;
    }
    s->bs.n = s->n;
    pk_ugrid_free(&s->ugrid);
    if (pk_ugrid_init(&s->ugrid, &s->box, s->bs.r, s->n, s->n) != 0)
        return -1;
    /* file everyone first, then query (the lists are built one-sided) */
    for (size_t i = 0; i < s->n; i++)
        if (pk_ugrid_insert(&s->ugrid, &s->bs, i) != 0)
            return -1;
    for (size_t i = 0; i < s->n; i++) {
        if ((i & 0x3fff) == 0 && s->mon && (s->stop = pk_monitor_tick(s->mon, s->pr, 0)) != 0)
            return 1; /* cancel within a second also at 10⁶ grains */
        visit_ctx c = {s, (int32_t)i, 0};
        pk_ugrid_query(&s->ugrid, &s->bs, &s->bs.x[3 * i], s->bs.r[i], visit, &c);
        if (c.failed)
            return -1;
    }
    return 0;
}

/* A neighbour j found by i's new query: kept (already in i's old list, so
 * i is in j's list: j's list is not touched) or new (i goes into j's list). */
typedef struct rebuild_ctx {
    edmd_state *s;
    int32_t self;
    uint32_t tag;             /* mark of i's old neighbours; tag + 1: kept */
    int failed;
} rebuild_ctx;

static int visit_rebuild(size_t j, const double dx[PK_MAXDIM], double dist2, void *ctx)
{
    (void)dx;
    (void)dist2;
    rebuild_ctx *c = ctx;
    if ((int32_t)j == c->self)
        return 0;
    uint32_t *mark = &c->s->nl_mark[j];
    int fail = push(&c->s->nl[c->self], (int32_t)j);
    if (*mark == c->tag)
        *mark = c->tag + 1;
    else
        fail |= push(&c->s->nl[j], c->self);
    if (fail) {
        c->failed = 1;
        return 1;
    }
    return 0;
}

/* i's list anew; the lists stay symmetric by touching only the lists of
 * the neighbours i gains or loses (most are kept: each list is its own
 * block, so each touch is a cache miss — mono 3D N = 10^4 to φ = 0.6: the
 * drop loop over all old neighbours was a fifth of the L2 misses). */
int edmd_nlist_rebuild(edmd_state *s, size_t i)
{
    if (s->nl_tag > UINT32_MAX - 2) { /* tags used up: clear the marks */
        memset(s->nl_mark, 0, s->n * sizeof *s->nl_mark);
        s->nl_tag = 0;
    }
    s->nl_tag += 2;
    const uint32_t tag = s->nl_tag;
    edmd_nlist old = s->nl[i]; /* i's list is built in the spare block */
    s->nl[i] = s->nl_spare;
    s->nl[i].n = 0;
    for (uint32_t q = 0; q < old.n; q++)
        s->nl_mark[old.nb[q]] = tag;
    edmd_sync(s, i);
    set_sphere(s, i, s->ncoll[i] == s->ncoll_nl[i] ? EDMD_AHEAD : 0);
    rebuild_ctx c = {s, (int32_t)i, tag, 0};
    if (pk_ugrid_insert(&s->ugrid, &s->bs, i) != 0) /* re-files i (new level/cell) */
        c.failed = 1;
    else
        pk_ugrid_query(&s->ugrid, &s->bs, &s->bs.x[3 * i], s->bs.r[i], visit_rebuild, &c);
    for (uint32_t q = 0; q < old.n; q++) /* lost neighbours */
        if (s->nl_mark[old.nb[q]] == tag)
            drop(&s->nl[old.nb[q]], (int32_t)i);
    old.n = 0;
    s->nl_spare = old;
    return c.failed ? -1 : 0;
}

void edmd_nlist_free(edmd_state *s)
{
    if (s->nl)
        for (size_t i = 0; i < s->n; i++)
            free(s->nl[i].nb);
    free(s->nl);
    s->nl = NULL;
    free(s->nl_spare.nb);
    s->nl_spare = (edmd_nlist){0};
    free(s->nl_mark);
    s->nl_mark = NULL;
    pk_ugrid_free(&s->ugrid);
    pk_particles_free(&s->bs);
}
