/* grid_cover.h — the cover of a pk_ugrid's coarse levels (internal to
 * core/space/grid_uniform.c; see grid_uniform.h for what it is and why). */
#ifndef PK_GRID_COVER_H
#define PK_GRID_COVER_H

#include <stddef.h>

#include "grid_uniform.h"

/* Picks the covered levels (count[l]: grains per level at init, n in all)
 * and allocates the cells; no cover (cov_r = 0) when none pays.  0 or -1. */
int pk_ugrid_cover_init(pk_ugrid *g, const size_t *count, size_t n);
void pk_ugrid_cover_free(pk_ugrid *g);
/* Grain j of a covered level, at x with radius r: listed / taken out. */
int pk_ugrid_cover_add(pk_ugrid *g, size_t j, const double x[PK_MAXDIM], double r);
void pk_ugrid_cover_remove(pk_ugrid *g, size_t j);
/* Grain j of a covered level, listed, re-listed with its ball at x, r (the
 * cells both balls touch are left alone): as remove + add but for j's
 * place in those cells. */
int pk_ugrid_cover_move(pk_ugrid *g, size_t j, const double x[PK_MAXDIM], double r);
/* fn for every covered grain within r + r_j of x; r <= g->cov_r. */
int pk_ugrid_cover_query(const pk_ugrid *g, const pk_particles *p, const double x[PK_MAXDIM],
                         double r, pk_grid_visit fn, void *ctx);

#endif
