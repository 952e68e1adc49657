/* fe2_material_linear.c — the linear elastic surrogate of the RVE: small
 * strain, P̄ = λ tr(ε) 1 + 2μ ε with ε = sym(F̄ − 1), constant Ā (the patch
 * tests and the macro solver's own tests).  Contract: fe2_material_linear.h. */
#include "fe2_material_linear.h"

#include <string.h>

/* (i, j) → position in the (11, 12, 21, 22) order */
#define IJ(i, j) (2 * (i) + (j))

static int linear_eval(void *ctx, size_t g, const double F[4], double P[4], double A[16],
                       pk_fe2_gp_info *info, char *why, size_t whylen)
{
    (void)g, (void)why, (void)whylen;
    const pk_fe2_linear_elastic *le = ctx;
    const double e11 = F[0] - 1, e22 = F[3] - 1, e12 = 0.5 * (F[1] + F[2]);
    const double tr = e11 + e22;
    P[IJ(0, 0)] = le->lambda * tr + 2 * le->mu * e11;
    P[IJ(1, 1)] = le->lambda * tr + 2 * le->mu * e22;
    P[IJ(0, 1)] = P[IJ(1, 0)] = 2 * le->mu * e12;
    /* ∂P_ij/∂F_kl = λ δij δkl + μ (δik δjl + δil δjk) */
    for (int i = 0; i < 2; i++)
        for (int j = 0; j < 2; j++)
            for (int k = 0; k < 2; k++)
                for (int l = 0; l < 2; l++)
                    A[4 * IJ(i, j) + IJ(k, l)] = le->lambda * (i == j) * (k == l) +
                        le->mu * ((i == k) * (j == l) + (i == l) * (j == k));
    if (info) {
        memset(info, 0, sizeof *info);
        /* Φ̄ = λ/2 tr²ε + μ ε:ε */
        info->energy =
            0.5 * le->lambda * tr * tr + le->mu * (e11 * e11 + e22 * e22 + 2 * e12 * e12);
    }
    return 0;
}

static int linear_commit(void *ctx, size_t g)
{
    (void)ctx, (void)g;
    return 0;
}

pk_fe2_material pk_fe2_linear_elastic_material(const pk_fe2_linear_elastic *le)
{
    pk_fe2_material m = {"linear_elastic", (void *)le, linear_eval, linear_commit};
    return m;
}
