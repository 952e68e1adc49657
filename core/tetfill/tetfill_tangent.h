/* tetfill_tangent.h — Jerier's geometric procedure: a fifth sphere tangent to
 * four given spheres (Jerier et al. 2010 §2.1, Eqs. 1–9).
 *
 * Subtracting Eq. 1 from Eqs. 2–4 gives A x = b(r) (Eqs. 5–8), so
 * x = r x_a + x_b (Eq. 9), and Eq. 1 becomes α r² + 2β r + κ = 0 with
 * α = |x_a|² − 1, β = x_a·(x_b − c_1) − r_1, κ = |x_b − c_1|² − r_1².
 * det A = ±48 V_tet vanishes for coplanar centres: it is tested relative to
 * the quadruple's length scale ℓ (|det A| < PK_TANGENT_DET_TOL·(2ℓ)³) and
 * never divided by when singular.  Coordinates are taken relative to c_1 so
 * far-away (virtual) spheres cost no cancellation in |c|² − r². */
#ifndef PK_TETFILL_TANGENT_H
#define PK_TETFILL_TANGENT_H

#define PK_TANGENT_DET_TOL 1e-10

typedef enum pk_tangent_status {
    PK_TANGENT_OK = 0,   /* roots (possibly none) computed */
    PK_TANGENT_SINGULAR, /* det A ≈ 0 relative to ℓ³: coplanar quadruple */
} pk_tangent_status;

/* Positive radii only (a root r <= 0 is a sphere enclosing the four), ordered
 * ascending; each root's four tangency residuals ||x − c_k| − (r + r_k)| are
 * <= res_tol or the root is dropped.  *nroot = 0, 1 or 2. */
pk_tangent_status pk_tangent_sphere(const double c[4][3], const double r[4], double res_tol,
                                    double x[2][3], double rr[2], int *nroot);

/* A sphere of given radius rho tangent to three spheres (trilateration of
 * |x − c_k| = r_k + rho): 0, 1 or 2 centres in x, returned count.  packd's
 * "last resort" when the four-sphere root exceeds r_max (see tetfill.h). */
int pk_tangent_sphere3(const double c[3][3], const double r[3], double rho, double x[2][3]);

/* 1 if x lies inside the tetrahedron c[0..3] (either orientation). */
int pk_point_in_tet(const double c[4][3], const double x[3]);

#endif
