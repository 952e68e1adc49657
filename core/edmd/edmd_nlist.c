/* edmd_nlist.c — Donev-style neighbour lists for growing grains.
 * Contract: the edmd_nlist_* declarations in core/edmd/edmd_state.h.
 *
 * At its build time particle i gets a bounding sphere (centre c_i = x_i,
 * radius σ_i = ρ_i + s_i/2); j is in i's list iff the bounding spheres
 * overlap.  Spheres inside disjoint bounding spheres cannot touch, so the
 * lists stay exact while every grain stays inside its sphere; the exit time
 * (motion AND growth) is a per-particle event, after which only that grain's
 * sphere and list are rebuilt (symmetrically).  σ_i uses at least the
 * grain's target radius, so early (small, fast) grains rebuild rarely.  The
 * bounding spheres live in levels of dense cell lists (core/space/grid_uniform.h:
 * pk_grid's levels without its hash probes — the rebuild queries were a
 * third of the run time), so wide size ratios cost O(1) cells per query;
 * the small grains read the coarse levels from its cover (one cell). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "edmd_state.h"

/* Offset of a ballistic grain's new sphere centre, as a fraction of its room
 * (bench/edmd: fewer rebuilds in the dilute phase of a zero start). */
#ifndef EDMD_AHEAD
#define EDMD_AHEAD 0.75
#endif

/* Free entries a slot gets beyond its list: a few gained neighbours before
 * the list moves to the pool's end. */
static uint32_t slot_cap(uint32_t n) { return n + n / 4 + 4; }

/* Room for extra more entries at the pool's end: compacts the slots in
 * grain order when at least half the pool is dead (abandoned slots), grows
 * it otherwise.  Offsets change, contents do not. */
static int pool_reserve(edmd_state *s, size_t extra)
{
    if (s->nl_used + extra <= s->nl_size)
        return 0;
    size_t size = s->nl_size;
    const int compact = s->nl_used - s->nl_live >= s->nl_used / 2;
    if (!compact || s->nl_live + extra > size)
        size = 2 * size > s->nl_live + extra + 16 ? 2 * size : s->nl_live + extra + 16;
    if (size > UINT32_MAX)
        return -1;
    int32_t *pool = malloc(size * sizeof *pool);
    edmd_big_hint(pool, size * sizeof *pool); /* (not touched yet) */
    if (!pool)
        return -1;
    size_t used = 0;
    for (size_t i = 0; i < s->n; i++) {
        edmd_nlist *L = &s->nl[i];
        if (L->cap)
            memcpy(pool + used, s->nl_pool + L->off, L->n * sizeof *pool);
        L->off = (uint32_t)used;
        used += L->cap;
    }
    free(s->nl_pool);
    s->nl_pool = pool;
    s->nl_size = size;
    s->nl_used = s->nl_live = used;
    return 0;
}

/* i's list (its n entries) into a new slot of cap entries at the pool's end. */
static int slot_move(edmd_state *s, size_t i, uint32_t cap)
{
    if (pool_reserve(s, cap) != 0)
        return -1;
    edmd_nlist *L = &s->nl[i];
    const uint32_t off = (uint32_t)s->nl_used;
    memcpy(s->nl_pool + off, s->nl_pool + L->off, L->n * sizeof *s->nl_pool);
    s->nl_live += cap - L->cap;
    s->nl_used += cap;
    L->off = off;
    L->cap = cap;
    return 0;
}

/* j appended to i's list. */
static int push(edmd_state *s, size_t i, int32_t j)
{
    edmd_nlist *L = &s->nl[i];
    if (L->n == L->cap && slot_move(s, i, 2 * L->cap + 4) != 0)
        return -1;
    s->nl_pool[L->off + L->n++] = j;
    return 0;
}

static void drop(edmd_state *s, size_t i, int32_t j)
{
    edmd_nlist *L = &s->nl[i];
    int32_t *nb = s->nl_pool + L->off;
    for (uint32_t q = 0; q < L->n; q++)
        if (nb[q] == j) {
            nb[q] = nb[--L->n];
            return;
        }
}

/* j appended to the list being rebuilt (s->nl_new, *n entries). */
static int push_new(edmd_state *s, uint32_t *n, int32_t j)
{
    if (*n == s->nl_new_cap) {
        uint32_t cap = s->nl_new_cap ? 2 * s->nl_new_cap : 64;
        int32_t *nb = realloc(s->nl_new, cap * sizeof *nb);
        if (!nb)
            return -1;
        s->nl_new = nb;
        s->nl_new_cap = cap;
    }
    s->nl_new[(*n)++] = j;
    return 0;
}

/* The rebuilt list (nl_new, n entries) becomes i's: in its slot when it
 * fits, in a new one otherwise. */
static int store_new(edmd_state *s, size_t i, uint32_t n)
{
    edmd_nlist *L = &s->nl[i];
    if (n > L->cap) {
        L->n = 0; /* nothing to carry over */
        if (slot_move(s, i, slot_cap(n)) != 0)
            return -1;
    }
    if (n)
        memcpy(s->nl_pool + L->off, s->nl_new, n * sizeof *s->nl_new);
    L->n = n;
    return 0;
}

typedef struct visit_ctx {
    edmd_state *s;
    int32_t self;
    uint32_t n;   /* entries in s->nl_new */
    uint32_t tag; /* rebuilds: mark of i's old neighbours; tag + 1: kept */
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
    if (push_new(c->s, &c->n, (int32_t)j) != 0) {
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
        s->nl[i] = (edmd_nlist){0, 0, 0};
    }
    s->nl_used = s->nl_live = 0; /* the slots are laid out anew, in grain order */
    if (pool_reserve(s, 16) != 0)
        return -1;
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
        visit_ctx c = {s, (int32_t)i, 0, 0, 0};
        pk_ugrid_query(&s->ugrid, &s->bs, &s->bs.x[3 * i], s->bs.r[i], visit, &c);
        if (c.failed || store_new(s, i, c.n) != 0)
            return -1;
    }
    return 0;
}

/* A neighbour j found by i's new query: kept (already in i's old list, so
 * i is in j's list: j's list is not touched) or new (i goes into j's list). */
static int visit_rebuild(size_t j, const double dx[PK_MAXDIM], double dist2, void *ctx)
{
    (void)dx;
    (void)dist2;
    visit_ctx *c = ctx;
    if ((int32_t)j == c->self)
        return 0;
    uint32_t *mark = &c->s->nl_mark[j];
    int fail = push_new(c->s, &c->n, (int32_t)j);
    if (*mark == c->tag)
        *mark = c->tag + 1;
    else
        fail |= push(c->s, j, c->self);
    if (fail) {
        c->failed = 1;
        return 1;
    }
    return 0;
}

/* i's list anew; the lists stay symmetric by touching only the lists of
 * the neighbours i gains or loses (not every old neighbour's: L2 misses).
 * i's old list stays in its slot until the new one (built in nl_new)
 * replaces it. */
int edmd_nlist_rebuild(edmd_state *s, size_t i)
{
    if (s->nl_tag > UINT32_MAX - 2) { /* tags used up: clear the marks */
        memset(s->nl_mark, 0, s->n * sizeof *s->nl_mark);
        s->nl_tag = 0;
    }
    s->nl_tag += 2;
    const uint32_t tag = s->nl_tag;
    const int32_t *old = s->nl_pool + s->nl[i].off;
    for (uint32_t q = 0; q < s->nl[i].n; q++)
        s->nl_mark[old[q]] = tag;
    edmd_sync(s, i);
    set_sphere(s, i, s->ncoll[i] == s->ncoll_nl[i] ? EDMD_AHEAD : 0);
    visit_ctx c = {s, (int32_t)i, 0, tag, 0};
    if (pk_ugrid_insert(&s->ugrid, &s->bs, i) != 0) /* re-files i (new level/cell) */
        c.failed = 1;
    else
        pk_ugrid_query(&s->ugrid, &s->bs, &s->bs.x[3 * i], s->bs.r[i], visit_rebuild, &c);
    old = s->nl_pool + s->nl[i].off;          /* the pushes may have moved the slots */
    for (uint32_t q = 0; q < s->nl[i].n; q++) /* lost neighbours */
        if (s->nl_mark[old[q]] == tag)
            drop(s, (size_t)old[q], (int32_t)i);
    if (c.failed || store_new(s, i, c.n) != 0)
        return -1;
    return 0;
}

void edmd_nlist_free(edmd_state *s)
{
    free(s->nl);
    s->nl = NULL;
    free(s->nl_pool);
    s->nl_pool = NULL;
    s->nl_used = s->nl_size = s->nl_live = 0;
    free(s->nl_new);
    s->nl_new = NULL;
    s->nl_new_cap = 0;
    free(s->nl_mark);
    s->nl_mark = NULL;
    pk_ugrid_free(&s->ugrid);
    pk_particles_free(&s->bs);
}
