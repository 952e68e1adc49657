/* homog_rve.h — the discrete RVE of a homogenization run (Meier 2009 §3.5,
 * §4.3).
 *
 *  - periodic BC: the primaries of a fully periodic packing; contacts by
 *    minimum image under the deformed lattice F̄L; grain 0 is pinned at F̄X₀
 *    to remove the translation mode (the simpler equivalent of (4.28)–(4.34),
 *    which handles particle flux, Remark 5.3, by construction).
 *  - Taylor / restricted Taylor: the packing is unfolded — every grain that
 *    crosses a periodic side gets its replicas (up to 4 copies in 2D, 8 in
 *    3D) as independent particles — and the hull 𝓑 (3.14) is the set of
 *    copies whose disk/ball meets the box boundary.  On walled axes (no
 *    replicas) the hull is the grains within one smallest diameter of a wall.
 *    Taylor prescribes every particle (4.24), restricted Taylor the hull
 *    (4.27).
 * V_rve = the undeformed box measure (= |L_ab × L_ad|, (5.1)). */
#ifndef PK_HOMOG_RVE_H
#define PK_HOMOG_RVE_H

#include <stddef.h>
#include <stdint.h>

#include "core/space/box.h"
#include "core/space/particles.h"

typedef enum pk_homog_bc { PK_BC_TAYLOR = 0, PK_BC_RESTRICTED_TAYLOR, PK_BC_PERIODIC } pk_homog_bc;

const char *pk_homog_bc_name(pk_homog_bc bc);

typedef struct pk_homog_rve {
    int dim;
    pk_homog_bc bc;
    size_t n;
    double *X;        /* [n][3] reference centres */
    double *r;        /* [n] radii (after any inflation) */
    int32_t *grain;   /* [n] index of the source grain */
    int32_t *species; /* [n] species (size class) of the source grain: selects E_n,ij */
    uint8_t *fixed;   /* [n] 1 = position prescribed, x = F̄X */
    uint8_t *hull;    /* [n] 1 = in the boundary set 𝓑 */
    int periodic;     /* contacts by minimum image across L */
    double L[3];
    double V; /* undeformed RVE measure */
} pk_homog_rve;

/* Build the RVE from a packing.  radius_factor (>= 1) inflates every radius
 * (initial-state policy).  0 on success; -1 with a message in err. */
int pk_homog_rve_build(const pk_box *b, const pk_particles *p, pk_homog_bc bc, double radius_factor,
                       pk_homog_rve *rve, char *err, size_t errlen);

void pk_homog_rve_free(pk_homog_rve *rve);

/* Build from explicit arrays (tests): X [n][3], r [n], fixed [n]; periodic
 * with box L when periodic != 0.  The hull is set equal to fixed. */
int pk_homog_rve_from_arrays(int dim, pk_homog_bc bc, size_t n, const double *X, const double *r,
                             const uint8_t *fixed, int periodic, const double L[3], double V,
                             pk_homog_rve *rve);

#endif
