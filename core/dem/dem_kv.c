/* dem_kv.c — products with the contact stiffness K = ∂²Φ_n/∂x∂x (4.11)–(4.14)
 * and its Gershgorin bound, from the last evaluation; contract: dem_contact.h. */
#include "dem_contact.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* k_ij·d with k_ij = E/|l| [ε 1 − R n⊗n] (4.12)₁ (pk_dem_kblock_coef) */
static inline void kblock_apply(int dim, double E, double len, double eps, const double *l,
                                const double *d, double *out)
{
    double a, b, ld = 0;
    pk_dem_kblock_coef(E, len, eps, &a, &b);
    for (int k = 0; k < dim; k++)
        ld += l[k] * d[k];
    for (int k = 0; k < dim; k++)
        out[k] = a * d[k] - b * ld * l[k];
}

/* The K·v loop; pk_dem_kv calls it with dim a constant (2 or 3), so the
 * compiler unrolls the axis loops — the same operations in the same order,
 * at fewer instructions (it runs 40 times per DR estimate refresh). */
static inline void kv_loop(const pk_dem_pairs *c, const int dim, double E, const uint8_t *mask,
                           const double *v, double *out)
{
    for (size_t p = 0; p < c->n; p++) {
        if (!(c->eps[p] >= 0) || !(c->len[p] > 0))
            continue;
        size_t i = (size_t)c->i[p], j = (size_t)c->j[p];
        int mi = mask[i] != 0, mj = mask[j] != 0;
        if (!mi && !mj)
            continue;
        double d[3] = {0, 0, 0}, kd[3];
        for (int a = 0; a < dim; a++)
            d[a] = (mj ? v[3 * j + a] : 0) - (mi ? v[3 * i + a] : 0);
        /* (K v)_i = Σ_j k_ij (v_j − v_i) by (4.14) */
        kblock_apply(dim, pk_dem_pair_E(c, p, E), c->len[p], c->eps[p], &c->l[3 * p], d, kd);
        for (int a = 0; a < dim; a++) {
            if (mi)
                out[3 * i + a] += kd[a];
            if (mj)
                out[3 * j + a] -= kd[a];
        }
    }
}

void pk_dem_kv(const pk_dem_pairs *c, int dim, size_t np, double E, const uint8_t *mask,
               const double *v, double *out)
{
    memset(out, 0, 3 * np * sizeof *out);
    if (dim == 2)
        kv_loop(c, 2, E, mask, v, out);
    else
        kv_loop(c, dim, E, mask, v, out);
}

double pk_dem_gershgorin(const pk_dem_pairs *c, int dim, size_t np, double E, const uint8_t *mask)
{
    double *row = calloc(3 * (np ? np : 1), sizeof *row);
    if (!row)
        return INFINITY;
    for (size_t p = 0; p < c->n; p++) {
        if (!(c->eps[p] >= 0) || !(c->len[p] > 0))
            continue;
        size_t i = (size_t)c->i[p], j = (size_t)c->j[p];
        const double *l = &c->l[3 * p];
        double len = c->len[p], eps = c->eps[p], R = eps + len;
        double cc = pk_dem_pair_E(c, p, E) / len;
        for (int a = 0; a < dim; a++) {
            double s = 0; /* Σ_b |k_ab| */
            for (int b = 0; b < dim; b++)
                s += fabs(cc * ((a == b ? eps : 0) - R * l[a] * l[b] / (len * len)));
            /* the block enters the diagonal of both and the off-diagonal once */
            if (mask[i])
                row[3 * i + a] += s * (mask[j] ? 2 : 1);
            if (mask[j])
                row[3 * j + a] += s * (mask[i] ? 2 : 1);
        }
    }
    double m = 0;
    for (size_t k = 0; k < 3 * np; k++)
        m = fmax(m, row[k]);
    free(row);
    return m;
}
