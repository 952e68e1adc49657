/* edmd_order.c — memory order of the grains: sorted along a Morton (Z-order)
 * curve of cells about one mean diameter wide, so that neighbours in space
 * are neighbours in the engine's arrays (fewer cache misses per event).
 * Contract: edmd_spatial_order / edmd_reorder in core/edmd/edmd_state.h. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "edmd_state.h"

typedef struct keyed {
    uint64_t key;
    size_t i;
} keyed;

static int by_key(const void *a, const void *b)
{
    const keyed *x = a, *y = b;
    if (x->key != y->key)
        return x->key < y->key ? -1 : 1;
    return x->i < y->i ? -1 : x->i > y->i; /* stable: deterministic */
}

/* Spread the low 21 bits of v to every third bit. */
static uint64_t spread3(uint64_t v)
{
    v &= 0x1fffff;
    v = (v | v << 32) & 0x1f00000000ffffull;
    v = (v | v << 16) & 0x1f0000ff0000ffull;
    v = (v | v << 8) & 0x100f00f00f00f00full;
    v = (v | v << 4) & 0x10c30c30c30c30c3ull;
    v = (v | v << 2) & 0x1249249249249249ull;
    return v;
}

int edmd_spatial_order(const pk_box *b, const double *x, size_t n, double h, size_t *perm)
{
    keyed *k = malloc((n ? n : 1) * sizeof *k);
    if (!k)
        return -1;
    for (size_t i = 0; i < n; i++) {
        uint64_t key = 0;
        for (int d = 0; d < b->dim; d++) {
            double c = floor(x[3 * i + d] / h);
            uint64_t ci = c < 0 ? 0 : c > 0x1fffff ? 0x1fffff : (uint64_t)c;
            key |= spread3(ci) << d;
        }
        k[i] = (keyed){key, i};
    }
    qsort(k, n, sizeof *k, by_key);
    for (size_t i = 0; i < n; i++)
        perm[i] = k[i].i;
    free(k);
    return 0;
}

/* a[k] = a[ord[k]] for n elements of size bytes (tmp holds n of them). */
static void permute(void *a, size_t size, size_t n, const size_t *ord, void *tmp)
{
    char *src = a, *dst = tmp;
    for (size_t k = 0; k < n; k++)
        memcpy(dst + k * size, src + ord[k] * size, size);
    memcpy(a, tmp, n * size);
}

int edmd_reorder(edmd_state *s, size_t *perm, double h)
{
    const size_t n = s->n;
    size_t *ord = malloc(n * sizeof *ord);
    double *x = calloc(3 * n, sizeof *x);
    void *tmp = malloc(n * sizeof(edmd_kin)); /* the largest element */
    int rc = -1;
    if (!ord || !x || !tmp)
        goto out;
    for (size_t i = 0; i < n; i++)
        edmd_pos(s, i, &x[3 * i]);
    if (edmd_spatial_order(&s->box, x, n, h, ord) != 0)
        goto out;
    permute(s->k, sizeof *s->k, n, ord, tmp);
    permute(s->m, sizeof *s->m, n, ord, tmp);
    permute(s->skin, sizeof *s->skin, n, ord, tmp);
    permute(s->rref, sizeof *s->rref, n, ord, tmp);
    permute(s->ncoll, sizeof *s->ncoll, n, ord, tmp);
    permute(perm, sizeof *perm, n, ord, tmp);
    rc = 0;
out:
    free(ord);
    free(x);
    free(tmp);
    return rc;
}
