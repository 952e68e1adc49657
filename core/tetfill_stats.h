/* tetfill_stats.h — characterisation of a filled mesh (Jerier §3.1, spec §4.4):
 * overlaps, coordination (Eq. 15), fabric tensor (Eq. 17) and eigenvalues,
 * solid fraction overall and per mesh region, spheres per tet, boundary
 * clearance.  Contacts: gap <= τ = max(ε r_min, 1e-9 r_min) (z_mean, the
 * histogram and the fabric); z_touching counts gap <= 0 only. */
#ifndef PK_TETFILL_STATS_H
#define PK_TETFILL_STATS_H

#include <stddef.h>
#include <stdint.h>

#include "mesh.h"
#include "particles.h"

#define PK_TETFILL_ZHIST 16   /* coordination histogram bins 0..15 (last: >= 15) */
#define PK_TETFILL_THIST 32   /* spheres-per-tet histogram bins 0..31 (last: >= 31) */

typedef struct pk_tetfill_measures {
    size_t n;
    double overlap_max;        /* largest overlap / r_min (0 if none) */
    double overlap_mean;       /* mean overlap / r_min over overlapping pairs */
    size_t pairs_overlapping, pairs_over_bound;   /* bound: ε r_min (1 + 1e-9) */
    size_t contacts;
    double z_mean;             /* 2 N_c / N */
    size_t contacts_touching;  /* pairs with gap <= 0 exactly (no tolerance) */
    double z_touching;         /* 2 N_c / N with those: the count of Jerier's
                                * SpherePadder (distance <= 0) and of a DEM
                                * code that detects contacts by overlap; a
                                * tangency solved in floating point lands on
                                * either side of 0, so about half count */
    int64_t z_hist[PK_TETFILL_ZHIST];
    double fabric[9];          /* F_αβ (Eq. 17), row-major */
    double fabric_eig[3];      /* ascending */
    double phi;                /* Σ V_i / V_mesh */
    size_t nregion;
    int64_t *region_id;        /* [nregion] ascending */
    double *region_phi;        /* [nregion] Σ V_i (centre in region) / region volume */
    double spheres_per_tet_mean;
    int64_t t_hist[PK_TETFILL_THIST];
    size_t outside;            /* centres in no tet */
    double min_wall_clearance; /* min over spheres of (distance to boundary − r) / r_min */
} pk_tetfill_measures;

/* m checked and at box origin 0.  0 or -1 (memory). */
int pk_tetfill_measure(const pk_mesh *m, const pk_particles *p, double r_min, double eps,
                       pk_tetfill_measures *out);
void pk_tetfill_measures_free(pk_tetfill_measures *out);

/* Eigenvalues (ascending) of a symmetric 3×3 matrix (row-major). */
void pk_sym3_eigenvalues(const double a[9], double ev[3]);

#endif
