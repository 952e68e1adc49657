/* fe2_fields.c — Cauchy stress, von Mises stress, deformed volume of FE².
 * Contract: fe2_fields.h. */
#include "fe2_fields.h"

#include <math.h>

void pk_fe2_cauchy(const double F[4], const double P[4], double sigma[4])
{
    const double J = F[0] * F[3] - F[1] * F[2];
    for (int i = 0; i < 2; i++)
        for (int j = 0; j < 2; j++) /* σ_ij = J⁻¹ P_iK F_jK */
            sigma[2 * i + j] = (P[2 * i] * F[2 * j] + P[2 * i + 1] * F[2 * j + 1]) / J;
}

double pk_fe2_von_mises(const double sigma[4])
{
    const double s12 = 0.5 * (sigma[1] + sigma[2]), m = 0.5 * (sigma[0] + sigma[3]);
    const double d11 = sigma[0] - m, d22 = sigma[3] - m;
    return sqrt(1.5 * (d11 * d11 + d22 * d22 + 2 * s12 * s12));
}

double pk_fe2_deformed_volume(const pk_fe2_mesh *m, const double *F)
{
    double v = 0;
    for (size_t g = 0; g < pk_fe2_gauss_count(m); g++) {
        double w;
        pk_fe2_gauss_point(m, g, NULL, NULL, &w);
        const double *f = &F[4 * g];
        v += w * (f[0] * f[3] - f[1] * f[2]);
    }
    return v;
}
