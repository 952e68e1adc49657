/* tetfill_tangent.c — the fifth sphere tangent to four (Jerier §2.1,
 * Eqs. 1–9).  Contract: core/tetfill/tetfill_tangent.h. */
#include "tetfill_tangent.h"
#include "tetfill_tangent_internal.h"

#include <math.h>
#include <string.h>

static double det3(const double a[3][3])
{
    return a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) -
        a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
        a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
}

/* Eq. 6 with c_1 moved to the origin: row k = 2 (c_1 − c_{k+1}). */
static void matrix_A(const double c[4][3], double A[3][3], double *ell)
{
    *ell = 0;
    for (int k = 0; k < 3; k++) {
        double l2 = 0;
        for (int j = 0; j < 3; j++) {
            A[k][j] = 2 * (c[0][j] - c[k + 1][j]);
            l2 += (c[0][j] - c[k + 1][j]) * (c[0][j] - c[k + 1][j]);
        }
        *ell = fmax(*ell, sqrt(l2));
    }
}

double pk_tangent_det(const double c[4][3])
{
    double A[3][3], ell;
    matrix_A(c, A, &ell);
    return det3(A);
}

pk_tangent_status pk_tangent_sphere(const double c[4][3], const double r[4], double res_tol,
                                    double x[2][3], double rr[2], int *nroot)
{
    *nroot = 0;
    double A[3][3], ell;
    matrix_A(c, A, &ell);
    double D = det3(A);
    if (!(fabs(D) >= PK_TANGENT_DET_TOL * 8 * ell * ell * ell))
        return PK_TANGENT_SINGULAR;
    /* relative to c_1: e_k = r_{k+1}² − r_1² − |c_{k+1} − c_1|² (Eq. 8 at r = 0),
     * d_k = 2 (r_1 − r_{k+1}) (the coefficient of −r) */
    double e[3], d[3];
    for (int k = 0; k < 3; k++) {
        double l2 = 0;
        for (int j = 0; j < 3; j++)
            l2 += (c[k + 1][j] - c[0][j]) * (c[k + 1][j] - c[0][j]);
        e[k] = r[k + 1] * r[k + 1] - r[0] * r[0] - l2;
        d[k] = 2 * (r[0] - r[k + 1]);
    }
    /* Cramer's rule: x_b = A⁻¹ e, x_a = −A⁻¹ d (Eq. 9) */
    double xa[3], xb[3];
    for (int j = 0; j < 3; j++) {
        double M[3][3];
        memcpy(M, A, sizeof M);
        for (int k = 0; k < 3; k++)
            M[k][j] = e[k];
        xb[j] = det3(M) / D;
        for (int k = 0; k < 3; k++)
            M[k][j] = d[k];
        xa[j] = -det3(M) / D;
    }
    double alpha = xa[0] * xa[0] + xa[1] * xa[1] + xa[2] * xa[2] - 1;
    double beta = xa[0] * xb[0] + xa[1] * xb[1] + xa[2] * xb[2] - r[0];
    double kappa = xb[0] * xb[0] + xb[1] * xb[1] + xb[2] * xb[2] - r[0] * r[0];
    double cand[2];
    int nc = 0;
    if (fabs(alpha) <= 1e-12) { /* linear case */
        if (beta != 0)
            cand[nc++] = -kappa / (2 * beta);
    } else {
        double disc = beta * beta - alpha * kappa;
        if (disc < 0)
            return PK_TANGENT_OK; /* no tangent sphere */
        double q = -(beta + copysign(sqrt(disc), beta));
        cand[nc++] = q / alpha;
        if (q != 0)
            cand[nc++] = kappa / q;
    }
    if (nc == 2 && cand[1] < cand[0]) {
        double s = cand[0];
        cand[0] = cand[1];
        cand[1] = s;
    }
    for (int i = 0; i < nc; i++) {
        double rad = cand[i];
        if (!(rad > 0) || !isfinite(rad))
            continue;
        double p[3];
        for (int j = 0; j < 3; j++)
            p[j] = c[0][j] + rad * xa[j] + xb[j];
        int ok = 1;
        for (int k = 0; k < 4 && ok; k++) {
            double d2 = 0;
            for (int j = 0; j < 3; j++)
                d2 += (p[j] - c[k][j]) * (p[j] - c[k][j]);
            ok = fabs(sqrt(d2) - (rad + r[k])) <= res_tol;
        }
        if (!ok)
            continue;
        memcpy(x[*nroot], p, sizeof p);
        rr[(*nroot)++] = rad;
    }
    return PK_TANGENT_OK;
}

int pk_point_in_tet(const double c[4][3], const double x[3])
{
    static const int f[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
    int sign = 0;
    for (int k = 0; k < 4; k++) {
        double a[3][3];
        for (int j = 0; j < 3; j++) {
            a[0][j] = c[f[k][1]][j] - c[f[k][0]][j];
            a[1][j] = c[f[k][2]][j] - c[f[k][0]][j];
            a[2][j] = x[j] - c[f[k][0]][j];
        }
        double v = det3(a);
        int s = v > 0 ? 1 : v < 0 ? -1 : 0;
        if (s == 0)
            continue;
        if (sign == 0)
            sign = s;
        else if (s != sign)
            return 0;
    }
    return 1;
}

int pk_tangent_sphere3(const double c[3][3], const double r[3], double rho, double x[2][3])
{
    double ex[3], ey[3], ez[3], v[3], d = 0, i = 0, j = 0;
    for (int k = 0; k < 3; k++) {
        ex[k] = c[1][k] - c[0][k];
        d += ex[k] * ex[k];
    }
    d = sqrt(d);
    if (!(d > 0))
        return 0;
    for (int k = 0; k < 3; k++) {
        ex[k] /= d;
        v[k] = c[2][k] - c[0][k];
        i += ex[k] * v[k];
    }
    double ny = 0;
    for (int k = 0; k < 3; k++) {
        ey[k] = v[k] - i * ex[k];
        ny += ey[k] * ey[k];
    }
    ny = sqrt(ny);
    if (!(ny > 1e-10 * d)) /* collinear centres */
        return 0;
    for (int k = 0; k < 3; k++) {
        ey[k] /= ny;
        j += ey[k] * v[k];
    }
    ez[0] = ex[1] * ey[2] - ex[2] * ey[1];
    ez[1] = ex[2] * ey[0] - ex[0] * ey[2];
    ez[2] = ex[0] * ey[1] - ex[1] * ey[0];
    double R1 = r[0] + rho, R2 = r[1] + rho, R3 = r[2] + rho;
    double px = (R1 * R1 - R2 * R2 + d * d) / (2 * d);
    double py = (R1 * R1 - R3 * R3 + i * i + j * j) / (2 * j) - (i / j) * px;
    double z2 = R1 * R1 - px * px - py * py;
    if (z2 < 0)
        return 0;
    double pz = sqrt(z2);
    for (int s = 0; s < 2; s++)
        for (int k = 0; k < 3; k++)
            x[s][k] = c[0][k] + px * ex[k] + py * ey[k] + (s ? -pz : pz) * ez[k];
    return pz > 0 ? 2 : 1;
}
