/* rsa_voxels.h — RSA's sampling set of "possibly free" voxels (internal to core/rsa/rsa.c).
 *
 * Late in an RSA run most uniform draws land in the exclusion zone of a placed
 * grain and are wasted.  This structure tiles the draw range with voxels, each
 * split into 64 sub-voxels (4³ or 8²) with one bit "known to be
 * covered", in 8 groups of 8.  The list holds the voxels with an open
 * sub-voxel, and once the open groups are fewer than half of those, the open
 * groups instead; the full ones leave it at its next compaction.  A draw
 * picks a listed voxel (group) uniformly and a point uniformly inside it; if the
 * point's sub-voxel is marked covered the draw is rejected at once, otherwise
 * it is tested exactly as before.  Why this is still true RSA: all voxels
 * (groups) have the same volume, so the point is uniform over the union of
 * the listed ones;
 * that union contains all the space still available to the grain (a bit is
 * set only when its sub-voxel lies inside the exclusion ball of one
 * placed grain, see pk_rsa_vox_cover), and the marked sub-voxels hold no
 * available point; rejection then leaves the accepted point uniform over the
 * available space — the law of a plain draw-until-accepted loop, with fewer
 * and cheaper wasted draws.
 *
 * Polydispersity: the set is built for a radius bound r_valid, the smallest
 * grain still to place.  A sub-voxel is cleared when it lies in
 * B(x_j, r_j + r_valid + Δd); exclusion balls only grow with the grain radius,
 * so the set stays valid for every later grain (r >= r_valid) and one set
 * serves the rest of a run, each placed grain marked once.  On walled axes
 * the lattice tiles the draw range of r_valid, the largest one; a larger grain
 * rejects draws outside its own range.
 *
 * The set holds only the bits (8 bytes a voxel, at most 4 more for the
 * list): the
 * exact test is the caller's (pk_grid), so the voxel edge
 * (2 r_valid + Δd)/√dim only sets the resolution of the marks. */
#ifndef PK_RSA_VOXELS_H
#define PK_RSA_VOXELS_H

#include <stdint.h>

#include "core/space/box.h"
#include "core/base/rng.h"

#define PK_RSA_DRAW_AHEAD 8

/* A voxel's 64 bits come in 8 groups of 8 sub-voxels (2×2×2 in 3D, 4×2 in
 * 2D), one byte each; a list of groups (entry voxel·8 + group) keeps only
 * the groups of a pocket of open space. */
#define PK_RSA_VOX_GROUPS 8

typedef struct pk_rsa_vox {
    pk_box box;
    double org[PK_MAXDIM]; /* lattice origin per axis */
    double e[PK_MAXDIM];   /* voxel edge per axis */
    double inv_e[PK_MAXDIM];
    int64_t n[PK_MAXDIM]; /* voxels per axis (1 on unused axes) */
    uint64_t nvox;
    double r_valid;       /* set valid for grains with r >= r_valid */
    double gap;           /* Δd */
    double margin;        /* absolute safety margin of the cover test */
    int sub;              /* sub-voxels per axis and voxel (sub^dim = 64) */
    double se[PK_MAXDIM]; /* sub-voxel edge per axis */
    /* bit of sub-voxel (lx, ly, lz): boff[0][lx] + boff[1][ly] + boff[2][lz]
     * (group·8 + place in the group) */
    uint8_t boff[PK_MAXDIM][8];
    uint8_t lsub[64][PK_MAXDIM]; /* the inverse: sub-voxel coordinates of a bit */
    uint64_t row_bits[256];      /* bits of the sub-voxels lx with bit lx of the index set,
                                    in row (ly, lz) = (0, 0) */
    uint64_t *covered;           /* [nvox] sub-voxels known covered */
    uint32_t *list;              /* voxels (grouped: groups) with an open sub-voxel at the
                                    last compaction (NULL before the first: all voxels) */
    uint64_t nlist;
    uint64_t nstale;      /* listed voxels (groups) full since */
    int grouped;          /* list entries are groups, voxel·8 + group */
    uint64_t open_groups; /* groups with an open sub-voxel, all voxels */
    /* draws picked ahead (rsa_voxels.c, pk_rsa_vox_draw) */
    uint32_t pick[PK_RSA_DRAW_AHEAD], id[PK_RSA_DRAW_AHEAD];
    int head, primed;
} pk_rsa_vox;

/* Number of voxels a set for (b, r_valid, gap) would hold, or 0 when the
 * structure cannot serve this box (a walled axis with no draw range, or a
 * periodic edge not larger than twice the largest contact distance 2 r_top + Δd).
 * wall: the clearance kept at walls (Δd/2, or 0 with wall_gap none). */
uint64_t pk_rsa_vox_count(const pk_box *b, double r_valid, double r_top, double gap, double wall);

/* All voxels active.  0, or -1 (bad input / out of memory). */
int pk_rsa_vox_init(pk_rsa_vox *v, const pk_box *b, double r_valid, double r_top, double gap,
                    double wall);
void pk_rsa_vox_free(pk_rsa_vox *v);

/* Mark the sub-voxels certainly inside the exclusion ball B(x, r + r_valid + Δd)
 * of a placed grain of radius r; voxels with none left leave the set. */
void pk_rsa_vox_cover(pk_rsa_vox *v, const double x[PK_MAXDIM], double r);

/* One draw: a point uniform over the active voxels.
 * Returns 0, or 1 when the point fell in a sub-voxel known to be covered (a
 * certain rejection: x is not computed), or -1 if no voxel is left: no room
 * for any grain with r >= r_valid (saturation). */
int pk_rsa_vox_draw(pk_rsa_vox *v, pk_rng *g, double x[PK_MAXDIM]);

/* The bit of sub-voxel l (coordinates 0..sub-1 per axis) in its voxel's word. */
static inline unsigned pk_rsa_vox_bit(const pk_rsa_vox *v, const int l[PK_MAXDIM])
{
    unsigned b = 0;
    for (int k = 0; k < v->box.dim; k++)
        b += v->boff[k][l[k]];
    return b;
}

#endif
