/* mesh_edges.c — the unique edges of a tet mesh and their lengths.
 * Contract: core/mesh/mesh_edges.h. */
#include "mesh_edges.h"

#include <math.h>
#include <stdlib.h>

static int cmp_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y;
}

int pk_mesh_edges(const pk_mesh *m, pk_mesh_edge_list *el)
{
    el->n = 0;
    el->v = NULL;
    size_t nk = 6 * m->ntet;
    uint64_t *key = malloc((nk ? nk : 1) * sizeof *key);
    if (!key)
        return -1;
    size_t c = 0;
    for (size_t e = 0; e < m->ntet; e++)
        for (int i = 0; i < 4; i++)
            for (int j = i + 1; j < 4; j++) {
                uint32_t a = (uint32_t)m->t[4 * e + (size_t)i],
                         b = (uint32_t)m->t[4 * e + (size_t)j];
                key[c++] = a < b ? ((uint64_t)a << 32 | b) : ((uint64_t)b << 32 | a);
            }
    qsort(key, nk, sizeof *key, cmp_u64);
    size_t u = 0;
    for (size_t i = 0; i < nk; i++)
        if (u == 0 || key[i] != key[u - 1])
            key[u++] = key[i];
    el->v = malloc((u ? u : 1) * 2 * sizeof *el->v);
    if (!el->v) {
        free(key);
        return -1;
    }
    for (size_t i = 0; i < u; i++) {
        el->v[2 * i] = (int32_t)(key[i] >> 32);
        el->v[2 * i + 1] = (int32_t)(key[i] & 0xffffffffu);
    }
    el->n = u;
    free(key);
    return 0;
}

void pk_mesh_edges_free(pk_mesh_edge_list *el)
{
    free(el->v);
    el->v = NULL;
    el->n = 0;
}

double pk_mesh_edge_length(const pk_mesh *m, const pk_mesh_edge_list *el, size_t i)
{
    const double *a = &m->x[3 * (size_t)el->v[2 * i]], *b = &m->x[3 * (size_t)el->v[2 * i + 1]];
    return sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                (a[2] - b[2]) * (a[2] - b[2]));
}
