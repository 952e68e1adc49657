/* mesh.h — a linear tetrahedral mesh (the domain of Jerier's filler) and its checks.
 *
 * Nodes x[3*i], tets t[4*e] (0-based node indices), an optional region id
 * per tet (Gmsh entity / physical tag, TetGen attribute; 0 if none).
 * pk_mesh_check() validates and prepares the mesh: inverted tets are
 * reoriented, zero-volume tets, non-conforming faces and non-manifold
 * boundaries are refused naming the element, slivers are counted and the
 * first is named.  It then builds the boundary faces (a face that belongs
 * to one tet only, Jerier Fig. 2a) with outward node order (Fig. 2b). */
#ifndef PK_MESH_H
#define PK_MESH_H

#include <stddef.h>
#include <stdint.h>

typedef struct pk_mesh {
    size_t nnode, ntet;
    double *x;       /* [nnode][3] */
    int32_t *t;      /* [ntet][4], positive orientation after the check */
    int32_t *region; /* [ntet] region id */
    /* filled by pk_mesh_check */
    size_t nbface;
    int32_t *bface;      /* [nbface][3] boundary faces, right-hand normal points outward */
    int32_t *bface_tet;  /* [nbface] the tet each boundary face belongs to */
    double volume;       /* total volume */
    double edge_mean;    /* mean length over unique edges */
    double lo[3], hi[3]; /* bounding box */
} pk_mesh;

typedef struct pk_mesh_report {
    size_t reoriented;   /* inverted tets whose orientation was flipped */
    size_t slivers;      /* tets with quality below the sliver threshold */
    size_t first_sliver; /* index of the first sliver (SIZE_MAX if none) */
    double min_quality;  /* smallest tet quality (1 = regular tet) */
} pk_mesh_report;

/* Quality below which a tet is called a sliver: q = 6√2·V / ℓ_rms³ (1 for a
 * regular tet, → 0 for flat ones). */
#define PK_MESH_SLIVER_QUALITY 0.05
/* |V| below this times ℓ_max³ is a zero-volume tet (refused). */
#define PK_MESH_ZERO_VOLUME 1e-12

/* Allocate a mesh with nnode nodes and ntet tets (contents uninitialised,
 * region zeroed).  0 or -1. */
int pk_mesh_alloc(pk_mesh *m, size_t nnode, size_t ntet);
void pk_mesh_free(pk_mesh *m);

/* Validate and prepare (see above).  max_tets: size limit (0 = none).
 * 0 on success; -1 with a message naming the element in err. */
int pk_mesh_check(pk_mesh *m, size_t max_tets, pk_mesh_report *rep, char *err, size_t errlen);

/* The unique triangular faces (interior and boundary), [nface][3] sorted
 * node indices, malloc'ed into *faces.  0 or -1. */
int pk_mesh_faces(const pk_mesh *m, int32_t **faces, size_t *nface);

/* Shift all nodes by -off (e.g. off = lo, so the bounding box starts at 0). */
void pk_mesh_translate(pk_mesh *m, const double off[3]);

/* Signed volume of tet e (positive after the check). */
double pk_mesh_tet_volume(const pk_mesh *m, size_t e);

/* Mesh the box [0,L0]×[0,L1]×[0,L2] with cubes of edge ≈ h (per axis
 * n_k = max(1, round(L_k / h))), each split into six tets around its main
 * diagonal (Kuhn/Freudenthal split: conforming between cubes).  The mesh
 * is checked.  0 or -1. */
int pk_mesh_box(pk_mesh *m, const double L[3], double h, size_t max_tets, char *err, size_t errlen);
/* pk_mesh_box's limits without building the mesh (cheap): 0, or -1 with err. */
int pk_mesh_box_count(const double L[3], double h, size_t max_tets, char *err, size_t errlen);

#endif
