/* homog_stiffness.c — the contact Hessian (4.11)–(4.14) and its entry into
 * the sparse free stiffness.  Contract: homog_stiffness.h. */
#include "homog_stiffness.h"

void pk_homog_pair_hessian(double E, double len, double eps, const double *l, double H[9])
{
    double R = eps + len, c = E / len;
    for (int a = 0; a < 3; a++)
        for (int b = 0; b < 3; b++)
            H[3 * a + b] = c * (R * l[a] * l[b] / (len * len) - (a == b ? eps : 0));
}

int pk_homog_add_pair_K(pk_sparse_sym *K, int dim, int32_t di, int32_t dj, const double H[9])
{
    int rc = 0;
    for (int a = 0; a < dim; a++)
        for (int b = 0; b < dim; b++) {
            double h = H[3 * a + b];
            if (di >= 0 && a <= b)
                rc |= pk_sparse_sym_add(K, di + a, di + b, h);
            if (dj >= 0 && a <= b)
                rc |= pk_sparse_sym_add(K, dj + a, dj + b, h);
            if (di >= 0 && dj >= 0)
                rc |= pk_sparse_sym_add(K, di + a, dj + b, -h);
        }
    return rc ? -1 : 0;
}
