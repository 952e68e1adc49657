/* fe2_mesh.h — the macroscopic 2D plane-strain mesh of an FE² problem
 * (Meier 2009 ch. 6): linear triangles (1 Gauss point) and bilinear
 * quadrilaterals Q1 (2×2 Gauss points), mixed in one mesh.
 *
 * Nodes are numbered 0 .. nnode−1, element nodes counter-clockwise; a
 * triangle has conn[e][3] = −1.  Degrees of freedom: 2·node + component
 * (0 = x, 1 = y).  Gauss points are numbered element by element:
 * those of element e are gp_first[e] .. gp_first[e+1]−1. */
#ifndef PK_FE2_MESH_H
#define PK_FE2_MESH_H

#include <stddef.h>
#include <stdint.h>

typedef struct pk_fe2_mesh {
    size_t nnode, nelem;
    double *xy;       /* [nnode][2] reference coordinates */
    int32_t *conn;    /* [nelem][4]; conn[e][3] = −1 for a triangle */
    size_t *gp_first; /* [nelem + 1], filled by pk_fe2_mesh_finish */
    /* The arrays are owned by the mesh (malloc'ed; pk_fe2_mesh_free frees
     * them); gp_first is NULL until pk_fe2_mesh_finish. */
} pk_fe2_mesh;

/* Nodes of element e (3 or 4). */
int pk_fe2_elem_nodes(const pk_fe2_mesh *m, size_t e);

/* Gauss points of the mesh (gp_first[nelem]). */
size_t pk_fe2_gauss_count(const pk_fe2_mesh *m);

/* Check the connectivity (node indices in range, positive element areas at
 * every Gauss point: counter-clockwise, not degenerate) and fill gp_first.
 * 0, or −1 with the first offending element named in err. */
int pk_fe2_mesh_finish(pk_fe2_mesh *m, char *err, size_t errlen);

/* A rectangle [0, lx] × [0, ly] in nx × ny Q1 elements (nodes row by row
 * from the lower-left corner: node = j·(nx+1) + i).  0 / −1 (memory, or
 * an empty rectangle). */
int pk_fe2_mesh_rectangle(double lx, double ly, size_t nx, size_t ny, pk_fe2_mesh *m);

void pk_fe2_mesh_free(pk_fe2_mesh *m);

/* Gauss points of element e (1 for a triangle, 4 for a Q1). */
int pk_fe2_elem_gauss(const pk_fe2_mesh *m, size_t e);

/* Shape functions of element e at its local Gauss point q: N[a], their
 * reference gradients dNdX[2·a + J] = ∂N_a/∂X_J (a < pk_fe2_elem_nodes) and
 * the Gauss weight × det J (the reference area the point carries).
 * Q1: ξ, η = ±1/√3, weights 1, points in the order of the nodes
 * (−−, +−, ++, −+); triangle: the centroid, weight ½.  0, or −1 when
 * det J <= 0 (clockwise or degenerate). */
int pk_fe2_shape(const pk_fe2_mesh *m, size_t e, int q, double N[4], double dNdX[8], double *wdet);

/* Reference position of Gauss point g (its element and weight·|J| too, any
 * of them NULL). */
void pk_fe2_gauss_point(const pk_fe2_mesh *m, size_t g, double X[2], size_t *elem, double *wdet);

#endif
