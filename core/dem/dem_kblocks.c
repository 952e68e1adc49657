/* dem_kblocks.c — the contact stiffness as a compact block list for repeated
 * K·v on one mask; contract: dem_kblocks.h. */
#include "dem_kblocks.h"

#include <stdlib.h>
#include <string.h>

void pk_dem_kblocks_free(pk_dem_kblocks *kb)
{
    free(kb->i);
    free(kb->j);
    free(kb->side);
    free(kb->l);
    free(kb->a);
    free(kb->b);
    memset(kb, 0, sizeof *kb);
}

int pk_dem_kblocks_build(pk_dem_kblocks *kb, const pk_dem_pairs *c, double E, const uint8_t *mask)
{
    pk_dem_kblocks_free(kb);
    size_t cap = c->n ? c->n : 1;
    kb->i = malloc(cap * sizeof *kb->i);
    kb->j = malloc(cap * sizeof *kb->j);
    kb->side = malloc(cap);
    kb->l = malloc(3 * cap * sizeof *kb->l);
    kb->a = malloc(cap * sizeof *kb->a);
    kb->b = malloc(cap * sizeof *kb->b);
    if (!kb->i || !kb->j || !kb->side || !kb->l || !kb->a || !kb->b) {
        pk_dem_kblocks_free(kb);
        return -1;
    }
    size_t n = 0;
    for (size_t p = 0; p < c->n; p++) { /* the contacts pk_dem_kv visits, in its order */
        if (!(c->eps[p] >= 0) || !(c->len[p] > 0))
            continue;
        int32_t i = c->i[p], j = c->j[p];
        uint8_t side = (uint8_t)((mask[i] != 0) | (mask[j] != 0) << 1);
        if (!side)
            continue;
        kb->i[n] = i;
        kb->j[n] = j;
        kb->side[n] = side;
        memcpy(&kb->l[3 * n], &c->l[3 * p], 3 * sizeof *kb->l);
        pk_dem_kblock_coef(pk_dem_pair_E(c, p, E), c->len[p], c->eps[p], &kb->a[n], &kb->b[n]);
        n++;
    }
    kb->n = n;
    return 0;
}

/* The product for any dim (3D). */
static inline void kv_loop(const pk_dem_kblocks *kb, const int dim, const double *v, double *out)
{
    for (size_t p = 0; p < kb->n; p++) {
        size_t i = (size_t)kb->i[p], j = (size_t)kb->j[p];
        int mi = kb->side[p] & 1, mj = kb->side[p] >> 1;
        const double *l = &kb->l[3 * p];
        double d[3], ld = 0;
        /* (K v)_i = Σ_j k_ij (v_j − v_i) by (4.14), held grains at v = 0 */
        for (int a = 0; a < dim; a++) {
            d[a] = (mj ? v[3 * j + a] : 0) - (mi ? v[3 * i + a] : 0);
            ld += l[a] * d[a];
        }
        for (int a = 0; a < dim; a++) {
            double kd = kb->a[p] * d[a] - kb->b[p] * ld * l[a];
            if (mi)
                out[3 * i + a] += kd;
            if (mj)
                out[3 * j + a] -= kd;
        }
    }
}

/* kv_loop for dim = 2 written out (the compiler kept the axis loops; the
 * variants measured: docs/perf/dem.md, kv_2d). */
static void kv_2d(const pk_dem_kblocks *kb, const double *v, double *out)
{
    for (size_t p = 0; p < kb->n; p++) {
        size_t i = (size_t)kb->i[p], j = (size_t)kb->j[p];
        int mi = kb->side[p] & 1, mj = kb->side[p] >> 1;
        const double *l = &kb->l[3 * p];
        double d0 = (mj ? v[3 * j] : 0) - (mi ? v[3 * i] : 0);
        double d1 = (mj ? v[3 * j + 1] : 0) - (mi ? v[3 * i + 1] : 0);
        double ld = 0;
        ld += l[0] * d0;
        ld += l[1] * d1;
        double a = kb->a[p], bld = kb->b[p] * ld;
        double k0 = a * d0 - bld * l[0], k1 = a * d1 - bld * l[1];
        if (mi)
            out[3 * i] += k0, out[3 * i + 1] += k1;
        if (mj)
            out[3 * j] -= k0, out[3 * j + 1] -= k1;
    }
}

void pk_dem_kblocks_kv(const pk_dem_kblocks *kb, int dim, size_t np, const double *v, double *out)
{
    memset(out, 0, 3 * np * sizeof *out);
    if (dim == 2)
        kv_2d(kb, v, out);
    else
        kv_loop(kb, dim, v, out);
}
