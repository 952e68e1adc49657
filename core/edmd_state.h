/* edmd_state.h — the EDMD engine's internal state, shared by core/edmd*.c.
 * Structure of arrays; particle i's position at time t is
 * x0[3i..] + v[3i..]·(t − t0[i]) (delayed state), its simulated radius
 * a[i] + g[i]·t and its true radius that minus the shell h0 + h1·t. */
#ifndef PK_EDMD_STATE_H
#define PK_EDMD_STATE_H

#include "edmd.h"
#include "grid.h"

enum { EV_NONE = 0, EV_PAIR, EV_WALL, EV_NLIST };

typedef struct edmd_nlist {
    int32_t *nb;      /* neighbour indices */
    uint32_t n, cap;
} edmd_nlist;

typedef struct edmd_hnode {
    double t;                 /* event time (copy of ev_t[i]) */
    int32_t i;                /* particle */
} edmd_hnode;

typedef struct edmd_state {
    pk_box box;
    double half_L[3];         /* L/2 on periodic axes, +inf otherwise */
    int dim;
    size_t n;
    /* kinematics */
    double *x0, *v, *t0;      /* [3n], [3n], [n] */
    double *a, *g, *m;        /* radius offset, radius rate, mass */
    double h0, h1;            /* shell h(t) = h0 + h1 t */
    double t;                 /* current time (re-based) */
    double eps_v;             /* extra separation speed (spec §3.4) */
    /* events: one per particle */
    double *ev_t;
    int32_t *ev_partner;      /* partner (EV_PAIR) or wall code 2k+side (EV_WALL) */
    uint32_t *ev_stamp;       /* partner's ncoll at prediction time */
    uint8_t *ev_kind;
    uint32_t *ncoll;          /* velocity changes of each particle (validity counter) */
    edmd_hnode *heap;         /* 4-ary heap of (ev_t, particle) */
    int32_t *hpos;            /* node of each particle in the heap */
    size_t hn;
    /* neighbour lists */
    edmd_nlist *nl;
    pk_particles bs;          /* bounding spheres: centre c_i, radius σ_i */
    pk_grid grid;             /* on the bounding spheres */
    double *skin;             /* per-particle skin s_i */
    double *rref;             /* radius at the reference time (target size) */
    uint32_t *ncoll_nl;       /* ncoll[i] at i's last list build (ballistic test) */
    double sig_hi;            /* expected largest bounding sphere (grid cell size) */
    /* physics accumulators */
    double K;                 /* kinetic energy ½Σm v² */
    double virial;            /* Σ σ J over particle collisions in the window */
    double kint;              /* ∫K dt over the window */
    uint64_t n_overlap;
    double max_overlap_rel;
} edmd_state;

/* Minimum image of a displacement between two synced grains (periodic
 * coordinates kept in [0, L) by edmd_sync, bounding-sphere centres wrapped):
 * |d_k| < L, so one conditional shift replaces the general rounding.  Fixed
 * three axes, no periodicity test: half_L is +inf on walled axes and beyond
 * dim (edmd_minimage_init). */
static inline void edmd_min_image_near(const edmd_state *s, double d[3])
{
    for (int k = 0; k < 3; k++) {
        if (d[k] > s->half_L[k])
            d[k] -= s->box.L[k];
        else if (d[k] < -s->half_L[k])
            d[k] += s->box.L[k];
    }
}

/* edmd_predict.c */
void edmd_sync(edmd_state *s, size_t i);               /* x0 ← x(t), t0 ← t */
void edmd_predict(edmd_state *s, size_t i);            /* refresh i's event and heap slot */
double edmd_wall_time(const edmd_state *s, size_t i, int *code);

/* edmd_collide.c */
double edmd_collide_pair(edmd_state *s, size_t i, size_t j);   /* returns σ·J */
void edmd_collide_wall(edmd_state *s, size_t i, int code);

/* edmd_queue.c */
int edmd_queue_init(edmd_state *s);
void edmd_queue_update(edmd_state *s, size_t i);       /* after ev_t[i] changed */
void edmd_queue_shift(edmd_state *s, double dt);       /* all times −= dt */

/* edmd_order.c: perm[k] = index of the k-th grain along a Z-order curve of
 * cells of edge h.  0 or -1 (out of memory). */
int edmd_spatial_order(const pk_box *b, const double *x, size_t n, double h, size_t *perm);

/* edmd_nlist.c */
int edmd_nlist_build_all(edmd_state *s);
int edmd_nlist_rebuild(edmd_state *s, size_t i);
void edmd_nlist_free(edmd_state *s);

#endif
