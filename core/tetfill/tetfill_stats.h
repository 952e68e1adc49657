/* tetfill_stats.h — characterisation of a filled mesh (Jerier §3.1):
 * overlaps, coordination (Eq. 15), fabric tensor (Eq. 17) and eigenvalues,
 * solid fraction overall and per mesh region, spheres per tet, boundary
 * clearance.
 *
 * Contacts (sphere pairs only; boundary faces and virtual spheres are not
 * counted; z = 2 N_c / N over all spheres, Eq. 15).  The paper gives no
 * tolerance, so three nested definitions are reported:
 *   contact  gap <= τ = max(ε, 1e-9)·r_min — the filler's own z_min test;
 *            z_mean, the histogram and the fabric use it;
 *   tangent  gap <= PK_TETFILL_TANGENT_TOL·r_min — the tangencies the solve
 *            creates (a root whose residual exceeds this bound is dropped,
 *            tetfill.c) plus every overlap; z counted this way is flat from
 *            1e-12 to 1e-6 r_min (docs/tetfill.md), so it does not depend on
 *            the exact value;
 *   touching gap <= 0 — Jerier's own code (SpherePadder counts distance <= 0);
 *            a tangency solved in floating point falls on either side of 0. */
#ifndef PK_TETFILL_STATS_H
#define PK_TETFILL_STATS_H

#include <stddef.h>
#include <stdint.h>

#include "core/space/grid.h"
#include "core/mesh/mesh.h"
#include "core/space/particles.h"

#define PK_TETFILL_ZHIST 16         /* coordination histogram bins 0..15 (last: >= 15) */
#define PK_TETFILL_THIST 32         /* spheres-per-tet histogram bins 0..31 (last: >= 31) */
#define PK_TETFILL_TANGENT_TOL 1e-9 /* tangency residual bound / r_min (tetfill.c) */

/* Which of the three contact definitions a pair with this gap meets. */
enum { PK_CONTACT_TOL = 1, PK_CONTACT_TANGENT = 2, PK_CONTACT_TOUCHING = 4 };
int pk_tetfill_contact_kind(double gap, double r_min, double eps);

/* Coordination by the three definitions (the filler reports it after steps 1–6). */
typedef struct pk_tetfill_coord {
    size_t n, contacts, tangent, touching;
    double z, z_tangent, z_touching;
} pk_tetfill_coord;

typedef struct pk_tetfill_measures {
    size_t n;
    double overlap_max;                         /* largest overlap / r_min (0 if none) */
    double overlap_mean;                        /* mean overlap / r_min over overlapping pairs */
    size_t pairs_overlapping, pairs_over_bound; /* bound: ε r_min (1 + 1e-9) */
    size_t contacts;
    double z_mean;            /* 2 N_c / N */
    size_t contacts_tangent;  /* pairs with gap <= PK_TETFILL_TANGENT_TOL r_min */
    double z_tangent;         /* 2 N_c / N with those */
    size_t contacts_touching; /* pairs with gap <= 0 exactly (no tolerance) */
    double z_touching;        /* 2 N_c / N with those: the count of Jerier's
                                * SpherePadder (distance <= 0) and of a DEM
                                * code that detects contacts by overlap; a
                                * tangency solved in floating point lands on
                                * either side of 0, so about half count */
    int64_t z_hist[PK_TETFILL_ZHIST];
    double fabric[9];     /* F_αβ (Eq. 17), row-major */
    double fabric_eig[3]; /* ascending */
    double phi;           /* Σ V_i / V_mesh */
    size_t nregion;
    int64_t *region_id; /* [nregion] ascending */
    double *region_phi; /* [nregion] Σ V_i (centre in region) / region volume */
    double spheres_per_tet_mean;
    int64_t t_hist[PK_TETFILL_THIST];
    size_t outside;            /* centres in no tet */
    double min_wall_clearance; /* min over spheres of (distance to boundary − r) / r_min */
} pk_tetfill_measures;

/* m checked and at box origin 0.  0 or -1 (memory). */
int pk_tetfill_measure(const pk_mesh *m, const pk_particles *p, double r_min, double eps,
                       pk_tetfill_measures *out);
void pk_tetfill_measures_free(pk_tetfill_measures *out);

/* Coordination of p's grains [first, n) (all held by g) by the three
 * definitions: one grid query per grain. */
void pk_tetfill_coordination(const pk_grid *g, const pk_particles *p, size_t first, double r_min,
                             double eps, pk_tetfill_coord *out);

/* Eigenvalues (ascending) of a symmetric 3×3 matrix (row-major). */
void pk_sym3_eigenvalues(const double a[9], double ev[3]);

#endif
