/* rsa_region.h — the still-open region of a batched RSA run of equal grains
 * (internal to core/rsa/batch/rsa_batch.c).
 *
 * The draw range is cut into cells (rsa_batch.c: each store cell of
 * rsa_cells.h halved per axis, edge ≈ c/2, c = 2r + Δd), each cell into
 * S^dim = 64 fine voxels (S = 4 in 3D, 8 in 2D) with one bit each, set once
 * the fine voxel is known to lie inside the exclusion ball B(x_j, c) of one
 * placed grain (pk_rsa_region_mark / _cover; Zhang & Torquato's voxel
 * removal, at a fixed resolution).  A draw picks a listed cell uniformly and
 * one of its 64 fine voxels uniformly: a set bit is a certain rejection at once; otherwise the
 * point is uniform in that fine voxel and goes to the exact test.
 * Contract: a bit is set only for a fine voxel lying entirely inside one
 * exclusion ball, and a cell leaves the list only when all 64 bits are set —
 * what makes region draws exact RSA (core/rsa/batch/README.md, "Why it is
 * exact").  The bits of a cell are one 64-bit word: bit (lz·S + ly)·S + lx. */
#ifndef PK_RSA_REGION_H
#define PK_RSA_REGION_H

#include <stddef.h>
#include <stdint.h>

#include "core/space/box.h"
#include "core/base/rng.h"

/* Cells a mark reaches on each side at most (its ball radius c over the
 * cell edge, rounded up; farther marks are left out, which is safe). */
#define PK_RSA_REGION_MAX_REACH 2

typedef struct pk_rsa_region {
    int dim, S;
    int periodic[PK_MAXDIM];
    int64_t n[PK_MAXDIM];  /* cells per axis (1 on unused axes) */
    int sbits;             /* log2 S */
    int64_t nf[PK_MAXDIM]; /* fine voxels per axis: S·n */
    double lo[PK_MAXDIM];  /* lower end of the draw range */
    double hf[PK_MAXDIM];  /* fine voxel edge span/(S·n) */
    double inv_hf[PK_MAXDIM];
    double margin; /* cover radius shrink: round-off never marks an open point */
    double h[PK_MAXDIM], inv_h[PK_MAXDIM]; /* cell edge */
    /* Marks of a run grain (ball radius c) come from a table: the centre's
     * offset in its cell, quantised to Q steps per axis, selects the marks of
     * the 3^dim cells around, made for the ball of radius c - margin - delta
     * about the step's centre (delta: half the step's diagonal), so they hold
     * for every centre in the step.  Entries are made when first needed (in
     * 3D those of one octant; the others are their mirror images). */
    int Q, D;     /* steps per axis; cells reached on each side */
    size_t entry; /* words per entry: (2D + 1)^dim */
    double c, delta;
    uint64_t *tab;   /* [Q^dim][entry]: word ((dz+D)·W + dy+D)·W + dx+D, W = 2D + 1 */
    uint32_t *trows; /* [Q^dim]: bit r set when row r (W words along x) marks */
    uint8_t *tcnt;   /* [Q^dim]: 1 made, 0xff = not made yet */
    int tab_far;     /* the table outgrows a core's cache (1 MB): entries are
                                   fetched ahead with the marks' rows */
    int nrow;        /* rows of 2D + 1 cells around a cell: (2D + 1)^(dim - 1) */
    int64_t roff[(2 * PK_RSA_REGION_MAX_REACH + 1) * (2 * PK_RSA_REGION_MAX_REACH + 1)];
    /* index offset of each row's middle cell (off the seams) */
    uint64_t ncell;
    uint64_t *covered; /* [ncell] bit set: fine voxel inside an exclusion ball */
    uint32_t *list;    /* cells that had an open fine voxel at the last compaction */
    uint64_t nlist;
    int listed; /* 0 until the first compaction: then every cell counts as
                                   listed (nlist = ncell) and list[] is not yet written */
} pk_rsa_region;

/* Most steps of the mark table per axis and cell: delta = √3·h/(2·steps),
 * 0.027 c at 16 with h ≈ c/2 (4096 entries of (2·2 + 1)³ words, 4.6 MB; a
 * mark reads the rows of its entry that mark, up to 25 of 5 words in 3D). */
#define PK_RSA_REGION_MAX_STEPS 16

/* For the draw range lo[], span[] cut into n[k] cells per axis (the store's
 * cells), contact distance c, a mark table of `steps` steps per axis (1 to
 * PK_RSA_REGION_MAX_STEPS).  All bits clear, every cell listed — the list is
 * written by the first pk_rsa_region_compact, which must come before the
 * first draw (the cells' first marks are usually made before: the list then
 * never holds the cells they close, and the pages it would have needed are
 * never touched).  0 or -1. */
int pk_rsa_region_init(pk_rsa_region *R, const pk_box *b, const int64_t *n, const double *lo,
                       const double *span, double c, int steps);
void pk_rsa_region_free(pk_rsa_region *R);

/* Mark the fine voxels lying entirely inside the ball of radius rad around x
 * (minimum image on periodic axes): every point of them is closer than rad to x. */
void pk_rsa_region_cover(pk_rsa_region *R, const double *x, double rad);

/* Mark the exclusion ball B(x, c) of a grain of the run (x in the draw
 * range) through the table: a subset of pk_rsa_region_cover(R, x, c)'s marks
 * at a fraction of its cost. */
void pk_rsa_region_mark(pk_rsa_region *R, const double *x);

/* Where the mark of a grain at x goes: its cell and its table entry.
 * Located once, a mark can be fetched ahead and made later. */
typedef struct pk_rsa_region_spot {
    int64_t i[3];  /* the cell's coordinates */
    uint64_t word; /* its word in covered[] */
    uint32_t e;    /* the table entry */
    int inner;     /* the 2D + 1 cells around lie in the range on every axis */
} pk_rsa_region_spot;

pk_rsa_region_spot pk_rsa_region_locate(const pk_rsa_region *R, const double *x);

/* pk_rsa_region_mark(R, x) for the spot s = pk_rsa_region_locate(R, x). */
void pk_rsa_region_mark_at(pk_rsa_region *R, pk_rsa_region_spot s);

/* Ask the memory system for the words the mark at spot s will write and,
 * for a large table, the table entry it reads (a hint: at 10^6 grains each
 * mark's rows are misses; rsa_batch.c asks a few marks ahead). */
void pk_rsa_region_prefetch(const pk_rsa_region *R, pk_rsa_region_spot s);

/* Drop fully covered cells from the list (cost: the list's length); the
 * first call lists the cells not fully covered. */
void pk_rsa_region_compact(pk_rsa_region *R);

/* A draw in two parts (needs nlist > 0).  Pick: the top 32 bits of one
 * output choose a listed cell (Lemire, unbiased; returns its list position),
 * the low 6 bits one of its 64 fine voxels (*bit).  Point: x (z = 0 in 2D)
 * uniform in fine voxel `bit` of cell `cell`, one uniform per axis. */
static inline uint32_t pk_rsa_region_pick(const pk_rsa_region *R, pk_rng *g, unsigned *bit)
{
    const uint32_t nl = (uint32_t)R->nlist;
    uint64_t u = pk_rng_next(g);
    uint64_t m = (u >> 32) * (uint64_t)nl;
    if ((uint32_t)m < nl) {
        const uint32_t t = (uint32_t)(0u - nl) % nl;
        while ((uint32_t)m < t) {
            u = pk_rng_next(g);
            m = (u >> 32) * (uint64_t)nl;
        }
    }
    *bit = (unsigned)(u & 63);
    return (uint32_t)(m >> 32);
}

static inline void pk_rsa_region_point(const pk_rsa_region *R, uint32_t cell, unsigned bit,
                                       pk_rng *g, double x[3])
{
    const int sb = R->sbits;
    uint32_t c = cell; /* 32-bit divisions: ncell <= UINT32_MAX */
    unsigned f = bit;
    x[2] = 0;
    for (int k = 0; k < R->dim; k++) {
        const uint32_t n = (uint32_t)R->n[k];
        uint64_t i = c % n;
        c /= n;
        unsigned l = f & ((1u << sb) - 1);
        f >>= sb;
        x[k] = R->lo[k] + R->hf[k] * ((double)(i << sb | l) + pk_rng_uniform(g));
    }
}

/* One whole draw: 0 if it fell in a marked fine voxel (a certain rejection;
 * x is not computed), else 1 with x uniform in an unmarked fine voxel. */
static inline int pk_rsa_region_draw(const pk_rsa_region *R, pk_rng *g, double x[3])
{
    unsigned bit;
    uint32_t cell = R->list[pk_rsa_region_pick(R, g, &bit)];
    if (R->covered[cell] >> bit & 1)
        return 0;
    pk_rsa_region_point(R, cell, bit, g, x);
    return 1;
}

#endif
