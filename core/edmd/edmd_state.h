/* edmd_state.h — the EDMD engine's internal state, shared by core/edmd/edmd*.c
 * (not part of the public contract, core/edmd/edmd.h).
 * Each grain's flight is one 64-byte record (one cache line: a prediction
 * reads one line per neighbour): position at time t is p + v·t — p is the
 * position extrapolated back to the re-based origin t = 0, so no per-grain
 * sync time is stored (delayed states; the clock is re-based every window so
 * |v·t| stays small against L) — simulated radius a + g·t, true radius that
 * minus the shell h0 + h1·t. */
#ifndef PK_EDMD_STATE_H
#define PK_EDMD_STATE_H

#include "edmd.h"
#include "core/space/grid.h"
#include "core/space/grid_uniform.h"

/* Who an event is with: a grain j >= 0, nobody, the grain's bounding
 * sphere (neighbour list), or a wall EDMD_EV_WALL0 − code (code = 2k + side). */
enum { EDMD_EV_NONE = -1, EDMD_EV_NLIST = -2, EDMD_EV_WALL0 = -3 };

/* A grain's pending event and its runner-up (Donev): when the partner of
 * the first changes course before it, the second is still a lower bound of
 * every collision with the unchanged neighbours (a changed one re-predicted
 * with this grain in its list), so it is taken without a new prediction. */
typedef struct edmd_event {
    double t, t2;           /* event times; t2 = +inf when there is no second */
    int32_t with, with2;    /* EDMD_EV_* or the partner grain */
    uint32_t stamp, stamp2; /* partner's ncoll at prediction time */
} edmd_event;
_Static_assert(sizeof(edmd_event) == 32, "two events per cache line");

/* A grain's neighbour list: a slot nl_pool[off .. off + cap) of the one
 * pool (CSR with slack), n of it used.  A full build lays the slots out in
 * grain order, so a prediction streams its list and the next grain's list
 * is in the next lines; a list that outgrows its slot moves to the pool's
 * end (edmd_nlist.c).  No per-list malloc header or power-of-two capacity
 * (measurements: docs/perf/edmd.md). */
typedef struct edmd_nlist {
    uint32_t off, n, cap;
} edmd_nlist;

typedef struct edmd_kin {
    double p[3]; /* position at t = 0 of the current flight */
    double a;    /* simulated radius at t = 0 */
    double v[3]; /* velocity (0 beyond dim) */
    double g;    /* radius growth rate */
} edmd_kin;
_Static_assert(sizeof(edmd_kin) == 64,
               "one cache line per grain (aligned_alloc needs a multiple of 64)");

typedef struct edmd_hnode {
    double t;  /* event time (copy of ev_t[i]) */
    int32_t i; /* particle */
} edmd_hnode;
_Static_assert(sizeof(edmd_hnode) == 16, "four heap nodes per cache line");

/* A grain's place in the event queue, one record (four a cache line: an
 * event reads one line for the grain, not one per field; a grain's slot is
 * that of its event time, recomputed where needed). */
typedef struct edmd_qnode {
    int32_t nxt, prv; /* bucket list links (-1: none) */
    int32_t where;    /* bucket, or Q_HEAP / Q_OVER (edmd_queue.c) */
    int32_t hpos;     /* node in the heap */
} edmd_qnode;
_Static_assert(sizeof(edmd_qnode) == 16, "four queue records per cache line");

/* The event queue (edmd_queue.c): a calendar of time slots after Paul
 * (2007, J. Comput. Phys. 221, 615).  Slot of time t: floor((t − T0)/w).
 * The events of the current slot sit in a small 4-ary heap; those of the
 * next slots up to lap_end in unsorted bucket lists (bucket = slot mod nb),
 * later ones in an overflow list, redistributed when a lap starts. */
typedef struct edmd_queue {
    double T0, inv_w;  /* slot origin and 1/width */
    int64_t cur;       /* current slot: its events are in the heap */
    int64_t lap_end;   /* first slot not in the buckets (<= cur + nb) */
    uint32_t nb, mask; /* buckets: a power of two */
    int32_t *head;     /* [nb + 1] first grain of each bucket's list; [nb]: overflow */
    uint64_t *occ;     /* [nb / 64] bucket holds a grain */
    edmd_qnode *node;  /* [n] each grain's links and place */
    edmd_hnode *heap;  /* current slot's events (4-ary, heap_mem + 3) */
    edmd_hnode *heap_mem;
    size_t hn;
    double *sample; /* scratch of the width estimate */
} edmd_queue;

typedef struct edmd_state {
    pk_box box;
    double Lp[3], inv_Lp[3]; /* L and 1/L on periodic axes, 0 otherwise (pk_min_image3) */
    int dim;
    int walled; /* some axis < dim has walls */
    size_t n;
    /* kinematics */
    edmd_kin *k;       /* [n], 64-byte aligned */
    double *m;         /* mass */
    double h0, h1;     /* shell h(t) = h0 + h1 t */
    double t;          /* current time (re-based) */
    double eps_v;      /* extra separation speed (a grazing pair separates) */
    pk_edmd_rule rule; /* pair (and wall) collision rule */
    /* events: one (and a runner-up) per particle, 32-byte aligned */
    edmd_event *ev;
    uint32_t *ncoll; /* velocity changes of each particle (validity counter) */
    edmd_queue q;
    /* neighbour lists */
    edmd_nlist *nl;          /* [n] slots in nl_pool */
    int32_t *nl_pool;        /* every list, in slots */
    size_t nl_used, nl_size; /* pool entries handed out / allocated */
    size_t nl_live;          /* Σ cap of the slots in use (the rest is dead) */
    int32_t *nl_new;         /* the list being rebuilt, before it goes in a slot */
    uint32_t nl_new_cap;
    uint32_t *nl_mark; /* [n] rebuild marks (edmd_nlist_rebuild) */
    uint32_t nl_tag;
    pk_particles bs;    /* bounding spheres: centre c_i, radius σ_i */
    pk_ugrid ugrid;     /* cells of the bounding spheres */
    double *skin;       /* per-particle skin s_i (at low pressure) */
    double skin_scale;  /* skins shrink with the cages as the pressure rises */
    double *rref;       /* radius at the reference time (target size) */
    uint32_t *ncoll_nl; /* ncoll[i] at i's last list build (ballistic test) */
    /* physics accumulators */
    double K;      /* kinetic energy ½Σm v² */
    double virial; /* Σ σ J over particle collisions in the window */
    double kint;   /* ∫K dt over the window */
    uint64_t n_overlap;
    /* the run's monitor, ticked inside full list builds (~1 s at 10⁶ grains);
     * NULL during the start-up build */
    pk_monitor *mon;
    pk_progress *pr;
    int stop; /* what the monitor said: 1 cancelled, 2 wall limit */
    double max_overlap_rel;
} edmd_state;

/* Minimum image of a displacement along the periodic axes (branch-free,
 * core/space/grid_uniform.h). */
static inline void edmd_min_image_near(const edmd_state *s, double d[3])
{
    pk_min_image3(s->Lp, s->inv_Lp, d);
}

/* x back into [0, L) on the periodic axes when it is less than a period
 * outside (bounding-sphere centres: a grain plus a fraction of its room);
 * pk_box_wrap (floor, division) otherwise. */
static inline void edmd_wrap_near(const edmd_state *s, double x[3])
{
    for (int d = 0; d < 3; d++) {
        const double L = s->Lp[d];
        if (L > 0) {
            if (x[d] < 0)
                x[d] += L;
            if (x[d] >= L)
                x[d] -= L;
            if (!(x[d] >= 0 && x[d] < L)) {
                pk_box_wrap(&s->box, x);
                return;
            }
        }
    }
}

/* Position of i now. */
static inline void edmd_pos(const edmd_state *s, size_t i, double x[3])
{
    const edmd_kin *k = &s->k[i];
    for (int d = 0; d < 3; d++)
        x[d] = k->p[d] + k->v[d] * s->t;
}

/* Simulated radius of i at time t. */
static inline double edmd_rho(const edmd_state *s, size_t i, double t)
{
    return s->k[i].a + s->k[i].g * t;
}

/* After i's velocity changed now: keep its position x now. */
static inline void edmd_pin(edmd_state *s, size_t i, const double x[3])
{
    edmd_kin *k = &s->k[i];
    for (int d = 0; d < 3; d++)
        k->p[d] = x[d] - k->v[d] * s->t;
}

/* Moves p by whole periods so that x(t) is in [0, L) on periodic axes (a
 * grain flies less than L between two syncs: its list sphere is smaller),
 * and returns that position x(t) = p + v·t. */
static inline void edmd_sync_pos(edmd_state *s, size_t i, double x[3])
{
    /* one test for the common case (every axis inside), bitwise & without
     * branches; same results as the per-axis loop (docs/perf/edmd.md) */
    edmd_kin *k = &s->k[i];
    const double t = s->t;
    const double x0 = k->p[0] + k->v[0] * t, x1 = k->p[1] + k->v[1] * t, x2 = k->p[2] + k->v[2] * t;
    x[0] = x0;
    x[1] = x1;
    x[2] = x2;
    const double *L = s->Lp;
    if (((L[0] <= 0) | ((x0 >= 0) & (x0 < L[0]))) & ((L[1] <= 0) | ((x1 >= 0) & (x1 < L[1]))) &
        ((L[2] <= 0) | ((x2 >= 0) & (x2 < L[2]))))
        return;
    for (int d = 0; d < 3; d++) {
        if (L[d] > 0 && !(x[d] >= 0 && x[d] < L[d])) {
            k->p[d] += x[d] < 0 ? L[d] : -L[d];
            x[d] = k->p[d] + k->v[d] * t;
        }
    }
}

static inline void edmd_sync(edmd_state *s, size_t i)
{
    double x[3];
    edmd_sync_pos(s, i, x);
}

/* edmd_mem.c: per-grain arrays, zeroed and 64-byte aligned (free()); from
 * 4 MB on on 2 MB pages where the system offers them. */
void *edmd_big_calloc(size_t n, size_t size);
/* The same advice for an array allocated elsewhere, before its first touch. */
void edmd_big_hint(void *p, size_t bytes);

/* edmd_predict.c */
void edmd_predict(edmd_state *s, size_t i); /* refresh i's event and heap slot */
/* Start loading the records of i's neighbours (before a collision: both
 * grains' predictions then find them in cache). */
void edmd_prefetch_list(const edmd_state *s, size_t i);
/* Start loading i's own records (flight, event, list slot, sphere, queue
 * links): one event ahead of its turn. */
void edmd_prefetch_grain(const edmd_state *s, size_t i);
/* Test hook: 1 = the neighbour loop runs scalar even where AVX2 lanes are
 * available (the lanes must give bit-identical events). */
extern int edmd_scalar_only;
int edmd_lanes_available(void);  /* AVX2 lanes in use now */
extern int edmd_lanes4_only;     /* 1: the AVX2 loop even where AVX-512 is there */
int edmd_lanes8_available(void); /* AVX-512 lanes in use now */
double edmd_wall_time(const edmd_state *s, size_t i, int *code);

/* edmd_collide.c */
double edmd_collide_pair(edmd_state *s, size_t i, size_t j); /* returns σ·J */
void edmd_collide_wall(edmd_state *s, size_t i, int code);

/* edmd_queue.c */
int edmd_queue_alloc(edmd_state *s, size_t n); /* 0 or -1 */
void edmd_queue_free(edmd_state *s);
void edmd_queue_init(edmd_state *s);               /* every ev[i] anew (slots sized here) */
size_t edmd_queue_top(edmd_state *s);              /* the grain of the earliest event */
int32_t edmd_queue_runner_up(const edmd_state *s); /* likely next grain after the top, or -1 */
void edmd_queue_update(edmd_state *s, size_t i);   /* after ev[i].t changed */
void edmd_queue_shift(edmd_state *s, double dt);   /* all times −= dt */

/* edmd_order.c: perm[k] = index of the k-th grain along a Z-order curve of
 * cells of edge h.  0 or -1 (out of memory). */
int edmd_spatial_order(const pk_box *b, const double *x, size_t n, double h, size_t *perm);
/* Renumber the grains along the Z-order of their positions now (cells of
 * edge h), perm (engine index → caller's grain) with them.  Neighbour lists,
 * bounding spheres and events are not carried over: the caller rebuilds
 * them.  0 or -1 (out of memory). */
int edmd_reorder(edmd_state *s, size_t *perm, double h);

/* edmd_nlist.c */
/* Every list from scratch: 0, -1 out of memory, or 1 when the monitor (if
 * set) stopped the run part-way (s->stop; the lists are then unusable). */
int edmd_nlist_build_all(edmd_state *s);
int edmd_nlist_rebuild(edmd_state *s, size_t i);
void edmd_nlist_free(edmd_state *s);

/* Event-time roots (edmd_predict.c; tested on their own in test_edmd). */

/* Time τ ≥ 0 until |Δp + Δv τ| = R + G τ (Titscher & Unger Eqs. 21–22, cancellation-free
 * roots); INFINITY if never.  *overlap set to 1 when C < −1e-9 R².  dim 2/3. */
double pk_edmd_pair_time(const double dp[3], const double dv[3], double R, double G, int *overlap);

/* Time until |q + v τ| + ρ0 + g τ = σ (the grain leaves its bounding sphere
 * of radius σ centred at q = 0); INFINITY if never. */
double pk_edmd_exit_time(const double q[3], const double v[3], double rho0, double g, double sigma);

#endif
