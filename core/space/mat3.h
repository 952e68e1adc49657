/* mat3.h — small dense 3×3 tensors (F̄, P̄, branch maps; row-major 3×3,
 * only the leading dim×dim block is used; unused entries are kept 0, and
 * F[2][2] = 1 in 2D so det/inverse work unchanged). */
#ifndef PK_MAT3_H
#define PK_MAT3_H

#include <math.h>

/* y = A x (3×3 row-major) */
static inline void pk_m3_vec(const double A[9], const double x[3], double y[3])
{
    for (int a = 0; a < 3; a++)
        y[a] = A[3 * a] * x[0] + A[3 * a + 1] * x[1] + A[3 * a + 2] * x[2];
}

static inline double pk_m3_det(const double A[9])
{
    return A[0] * (A[4] * A[8] - A[5] * A[7]) - A[1] * (A[3] * A[8] - A[5] * A[6]) +
        A[2] * (A[3] * A[7] - A[4] * A[6]);
}

/* B = A^{-1}; returns det(A) (B untouched when det == 0). */
static inline double pk_m3_inv(const double A[9], double B[9])
{
    double d = pk_m3_det(A);
    if (d == 0)
        return 0;
    double c[9] = {A[4] * A[8] - A[5] * A[7], A[2] * A[7] - A[1] * A[8], A[1] * A[5] - A[2] * A[4],
                   A[5] * A[6] - A[3] * A[8], A[0] * A[8] - A[2] * A[6], A[2] * A[3] - A[0] * A[5],
                   A[3] * A[7] - A[4] * A[6], A[1] * A[6] - A[0] * A[7], A[0] * A[4] - A[1] * A[3]};
    for (int k = 0; k < 9; k++)
        B[k] = c[k] / d;
    return d;
}

/* C = A B */
static inline void pk_m3_mul(const double A[9], const double B[9], double C[9])
{
    for (int a = 0; a < 3; a++)
        for (int b = 0; b < 3; b++)
            C[3 * a + b] = A[3 * a] * B[b] + A[3 * a + 1] * B[3 + b] + A[3 * a + 2] * B[6 + b];
}

/* Smallest singular value of the leading dim×dim block of F: the square
 * root of the smallest eigenvalue of FᵗF (closed form; trigonometric
 * solution of the cubic in 3D). */
static inline double pk_m3_sigma_min(const double F[9], int dim)
{
    double C[9];
    for (int a = 0; a < 3; a++)
        for (int b = 0; b < 3; b++)
            C[3 * a + b] = F[a] * F[b] + F[3 + a] * F[3 + b] + F[6 + a] * F[6 + b];
    if (dim == 2) {
        double tr = C[0] + C[4], det = C[0] * C[4] - C[1] * C[3];
        double disc = sqrt(fmax(0, 0.25 * tr * tr - det));
        return sqrt(fmax(0, 0.5 * tr - disc));
    }
    double q = (C[0] + C[4] + C[8]) / 3;
    double p1 = C[1] * C[1] + C[2] * C[2] + C[5] * C[5];
    double p2 =
        (C[0] - q) * (C[0] - q) + (C[4] - q) * (C[4] - q) + (C[8] - q) * (C[8] - q) + 2 * p1;
    double p = sqrt(p2 / 6);
    if (!(p > 0))
        return sqrt(fmax(0, q));
    double B[9];
    for (int k = 0; k < 9; k++)
        B[k] = (C[k] - (k % 4 == 0 ? q : 0)) / p;
    double rr = 0.5 * pk_m3_det(B);
    double phi = rr <= -1 ? M_PI / 3 : rr >= 1 ? 0 : acos(rr) / 3;
    double lmin = q + 2 * p * cos(phi + 2 * M_PI / 3);
    return sqrt(fmax(0, lmin));
}

static inline void pk_m3_identity(double A[9])
{
    for (int k = 0; k < 9; k++)
        A[k] = (k % 4 == 0) ? 1.0 : 0.0;
}

#endif
