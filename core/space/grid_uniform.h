/* grid_uniform.h — levels of dense cell lists, for neighbour searches that
 * rebuild often (EDMD's per-grain lists).
 *
 * core/space/grid.h's hashed multi-level grid is the general structure (memory
 * O(N) for any box/grain ratio).  This one keeps the same levels (radii
 * halving from level to level, cells about one level diameter wide) but
 * dense cell heads and doubly linked chains: a cell visit is an array load,
 * not a hash probe, and a remove is O(1).  Each level gets at most
 * PK_UGRID_CELLS_PER_GRAIN cells per grain it holds at init (wider cells
 * beyond that), so memory stays O(N).  Same visitor contract as
 * pk_grid_query (the order of the visits is not part of it).
 *
 * Cover: with many small grains and few big ones (Fuller-like
 * gradings) the small grains' queries spent most of their time in the
 * coarse levels — a box of big cells with few grains, ~50 tests for ~2
 * found.  The levels coarser than the most populated one are therefore also
 * listed in a cover: every grain there is listed in each cell (of the
 * populated level's geometry) its ball r_j + cov_r touches, and a query of
 * radius r <= cov_r tests the grains listed in its point's cell instead of
 * scanning those levels.  Inserts and removes of coarse grains walk their
 * ball's cells (rare: coarse grains are slow).  Memory: 16 bytes per cell
 * of the populated level and the cells' lists, planned at init to at most
 * 8 N + 65536 entries per covered level (levels whose balls span more than
 * 512 cells are not covered).  Code: core/space/grid_cover.c. */
#ifndef PK_GRID_UNIFORM_H
#define PK_GRID_UNIFORM_H

#include <stddef.h>
#include <stdint.h>

#include "box.h"
#include "grid.h"
#include "particles.h"

#define PK_UGRID_MAX_LEVELS 24
#define PK_UGRID_CELLS_PER_GRAIN 8

typedef struct pk_ugrid_level {
    double inv_h[PK_MAXDIM]; /* 1 / cell edge */
    int32_t n[PK_MAXDIM];    /* cells per axis (1 beyond dim) */
    int32_t *head;           /* first grain of each cell, -1 = empty */
    double r_max;            /* largest radius registered here (never lowered) */
} pk_ugrid_level;

/* A cover cell: the coarse grains whose balls r_j + cov_r touch it. */
typedef struct pk_ugrid_cover {
    int32_t *ids;
    uint32_t n, cap;
} pk_ugrid_cover;

typedef struct pk_ugrid {
    pk_box box;
    double L[PK_MAXDIM];     /* box edges on periodic axes, 0 otherwise */
    double inv_L[PK_MAXDIM]; /* 1/L on periodic axes, 0 otherwise */
    double r_top;            /* level l holds radii in (r_top/2^(l+1), r_top/2^l] */
    int nlevel;
    pk_ugrid_level lv[PK_UGRID_MAX_LEVELS];
    int32_t *next, *prev, *cell; /* per grain; cell -1 = not registered */
    int8_t *level;
    size_t cap;
    /* Cover of the levels coarser than the most populated one (few grains in
     * big cells): each of their grains is also listed in every cell of that
     * level's geometry its ball r_j + cov_r touches, so a query of radius
     * <= cov_r reads one cell for all of them instead of a box of cells per
     * coarse level.  cov_r = 0: no cover (one level, or the coarsest is the
     * most populated). */
    double cov_r;
    int8_t covered[PK_UGRID_MAX_LEVELS];
    int cov_level;          /* whose cell geometry the cover uses */
    pk_ugrid_cover *cov;    /* cells */
    pk_ugrid_cover cov_big; /* grains grown past a bounded ball: tested by every cover query */
    double *cov_ball; /* per grain: centre and radius it is listed with (0: not; < 0: in cov_big) */
    size_t cov_nmax;  /* most cells along an axis */
    int64_t *cov_off; /* scratch of the cover walks: 3 × 3 × cov_nmax cell offsets
                                 * (two balls and their union) */
    double *cov_e2;   /* and 4 × 3 × cov_nmax squared slab distances (two balls,
                                 * and each over the union) */
} pk_ugrid;

/* Minimum image of d along the axes with inv_L[k] = 1/L[k] (walled axes:
 * inv_L = L = 0, d unchanged), branch-free: n = round(d/L) by the 1.5·2^52
 * trick (exact round-to-nearest under the default rounding mode for
 * |d/L| < 2^51; the build uses no -ffast-math, which could fold it). */
static inline void pk_min_image3(const double L[PK_MAXDIM], const double inv_L[PK_MAXDIM],
                                 double d[PK_MAXDIM])
{
    const double M = 6755399441055744.0;
    for (int k = 0; k < PK_MAXDIM; k++)
        d[k] -= L[k] * ((d[k] * inv_L[k] + M) - M);
}

/* Levels for the n radii r[0..n) (they size the cell budget of each level;
 * later grains may have any radius: bigger ones go to level 0, whose bound
 * grows); grain indices < cap (>= n).  0 or -1 (bad arguments / memory). */
int pk_ugrid_init(pk_ugrid *g, const pk_box *b, const double *r, size_t n, size_t cap);
void pk_ugrid_free(pk_ugrid *g);
/* Register grain i of p (its position and radius are read now; position
 * wrapped into [0, L) on periodic axes).  Re-registers if present. */
int pk_ugrid_insert(pk_ugrid *g, const pk_particles *p, size_t i);
void pk_ugrid_remove(pk_ugrid *g, size_t i);
/* fn for every registered j with |x_j − x| < r + r_j (minimum image). */
int pk_ugrid_query(const pk_ugrid *g, const pk_particles *p, const double x[PK_MAXDIM], double r,
                   pk_grid_visit fn, void *ctx);

#endif
