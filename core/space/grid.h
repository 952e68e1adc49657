/* grid.h — the one neighbour structure of packd: a multi-level cell grid.
 *
 * Why multi-level: one grid sized by the largest grain puts thousands of fine
 * grains in a cell at size ratios of 1:1000; one sized by the finest makes a
 * coarse grain cover millions of cells.  Level l holds the grains with radius
 * in (r_max/2^(l+1), r_max/2^l] in cells of edge ≈ 2·r_max/2^l + gap, so each
 * cell holds O(1) grains of its level at any density, and a query visits
 * O(1) cells per non-empty level (Titscher §4's halving cell size, without
 * the rebuilds).  Cells live in a hash table per level (power-of-two buckets,
 * each grain remembers its cell, so hash collisions never report a grain
 * twice) — memory is O(N), independent of the box/finest-grain ratio — or
 * (pk_grid_init_dense), where a level has few cells per grain, in one head
 * per cell.
 *
 * Used by RSA (insert + overlap test), the gap audit's cross-check, EDMD's
 * neighbour lists and DEM contact detection (insert/move/remove + query).
 * Periodic axes use the minimum image; a periodic edge must exceed twice the
 * largest contact distance (checked by the callers that build jobs). */
#ifndef PK_GRID_H
#define PK_GRID_H

#include <stddef.h>
#include <stdint.h>

#include "box.h"
#include "particles.h"

#define PK_GRID_MAX_LEVELS 24

typedef struct pk_grid_level {
    double h[PK_MAXDIM];      /* cell edge per axis */
    int64_t ncell[PK_MAXDIM]; /* cells per axis */
    double r_hi;              /* radii in this level are <= r_hi */
    size_t count;             /* grains registered */
    int dense;                /* one bucket per cell (index = linear cell index) */
    uint64_t mask;            /* hashed: nbucket - 1 (nbucket a power of two) */
    int32_t *head;            /* [nbucket] first grain of each bucket, -1 = empty */
} pk_grid_level;

typedef struct pk_grid {
    pk_box box;
    double gap;   /* contact distance is r_i + r_j + gap */
    double r_top; /* radius bound of level 0 */
    int nlevel;
    pk_grid_level lv[PK_GRID_MAX_LEVELS];
    size_t cap;     /* per-grain arrays sized for indices < cap */
    int32_t *next;  /* bucket chain */
    uint64_t *cell; /* linear cell index of each registered grain */
    int8_t *level;  /* level of each grain, -1 = not registered */
} pk_grid;

/* r_min..r_max: radius range of the grains to be registered (r_max > 0);
 * gap: the extra contact distance (Δd, >= 0); cap: grains indices < cap.
 * Returns 0 or -1 (bad arguments / out of memory). */
int pk_grid_init(pk_grid *g, const pk_box *b, double r_min, double r_max, double gap, size_t cap);
/* The same, but levels with at most 4 cells per grain (+4096) get one head
 * per cell instead of hashed buckets (faster cell visits; RSA).  Queries
 * find the same grains; the order of the visits within a cell may differ
 * from pk_grid_init's, whose chains reorder when buckets grow. */
int pk_grid_init_dense(pk_grid *g, const pk_box *b, double r_min, double r_max, double gap,
                       size_t cap);
void pk_grid_free(pk_grid *g);

/* Register grain i of p (its position and radius are read now). */
int pk_grid_insert(pk_grid *g, const pk_particles *p, size_t i);
/* Unregister grain i (no-op if absent). */
void pk_grid_remove(pk_grid *g, size_t i);
/* Re-register grain i after its position or radius changed. */
int pk_grid_update(pk_grid *g, const pk_particles *p, size_t i);

/* Called for every registered grain j with |x_j - x| < r + r_j + gap + extra
 * (minimum image).  dx = x_j - x (minimum image), dist2 = |dx|².  Return
 * non-zero to stop the query; pk_grid_query then returns that value. */
typedef int (*pk_grid_visit)(size_t j, const double dx[PK_MAXDIM], double dist2, void *ctx);

int pk_grid_query(const pk_grid *g, const pk_particles *p, const double x[PK_MAXDIM], double r,
                  double extra, pk_grid_visit fn, void *ctx);

/* Fast path for RSA: 1 if a registered grain j has |x_j - x| < r + r_j + gap. */
int pk_grid_overlaps(const pk_grid *g, const pk_particles *p, const double x[PK_MAXDIM], double r);

#endif
