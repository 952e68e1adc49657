/* fe2_mesh.c — the macroscopic 2D mesh of FE²: Q1 and linear triangles,
 * their Gauss points, the checks and a rectangle generator.  Contract:
 * fe2_mesh.h. */
#include "fe2_mesh.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int pk_fe2_elem_nodes(const pk_fe2_mesh *m, size_t e) { return m->conn[4 * e + 3] < 0 ? 3 : 4; }

int pk_fe2_elem_gauss(const pk_fe2_mesh *m, size_t e)
{
    return pk_fe2_elem_nodes(m, e) == 3 ? 1 : 4;
}

size_t pk_fe2_gauss_count(const pk_fe2_mesh *m) { return m->gp_first ? m->gp_first[m->nelem] : 0; }

/* Reference-element shape functions and their ξ-derivatives dNr[2a + k]. */
static void shape_ref(int nen, int q, double N[4], double dNr[8])
{
    if (nen == 3) {
        const double xi = 1.0 / 3, eta = 1.0 / 3;
        N[0] = 1 - xi - eta, N[1] = xi, N[2] = eta, N[3] = 0;
        const double d[8] = {-1, -1, 1, 0, 0, 1, 0, 0};
        memcpy(dNr, d, sizeof d);
        return;
    }
    static const double sx[4] = {-1, 1, 1, -1}, sy[4] = {-1, -1, 1, 1};
    const double g = 1 / sqrt(3.0), xi = sx[q] * g, eta = sy[q] * g;
    for (int a = 0; a < 4; a++) {
        N[a] = 0.25 * (1 + sx[a] * xi) * (1 + sy[a] * eta);
        dNr[2 * a] = 0.25 * sx[a] * (1 + sy[a] * eta);
        dNr[2 * a + 1] = 0.25 * sy[a] * (1 + sx[a] * xi);
    }
}

int pk_fe2_shape(const pk_fe2_mesh *m, size_t e, int q, double N[4], double dNdX[8], double *wdet)
{
    const int nen = pk_fe2_elem_nodes(m, e);
    double dNr[8];
    shape_ref(nen, q, N, dNr);
    /* J[k][l] = ∂X_k/∂ξ_l */
    double J[2][2] = {{0, 0}, {0, 0}};
    for (int a = 0; a < nen; a++) {
        const double *X = &m->xy[2 * (size_t)m->conn[4 * e + a]];
        for (int k = 0; k < 2; k++)
            for (int l = 0; l < 2; l++)
                J[k][l] += X[k] * dNr[2 * a + l];
    }
    const double det = J[0][0] * J[1][1] - J[0][1] * J[1][0];
    memset(dNdX, 0, 8 * sizeof *dNdX);
    if (!(det > 0)) {
        if (wdet)
            *wdet = 0;
        return -1;
    }
    /* ∂N/∂X = ∂N/∂ξ · J⁻¹ */
    const double Ji[2][2] = {{J[1][1] / det, -J[0][1] / det}, {-J[1][0] / det, J[0][0] / det}};
    for (int a = 0; a < nen; a++)
        for (int k = 0; k < 2; k++)
            dNdX[2 * a + k] = dNr[2 * a] * Ji[0][k] + dNr[2 * a + 1] * Ji[1][k];
    if (wdet)
        *wdet = (nen == 3 ? 0.5 : 1.0) * det;
    return 0;
}

int pk_fe2_mesh_finish(pk_fe2_mesh *m, char *err, size_t errlen)
{
    size_t *gf = realloc(m->gp_first, (m->nelem + 1) * sizeof *gf);
    if (!gf) {
        snprintf(err, errlen, "out of memory");
        return -1;
    }
    m->gp_first = gf;
    gf[0] = 0;
    for (size_t e = 0; e < m->nelem; e++) {
        const int32_t *c = &m->conn[4 * e];
        const int nen = pk_fe2_elem_nodes(m, e);
        for (int a = 0; a < nen; a++) {
            if (c[a] < 0 || (size_t)c[a] >= m->nnode) {
                snprintf(err, errlen, "element %zu: node %ld out of range [0, %zu)", e, (long)c[a],
                         m->nnode);
                return -1;
            }
            for (int b = 0; b < a; b++)
                if (c[a] == c[b]) {
                    snprintf(err, errlen, "element %zu: node %ld repeated", e, (long)c[a]);
                    return -1;
                }
        }
        gf[e + 1] = gf[e] + (size_t)pk_fe2_elem_gauss(m, e);
        for (int q = 0; q < pk_fe2_elem_gauss(m, e); q++) {
            double N[4], dN[8], w;
            if (pk_fe2_shape(m, e, q, N, dN, &w) != 0) {
                snprintf(err, errlen,
                         "element %zu: non-positive area at Gauss point %d (nodes not "
                         "counter-clockwise, or degenerate)",
                         e, q);
                return -1;
            }
        }
    }
    return 0;
}

int pk_fe2_mesh_rectangle(double lx, double ly, size_t nx, size_t ny, pk_fe2_mesh *m)
{
    memset(m, 0, sizeof *m);
    if (nx == 0 || ny == 0 || !(lx > 0) || !(ly > 0))
        return -1;
    m->nnode = (nx + 1) * (ny + 1);
    m->nelem = nx * ny;
    m->xy = malloc(2 * m->nnode * sizeof *m->xy);
    m->conn = malloc(4 * (m->nelem ? m->nelem : 1) * sizeof *m->conn);
    if (!m->xy || !m->conn) {
        pk_fe2_mesh_free(m);
        return -1;
    }
    for (size_t j = 0; j <= ny; j++)
        for (size_t i = 0; i <= nx; i++) {
            m->xy[2 * (j * (nx + 1) + i)] = lx * (double)i / (double)nx;
            m->xy[2 * (j * (nx + 1) + i) + 1] = ly * (double)j / (double)ny;
        }
    for (size_t j = 0; j < ny; j++)
        for (size_t i = 0; i < nx; i++) {
            int32_t *c = &m->conn[4 * (j * nx + i)];
            const int32_t n0 = (int32_t)(j * (nx + 1) + i);
            c[0] = n0, c[1] = n0 + 1, c[2] = n0 + 1 + (int32_t)(nx + 1),
            c[3] = n0 + (int32_t)(nx + 1);
        }
    char err[128];
    if (pk_fe2_mesh_finish(m, err, sizeof err) != 0) {
        pk_fe2_mesh_free(m);
        return -1;
    }
    return 0;
}

void pk_fe2_mesh_free(pk_fe2_mesh *m)
{
    free(m->xy);
    free(m->conn);
    free(m->gp_first);
    memset(m, 0, sizeof *m);
}

void pk_fe2_gauss_point(const pk_fe2_mesh *m, size_t g, double X[2], size_t *elem, double *wdet)
{
    /* the element whose range holds g: gp_first is increasing */
    size_t lo = 0, hi = m->nelem;
    while (hi - lo > 1) {
        size_t mid = lo + (hi - lo) / 2;
        if (m->gp_first[mid] <= g)
            lo = mid;
        else
            hi = mid;
    }
    const int q = (int)(g - m->gp_first[lo]);
    double N[4], dN[8], w;
    pk_fe2_shape(m, lo, q, N, dN, &w);
    if (X) {
        X[0] = X[1] = 0;
        for (int a = 0; a < pk_fe2_elem_nodes(m, lo); a++) {
            X[0] += N[a] * m->xy[2 * (size_t)m->conn[4 * lo + a]];
            X[1] += N[a] * m->xy[2 * (size_t)m->conn[4 * lo + a] + 1];
        }
    }
    if (elem)
        *elem = lo;
    if (wdet)
        *wdet = w;
}
