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
#include <stddef.h>
#include <stdint.h>

#include "box.h"

typedef struct pk_rsa_cell2 {
    double x[2][3];             /* inline centres (z = 0 in 2D) */
    int32_t n;                  /* centres in this cell */
    int32_t more;               /* first overflow entry (n > 2), -1 = none */
    int32_t seam;               /* 1: a neighbour may need a periodic image (below) */
    int32_t pad_;               /* one record = one 64-byte line */
} pk_rsa_cell2;

typedef struct pk_rsa_extra {
    double x[3];
    int32_t next;
} pk_rsa_extra;

typedef struct pk_rsa_cells {
    int dim;
    double L[PK_MAXDIM];
    double quarter[PK_MAXDIM];  /* L/4 on periodic axes (beyond it the image may
                                   shift), +inf on walled and unused axes */
    double lo[PK_MAXDIM];       /* lower end of the draw range per axis */
    double inv_h[PK_MAXDIM];
    double inv_h2[PK_MAXDIM];   /* 2·inv_h: half cells (the key's octant) */
    uint64_t jmax[PK_MAXDIM];   /* 2n - 1: last half cell */
    int periodic[PK_MAXDIM];
    int64_t n[PK_MAXDIM];       /* real cells per axis (1 on unused axes) */
    int64_t np[PK_MAXDIM];      /* with the ghost layer: n + 2 on used axes */
    uint64_t ncell;             /* padded cells */
    double s2;                  /* (r + r + Δd)², the squared contact distance */
    uint64_t stride[PK_MAXDIM]; /* padded index = base + sum_k i_k·stride[k] */
    uint64_t base;
    int noff;
    int64_t off[8][26];         /* neighbour offsets in the padded array per octant of
                                   the cell (bit k: upper half along axis k), the near
                                   sides first: a rejected attempt usually meets its
                                   overlap in the first few cells */
    pk_rsa_cell2 *cell;
    pk_rsa_extra *extra;
    size_t nextra, capextra;
} pk_rsa_cells;

/* A ghost layer surrounds the real cells: on periodic axes it holds copies of
 * the opposite face's centres (original coordinates: the predicate finds the
 * image), on walled axes it stays empty — so every test reads the cell and
 * its fixed index offsets, with no wrap or clip. */

/* Cells a store for grains of radius r (gap Δd) over the draw range starting at
 * lo[] with spans span[] would hold (ghosts included); 0 if it cannot serve the
 * box (a periodic axis with fewer than 3 cells, or too many cells). */
uint64_t pk_rsa_cells_count(const pk_box *b, double r, double gap, const double *span);
int pk_rsa_cells_init(pk_rsa_cells *C, const pk_box *b, double r, double gap, const double *lo,
                      const double *span);
void pk_rsa_cells_free(pk_rsa_cells *C);

/* Real cell coordinate along axis k (clamped: round-off at the range ends). */
static inline int64_t pk_rsa_cells_coord(const pk_rsa_cells *C, int k, double xk)
{
    double f = (xk - C->lo[k]) * C->inv_h[k];
    int64_t i = f < 0 ? 0 : (int64_t)f;
    return i >= C->n[k] ? C->n[k] - 1 : i;
}

#define PK_RSA_CELLS_OCT_SHIFT 28
#define PK_RSA_CELLS_INDEX_MASK 0x0fffffffu

/* Coordinate in half cells along axis k: i = j >> 1 is the cell coordinate
 * (truncation of f = 2·(xk - lo)·inv_h; clamped into 0..2n-1), j & 1 the
 * half of the cell.  (It may differ from pk_rsa_cells_coord by one cell when
 * x is within round-off of a face: harmless, h >= c·(1 + 1e-9).) */
static inline uint64_t pk_rsa_cells_half(const pk_rsa_cells *C, int k, double xk)
{
    double f = (xk - C->lo[k]) * C->inv_h2[k];
    uint64_t j = (uint64_t)(int64_t)f;
    if (j > C->jmax[k]) /* rare: round-off at the range ends */
        j = f < 0 ? 0 : C->jmax[k];
    return j;
}

/* Padded index of the real cell holding x (bits 0..27) and the octant of x in
 * it (bits 28..30, bit k: upper half along axis k; which neighbours to test
 * first).  (ncell < 2^28: the fields never collide.) */
static inline uint32_t pk_rsa_cells_key(const pk_rsa_cells *C, const double *x)
{
    uint64_t j0 = pk_rsa_cells_half(C, 0, x[0]), j1 = pk_rsa_cells_half(C, 1, x[1]), j2 = 0;
    if (C->dim == 3)
        j2 = pk_rsa_cells_half(C, 2, x[2]);
    uint64_t lin = C->base + (j0 >> 1) + (j1 >> 1) * C->stride[1] + (j2 >> 1) * C->stride[2];
    uint32_t oct = (uint32_t)((j0 & 1) | (j1 & 1) << 1 | (j2 & 1) << 2);
    return (uint32_t)lin | oct << PK_RSA_CELLS_OCT_SHIFT;
}

/* A real cell's seam flag is set when a neighbour may need a periodic image:
 * the cell touches a periodic seam, or its axis has fewer than 4 cells.
 * Otherwise every neighbour is nearer than 2h <= L/2 on each periodic axis,
 * where nearbyint(d/L) = 0: the test may take d as is. */

/* 1 if centres a and b (z = 0 in 2D) are closer than contact: pk_grid's
 * predicate (grid.c scan) bit for bit — same difference, image
 * d -= L·nearbyint(d/L) on periodic axes, same sum order (in 2D the extra
 * z term is +0, exact).  For |d| <= L/4, nearbyint(d/L) = 0 and d - L·0 = d,
 * so skipping the image there changes no bit. */
static inline int pk_rsa_cells_close(const pk_rsa_cells *C, const double *a, const double *b)
{
    double d0 = a[0] - b[0], d1 = a[1] - b[1], d2 = a[2] - b[2];
    if (fabs(d0) > C->quarter[0])
        d0 -= C->L[0] * nearbyint(d0 / C->L[0]);
    if (fabs(d1) > C->quarter[1])
        d1 -= C->L[1] * nearbyint(d1 / C->L[1]);
    if (fabs(d2) > C->quarter[2])
        d2 -= C->L[2] * nearbyint(d2 / C->L[2]);
    return d0 * d0 + d1 * d1 + d2 * d2 < C->s2;
}

/* Real neighbour cells (padded indices) of the cell holding x, itself
 * included, each once: periodic axes wrap, walled axes clip. */
int pk_rsa_cells_around(const pk_rsa_cells *C, const double *x, uint64_t out[27]);

/* Store a centre (and its ghost copies).  0, or -1 when out of memory. */
int pk_rsa_cells_insert(pk_rsa_cells *C, const double *x);

/* For the n points pos[3i..] (z = 0 in 2D) with keys key[i] (pk_rsa_cells_key;
 * any order, sorted by key is fast): writes the indices i of the points no
 * stored centre is within contact of, ascending, to kept[] and returns their
 * number. */
static inline uint64_t pk_rsa_cells_index(uint32_t key) { return key & PK_RSA_CELLS_INDEX_MASK; }
static inline unsigned pk_rsa_cells_octant(uint32_t key)
{
    return key >> PK_RSA_CELLS_OCT_SHIFT & 7u;
}
size_t pk_rsa_cells_filter(const pk_rsa_cells *C, const double *pos, const uint32_t *key, size_t n,
                           uint32_t *kept);

#endif
