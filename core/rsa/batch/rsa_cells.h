/* rsa_cells.h — dense cell store of equal grains for batched RSA (internal to
 * core/rsa/batch/rsa_batch.c).
 *
 * The draw range of one grain size is cut into cells of edge h >= c, c = 2r + Δd
 * the contact distance, so a grain can only touch grains of its own and the
 * 3^dim - 1 neighbouring cells.  Cells are a dense array (index
 * (iz·ny + iy)·nx + ix) of 16-byte records, four to a cache line, each holding
 * one grain inline — its offset from the cell's lower corner as floats and its
 * index in the particle array — or, for a cell with two or more grains, a
 * chain into an overflow pool and the first two grains' offsets in 16-bit
 * steps.  An occupancy bitmap (one bit per cell) says which of the 3^dim cells
 * around an attempt hold grains, so a test reads the nonempty records only.
 *
 * Contract: every test here answers as the exact predicate pk_rsa_cells_close
 * (pk_grid's, bit for bit) on the double positions of the particle array; the
 * floats and 16-bit offsets only decide outside a band around contact
 * (PK_RSA_CELLS_BAND, PK_RSA_CELLS_QBAND), inside it the doubles decide.  Why
 * the bands suffice: core/rsa/batch/README.md, "Why it is exact". */
#ifndef PK_RSA_CELLS_H
#define PK_RSA_CELLS_H

#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "core/space/box.h"

#define PK_RSA_CELLS_BAND 0x1p-14
#define PK_RSA_CELLS_NONE 0xffffffffu  /* empty slot */
#define PK_RSA_CELLS_MORE 0x80000000u  /* id: the cell's grains are in the pool */
#define PK_RSA_CELLS_THREE 0x40000000u /* id, with MORE: three or more grains */
#define PK_RSA_CELLS_POOL 0x3fffffffu  /* id, with MORE: the chain's first pool entry */
/* Offsets of a cell's first two grains in 16-bit steps of h/65536 and the band
 * of their quick test: a step's error moves a squared distance near contact by
 * < 1.1e-4·c², inside ±2^-12·c² (README.md, "Why it is exact"). */
#define PK_RSA_CELLS_QSTEPS 65536.0
#define PK_RSA_CELLS_QBAND 0x1p-12

typedef struct pk_rsa_cell1 {
    union {
        float x[3];       /* one grain: its offsets from the cell's lower corner
                                   (z = 0 in 2D) */
        uint16_t q[2][3]; /* two or more (MORE): the first two grains' offsets in
                                   steps of h/65536, rounded down */
    };
    uint32_t id; /* particle index, PK_RSA_CELLS_NONE = empty; with
                                   PK_RSA_CELLS_MORE: the cell holds two or more grains, all
                                   in the pool (exact offsets and indices), the chain
                                   starting at entry id & PK_RSA_CELLS_POOL; THREE set when
                                   they are three or more (q holds the first two only) */
} pk_rsa_cell1;

typedef struct pk_rsa_extra {
    float x[3];
    uint32_t id;
    int32_t next; /* next pool entry of the cell, -1 = last */
} pk_rsa_extra;

typedef struct pk_rsa_cells {
    int dim;
    double L[PK_MAXDIM];
    double quarter[PK_MAXDIM]; /* L/4 on periodic axes (beyond it the image may
                                   shift), +inf on walled and unused axes */
    double lo[PK_MAXDIM];      /* lower end of the draw range per axis */
    double h[PK_MAXDIM];       /* cell edge (0 on unused axes) */
    double inv_h[PK_MAXDIM];
    double inv_h2[PK_MAXDIM]; /* 2·inv_h: half cells (the key's octant) */
    uint64_t jmax[PK_MAXDIM]; /* 2n - 1: last half cell */
    int periodic[PK_MAXDIM];
    double seam_lo[PK_MAXDIM];  /* x < seam_lo or x >= seam_hi: maybe in a seam cell */
    double seam_hi[PK_MAXDIM];  /* (pk_rsa_cells_seam; -inf / +inf where never,
                                   seam_lo = +inf where always) */
    int64_t n[PK_MAXDIM];       /* real cells per axis (1 on unused axes) */
    int64_t np[PK_MAXDIM];      /* with the ghost layer: n + 2 on used axes */
    uint64_t ncell;             /* padded cells */
    double s2;                  /* (r + r + Δd)², the squared contact distance */
    double s2_lo, s2_hi;        /* s2·(1 ∓ PK_RSA_CELLS_BAND): the float band */
    double q2_lo, q2_hi;        /* s2·(1 ∓ PK_RSA_CELLS_QBAND): the 16-bit band */
    double hq[PK_MAXDIM];       /* h/65536: a 16-bit step (0 on unused axes) */
    uint64_t stride[PK_MAXDIM]; /* padded index = base + sum_k i_k·stride[k] */
    uint64_t base;
    int noff;               /* 3^dim */
    int64_t off[8][27];     /* offsets in the padded array of the cell itself (first)
                                   and its neighbours per octant of the cell (bit k: upper
                                   half along axis k), the near sides first: a rejected
                                   attempt usually meets its overlap in the first few */
    double shift[8][27][3]; /* the neighbour's corner minus the cell's */
    /* Occupancy: bit i of occ is set once padded cell i holds a grain (ghost
     * copies included), so a test reads 9 (3D) or 3 (2D) runs of 3 bits from
     * an array 256 times smaller than the cells and touches nonempty cells
     * only.  row[r]: index offset of row r's first cell (dz = r / 3 - 1 in 3D,
     * dy = r % 3 - 1, dx = -1); order[oct][r][p]: the bits t (of off[oct][t])
     * of the cells set in 3-bit pattern p of row r. */
    uint8_t *occ;
    int nrow;
    int64_t row[9];
    uint32_t order[8][9][8];
    pk_rsa_cell1 *cell;
    pk_rsa_extra *extra;
    size_t nextra, capextra;
} pk_rsa_cells;

/* A ghost layer surrounds the real cells: on periodic axes it holds copies of
 * the opposite face's grains (same offsets from the ghost's corner, so the
 * floats give the periodic image; same particle index, so the band's double
 * test finds the image through pk_rsa_cells_close), on walled axes it stays
 * empty — so every test reads the cell and its fixed index offsets, with no
 * wrap or clip.  With at least 3 cells per periodic axis a grain appears once
 * among a cell's neighbours, as the image nearest to it when within contact. */

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

/* Key of x: padded index of the real cell holding x (bits 0..27) and the
 * octant of x in it (bits 28..30, bit k: upper half along axis k; which
 * neighbours to test first).  (ncell < 2^28: the fields never collide.)
 * pk_rsa_cells_key_q also writes the offsets q of x from the lower corner of
 * that cell (z = 0 in 2D): what pk_rsa_cells_filter tests with. */
static inline uint32_t pk_rsa_cells_key_q(const pk_rsa_cells *C, const double *x, double q[3])
{
    uint64_t j0 = pk_rsa_cells_half(C, 0, x[0]), j1 = pk_rsa_cells_half(C, 1, x[1]), j2 = 0;
    q[0] = x[0] - (C->lo[0] + (double)(int64_t)(j0 >> 1) * C->h[0]);
    q[1] = x[1] - (C->lo[1] + (double)(int64_t)(j1 >> 1) * C->h[1]);
    q[2] = 0;
    if (C->dim == 3) {
        j2 = pk_rsa_cells_half(C, 2, x[2]);
        q[2] = x[2] - (C->lo[2] + (double)(int64_t)(j2 >> 1) * C->h[2]);
    }
    uint64_t lin = C->base + (j0 >> 1) + (j1 >> 1) * C->stride[1] + (j2 >> 1) * C->stride[2];
    uint32_t oct = (uint32_t)((j0 & 1) | (j1 & 1) << 1 | (j2 & 1) << 2);
    return (uint32_t)lin | oct << PK_RSA_CELLS_OCT_SHIFT;
}

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

/* The 3 bits of map from bit `first` on (the map has 8 bytes of slack). */
static inline unsigned pk_rsa_cells_bits3(const uint8_t *map, uint64_t first)
{
    uint64_t v;
    memcpy(&v, &map[first >> 3], sizeof v);
    return (unsigned)(v >> (first & 7)) & 7u;
}

/* Store grain `id` (< 2^31) of the particle array, centre x (and its ghost
 * copies).  0, or -1 when out of memory. */
int pk_rsa_cells_insert(pk_rsa_cells *C, const double *x, uint32_t id);

/* 1 if x lies in a real cell next to a periodic seam (or on an axis of fewer
 * than 4 cells): its neighbours may need a periodic image (rsa_batch.c's
 * hash of a batch's grains).  The cell is the key's (pk_rsa_cells_key_q); the
 * test is conservative: within 1e-9·h of the first or last cell's inner face
 * it says 1 (harmless: the seam path serves every cell). */
static inline int pk_rsa_cells_seam(const pk_rsa_cells *C, const double *x)
{
    int s = x[0] < C->seam_lo[0] || x[0] >= C->seam_hi[0];
    s |= x[1] < C->seam_lo[1] || x[1] >= C->seam_hi[1];
    if (C->dim == 3)
        s |= x[2] < C->seam_lo[2] || x[2] >= C->seam_hi[2];
    return s;
}

/* For n points with keys key[i] and offsets q[3i..] from their cells' corners
 * (pk_rsa_cells_key_q; any order, sorted by key is fast): writes the indices i
 * of the points no stored centre is within contact of, ascending, to kept[]
 * and returns their number.  Point i itself (z = 0 in 2D) is pos[3·idx[i]..]
 * (idx NULL: pos[3i..]); it is read only in the band, with px: the particle
 * array's centres (stride 3). */
static inline uint64_t pk_rsa_cells_index(uint32_t key) { return key & PK_RSA_CELLS_INDEX_MASK; }
static inline unsigned pk_rsa_cells_octant(uint32_t key)
{
    return key >> PK_RSA_CELLS_OCT_SHIFT & 7u;
}
size_t pk_rsa_cells_filter(const pk_rsa_cells *C, const double *px, const double *q,
                           const double *pos, const uint32_t *idx, const uint32_t *key, size_t n,
                           uint32_t *kept);

#endif
