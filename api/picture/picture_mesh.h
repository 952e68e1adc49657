/* picture_mesh.h — a tetfill result's tet mesh for the packing picture: read
 * from the file and cut by the section plane z = z0 (its edges drawn over the
 * grains of the section). */
#ifndef PK_PICTURE_MESH_H
#define PK_PICTURE_MESH_H

#include <stddef.h>
#include <stdint.h>

typedef struct pk_picture_mesh {
    size_t nn, nt;
    double *x;  /* [nn][3] nodes, the particles' frame */
    int64_t *t; /* [nt][4] node indices */
} pk_picture_mesh;

/* /observables/tetfill/mesh_nodes [n][3] and mesh_tets [m][4] (flat [3n],
 * [4m] in files before the H5MD 1.1 layout).  0 with the mesh; -1 when the
 * file has none or a bad one (m zeroed). */
int pk_picture_mesh_read(const char *h5_path, pk_picture_mesh *m);
void pk_picture_mesh_free(pk_picture_mesh *m);

/* The polygon in which tet k meets the plane z = z0: its 3 or 4 corners
 * (x, y) in order around it, or 0 when the tet does not cross the plane. */
int pk_picture_mesh_cut(const pk_picture_mesh *m, size_t k, double z0, double xy[4][2]);

#endif
