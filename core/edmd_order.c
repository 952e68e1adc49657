/* edmd_order.c — memory order of the grains: sorted along a Morton (Z-order)
 * curve of cells about one mean diameter wide, so that neighbours in space
 * are neighbours in the engine's arrays (fewer cache misses per event). */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>

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
