/* rsa_voxels.h — RSA's sampling set of "possibly free" voxels (internal to core/rsa/rsa.c).
 *
 * Late in an RSA run most uniform draws land in the exclusion zone of a placed
 * grain and are wasted.  This structure tiles the draw range with voxels, each
 * split into 64 sub-voxels (4³ or 8²) with one bit "not yet known to be
 * covered"; voxels with no bit left leave the list of active voxels.  A draw
 * picks an active voxel uniformly and a point uniformly inside it; if the
 * point's sub-voxel is marked covered the draw is rejected at once, otherwise
 * it is tested exactly as before.  Why this is still true RSA: all voxels have
 * the same volume, so the point is uniform over the union of active voxels;
 * that union contains all the space still available to the grain (a bit is
 * cleared only when its sub-voxel lies inside the exclusion ball of one
 * placed grain, see pk_rsa_vox_cover), and the marked sub-voxels hold no
 * available point; rejection then leaves the accepted point uniform over the
 * available space — the law of a plain draw-until-accepted loop, with fewer
 * and cheaper wasted draws.
 *
 * Polydispersity: the set is built for a radius bound r_valid.  A voxel is
 * removed when it lies in B(x_j, r_j + r_valid + Δd); exclusion balls only grow
 * with the grain radius, so the set stays valid for every grain with r >= r_valid
 * (sizes decrease during the run; the caller rebuilds when r falls below).
 * On walled axes the lattice tiles the draw range of r_valid, the largest one;
 * a larger grain rejects draws outside its own range.
 *
 * The voxels also index the grains placed since the build: the voxel edge is
 * at most (2 r_valid + Δd)/√dim, so no voxel can hold two centres, and each
 * voxel stores its grain (x, y, z, r) inline — the overlap test reads a few
 * contiguous rows instead of chasing hashed cell chains. */
#ifndef PK_RSA_VOXELS_H
#define PK_RSA_VOXELS_H

#include <stdint.h>

#include "core/space/box.h"
#include "core/base/rng.h"

/* One voxel: its grain (x = +inf when none) and its sub-voxel bits, in one
 * record so a draw, the overlap test and the cover read the same lines. */
typedef struct pk_rsa_cell {
    double x[3], r;
    uint64_t mask; /* sub-voxels not yet known covered, bit (z·sub+y)·sub+x */
} pk_rsa_cell;

typedef struct pk_rsa_vox {
    pk_box box;
    double org[PK_MAXDIM]; /* lattice origin per axis */
    double e[PK_MAXDIM];   /* voxel edge per axis */
    double inv_e[PK_MAXDIM];
    int64_t n[PK_MAXDIM]; /* voxels per axis (1 on unused axes) */
    uint64_t nvox;
    double r_valid;       /* set valid for grains with r >= r_valid */
    double r_top;         /* largest grain stored */
    double gap;           /* Δd */
    double margin;        /* absolute safety margin of the cover test */
    int sub;              /* sub-voxels per axis and voxel (sub^dim = 64) */
    double se[PK_MAXDIM]; /* sub-voxel edge per axis */
    pk_rsa_cell *cell;    /* [nvox] */
    uint32_t *slot;       /* index in `active`, UINT32_MAX once removed */
    uint32_t *active;     /* active voxel ids */
    uint64_t nactive;
} pk_rsa_vox;

/* Number of voxels a set for (b, r_valid, gap) would hold, or 0 when the
 * structure cannot serve this box (a walled axis with no draw range, or a
 * periodic edge not larger than twice the contact distance 2 r_top + Δd).
 * wall: the clearance kept at walls (Δd/2, or 0 with wall_gap none). */
uint64_t pk_rsa_vox_count(const pk_box *b, double r_valid, double r_top, double gap, double wall);

/* All voxels active, no grain stored.  0, or -1 (bad input / out of memory). */
int pk_rsa_vox_init(pk_rsa_vox *v, const pk_box *b, double r_valid, double r_top, double gap,
                    double wall);
void pk_rsa_vox_free(pk_rsa_vox *v);

/* Mark the sub-voxels certainly inside the exclusion ball B(x, r + r_valid + Δd)
 * of a placed grain of radius r; voxels with none left leave the set. */
void pk_rsa_vox_cover(pk_rsa_vox *v, const double x[PK_MAXDIM], double r);

/* One draw: a point uniform over the active voxels (voxel id in *vid).
 * Returns 0, or 1 when the point fell in a sub-voxel known to be covered (a
 * certain rejection: x is not computed), or -1 if no voxel is left: no room
 * for any grain with r >= r_valid (saturation). */
int pk_rsa_vox_draw(const pk_rsa_vox *v, pk_rng *g, double x[PK_MAXDIM], uint64_t *vid);

/* 1 if a stored grain j has |x_j - x| < r + r_j + Δd (minimum image). */
int pk_rsa_vox_overlaps(const pk_rsa_vox *v, const double x[PK_MAXDIM], double r);

/* Store a placed grain in voxel vid (the one it was drawn in).  -1 if the voxel
 * is taken (cannot happen for non-overlapping grains with r >= r_valid). */
int pk_rsa_vox_store(pk_rsa_vox *v, uint64_t vid, const double x[PK_MAXDIM], double r);

#endif
