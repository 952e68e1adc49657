/* rsa_cells.h — dense cell store of equal grains for batched RSA (internal to core/rsa_batch.c).
 *
 * The draw range of one grain size is cut into cells of edge h >= c, c = 2r + Δd
 * the contact distance, so a grain can only touch grains of its own and the
 * 3^dim - 1 neighbouring cells.  Cells are a dense array (index
 * (iz·ny + iy)·nx + ix), each one 64-byte record holding up to two centres
 * inline and a chain into an overflow pool for the rare third one: a test reads
 * 9 (3D) or 3 (2D) runs of three adjacent records, so tests of attempts sorted
 * by cell index stream through memory instead of chasing pointers.
 *
 * The overlap predicate is, bit for bit, the one of pk_grid_overlaps (same
 * difference, minimum image through nearbyint, same sum order, same s²): the
 * batched path and the one-at-a-time path take the same decisions. */
#ifndef PK_RSA_CELLS_H
#define PK_RSA_CELLS_H

#include <math.h>
#include <stdint.h>

#include "box.h"

typedef struct pk_rsa_cell2 {
    double x[2][3];             /* inline centres (z = 0 in 2D) */
    int32_t n;                  /* centres in this cell */
    int32_t more;               /* first overflow entry (n > 2), -1 = none */
    int64_t pad_;               /* one record = one 64-byte line */
} pk_rsa_cell2;

typedef struct pk_rsa_extra {
    double x[3];
    int32_t next;
} pk_rsa_extra;

typedef struct pk_rsa_cells {
    int dim;
    int periodic[PK_MAXDIM];
    double L[PK_MAXDIM], quarter[PK_MAXDIM]; /* quarter = L/4: beyond it the image may shift */
    double lo[PK_MAXDIM];       /* lower end of the draw range per axis */
    double inv_h[PK_MAXDIM];
    int64_t n[PK_MAXDIM];       /* cells per axis (1 on unused axes) */
    uint64_t ncell;
    double s2;                  /* (r + r + Δd)², the squared contact distance */
    pk_rsa_cell2 *cell;
    pk_rsa_extra *extra;
    size_t nextra, capextra;
} pk_rsa_cells;

/* Cells a store for grains of radius r (gap Δd) over the draw range starting at
 * lo[] with spans span[] would hold; 0 if it cannot serve the box (a periodic
 * axis with fewer than 3 cells). */
uint64_t pk_rsa_cells_count(const pk_box *b, double r, double gap, const double *lo,
                            const double *span);
int pk_rsa_cells_init(pk_rsa_cells *C, const pk_box *b, double r, double gap, const double *lo,
                      const double *span);
void pk_rsa_cells_free(pk_rsa_cells *C);

/* Cell coordinate along axis k (clamped: round-off at the range ends). */
static inline int64_t pk_rsa_cells_coord(const pk_rsa_cells *C, int k, double xk)
{
    double f = (xk - C->lo[k]) * C->inv_h[k];
    int64_t i = f < 0 ? 0 : (int64_t)f;
    return i >= C->n[k] ? C->n[k] - 1 : i;
}

static inline uint64_t pk_rsa_cells_of(const pk_rsa_cells *C, const double *x)
{
    uint64_t lin = (uint64_t)pk_rsa_cells_coord(C, 0, x[0]);
    lin += (uint64_t)C->n[0] * (uint64_t)pk_rsa_cells_coord(C, 1, x[1]);
    if (C->dim == 3)
        lin += (uint64_t)C->n[0] * (uint64_t)C->n[1] * (uint64_t)pk_rsa_cells_coord(C, 2, x[2]);
    return lin;
}

/* 1 if centres a and b are closer than contact: pk_grid's predicate (grid.c
 * scan) for two grains of this size.  For |d| <= L/4, nearbyint(d/L) = 0 and
 * d - L·0 = d exactly, so skipping the image there changes no bit. */
static inline int pk_rsa_cells_close(const pk_rsa_cells *C, const double *a, const double *b)
{
    double d2 = 0;
    for (int k = 0; k < C->dim; k++) {
        double d = a[k] - b[k];
        if (C->periodic[k] && fabs(d) > C->quarter[k])
            d -= C->L[k] * nearbyint(d / C->L[k]);
        d2 += d * d;
    }
    return d2 < C->s2;
}

/* Neighbour cells of the cell holding x (itself included), each once. */
int pk_rsa_cells_around(const pk_rsa_cells *C, const double *x, uint64_t out[27]);

/* Store a centre.  0, or -1 when out of memory. */
int pk_rsa_cells_insert(pk_rsa_cells *C, const double *x);

/* For each of the n points pos[3i..] (any order; sorted by cell is fast):
 * keep[i] = 1 if no stored centre is closer than contact, else 0. */
void pk_rsa_cells_filter(const pk_rsa_cells *C, const double *pos, size_t n, uint8_t *keep);

#endif
