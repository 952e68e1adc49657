/* mesh_locate.h — point-in-mesh and distance to the mesh boundary.
 *
 * Tets and boundary faces are registered in two core/space/grid.h grids by their
 * bounding spheres (centroid, farthest vertex), so a query visits O(1)
 * elements and a filler's cost stays linear in the number of tets.  The
 * mesh must be checked and translated so its bounding box starts at 0 (the
 * grids live in the box [0, hi]). */
#ifndef PK_MESH_LOCATE_H
#define PK_MESH_LOCATE_H

#include "core/space/grid.h"
#include "mesh.h"
#include "core/space/particles.h"

typedef struct pk_mesh_locator {
    const pk_mesh *m;
    pk_box box;          /* [0, hi] padded, walls */
    pk_particles tb, fb; /* bounding spheres of tets and boundary faces */
    pk_grid tg, fg;
    double *fn; /* [nbface][3] outward unit normals */
} pk_mesh_locator;

int pk_mesh_locator_init(pk_mesh_locator *L, const pk_mesh *m);
void pk_mesh_locator_free(pk_mesh_locator *L);

/* Index of a tet containing x (barycentric coordinates >= -1e-12), or -1. */
long pk_mesh_locate(const pk_mesh_locator *L, const double x[3]);

/* Distance from x to the nearest boundary face, looking only at faces closer
 * than `reach` (returns INFINITY if none).  If q/n are non-NULL they get the
 * closest point and that face's outward normal. */
double pk_mesh_boundary_distance(const pk_mesh_locator *L, const double x[3], double reach,
                                 double q[3], double n[3]);

/* Up to `max` distinct boundary planes closer than reach to x, nearest first:
 * closest point q[i], outward normal n[i], distance d[i].  Faces whose planes
 * coincide (normals within 1e-9 and same offset) are reported once. */
int pk_mesh_boundary_planes(const pk_mesh_locator *L, const double x[3], double reach, int max,
                            double (*q)[3], double (*n)[3], double *d);

/* Closest point on triangle (a, b, c) to p (Ericson, Real-Time Collision
 * Detection §5.1.5). */
void pk_closest_on_triangle(const double p[3], const double a[3], const double b[3],
                            const double c[3], double q[3]);

#endif
