/* mesh_box.c — a box domain as a tet mesh (so a box can be filled by tetfill).
 * Contract: pk_mesh_box / pk_mesh_box_count in core/mesh/mesh.h. */
#include <math.h>
#include <stdio.h>

#include "mesh.h"

/* Cells per axis and the tet count; -1 with err beyond the limits. */
static int box_cells(const double L[3], double h, size_t max_tets, int64_t n[3], double *tets,
                     char *err, size_t errlen)
{
    double nt = 6;
    for (int k = 0; k < 3; k++) {
        if (!(L[k] > 0) || !(h > 0)) {
            snprintf(err, errlen, "box mesh: edges and cell size must be positive");
            return -1;
        }
        double c = fmax(1, round(L[k] / h));
        if (c > 1e6) {
            snprintf(err, errlen, "box mesh: %.0f cells along axis %d is too many", c, k);
            return -1;
        }
        n[k] = (int64_t)c;
        nt *= c;
    }
    if ((max_tets && nt > (double)max_tets) || nt > 4e8) {
        snprintf(err, errlen, "box mesh: %.0f tets, over the limit of %zu", nt, max_tets);
        return -1;
    }
    *tets = nt;
    return 0;
}

int pk_mesh_box_count(const double L[3], double h, size_t max_tets, char *err, size_t errlen)
{
    int64_t n[3];
    double nt;
    return box_cells(L, h, max_tets, n, &nt, err, errlen);
}

int pk_mesh_box(pk_mesh *m, const double L[3], double h, size_t max_tets, char *err, size_t errlen)
{
    int64_t n[3];
    double nt;
    if (box_cells(L, h, max_tets, n, &nt, err, errlen) != 0)
        return -1;
    size_t nn = (size_t)((n[0] + 1) * (n[1] + 1) * (n[2] + 1));
    if (pk_mesh_alloc(m, nn, (size_t)nt) != 0) {
        snprintf(err, errlen, "box mesh: out of memory");
        return -1;
    }
#define NODE(i, j, k) ((int32_t)(((k) * (n[1] + 1) + (j)) * (n[0] + 1) + (i)))
    for (int64_t k = 0; k <= n[2]; k++)
        for (int64_t j = 0; j <= n[1]; j++)
            for (int64_t i = 0; i <= n[0]; i++) {
                double *x = &m->x[3 * (size_t)NODE(i, j, k)];
                x[0] = L[0] * (double)i / (double)n[0];
                x[1] = L[1] * (double)j / (double)n[1];
                x[2] = L[2] * (double)k / (double)n[2];
            }
    /* Kuhn split: one tet per axis permutation, along the path
     * (0,0,0) → e_a → e_a + e_b → (1,1,1). */
    static const int perm[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2},
                                   {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
    size_t e = 0;
    for (int64_t k = 0; k < n[2]; k++)
        for (int64_t j = 0; j < n[1]; j++)
            for (int64_t i = 0; i < n[0]; i++)
                for (int p = 0; p < 6; p++) {
                    int64_t c[3] = {i, j, k};
                    int32_t *t = &m->t[4 * e++];
                    t[0] = NODE(c[0], c[1], c[2]);
                    for (int s = 0; s < 3; s++) {
                        c[perm[p][s]]++;
                        t[s + 1] = NODE(c[0], c[1], c[2]);
                    }
                }
#undef NODE
    return pk_mesh_check(m, max_tets, NULL, err, errlen);
}
