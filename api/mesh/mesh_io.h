/* mesh_io.h — tet meshes from a job: inline JSON or files (Gmsh MSH 2.2 and
 * 4.1 ASCII, TetGen .node/.ele).  The result is checked (pk_mesh_check). */
#ifndef PK_MESH_IO_H
#define PK_MESH_IO_H

#include <jansson.h>
#include <stddef.h>
#include <stdint.h>

#include "core/mesh/mesh.h"

/* "mesh": {"nodes": [[x,y,z],...], "tets": [[i,j,k,l],...], "regions": [...]}
 * or {"file": "path"} (.msh → Gmsh; .node/.ele/no extension → TetGen).
 * max_tets: size limit (0 = none).  0, or -1 with a message in err. */
int pk_mesh_from_json(json_t *mesh, size_t max_tets, pk_mesh *m, pk_mesh_report *rep, char *err,
                      size_t errlen);

/* Unchecked readers (for tests); 0 or -1 with err. */
int pk_mesh_read_msh(const char *path, size_t max_tets, pk_mesh *m, char *err, size_t errlen);
int pk_mesh_read_tetgen(const char *path, size_t max_tets, pk_mesh *m, char *err, size_t errlen);

/* ---- 2D meshes (the FE² macro mesh): 3-node triangles and 4-node
 * quadrilaterals, with named sets of nodes, edges and elements. */
typedef struct pk_mesh2d_set {
    char name[64];
    size_t nnode, nedge, nelem;
    int32_t *node; /* [nnode] ascending, distinct */
    int32_t *edge; /* [nedge][2] */
    int32_t *elem; /* [nelem] */
} pk_mesh2d_set;

typedef struct pk_mesh2d {
    size_t nnode, nelem, nset;
    double *xy;    /* [nnode][2] */
    int32_t *conn; /* [nelem][4]; conn[e][3] = -1 for a triangle */
    pk_mesh2d_set *set;
} pk_mesh2d;

/* Gmsh MSH 2.2 / 4.1 ASCII: triangles (type 2) and quadrilaterals (type 3)
 * are the elements (z ignored); physical groups are sets named by
 * $PhysicalNames, else "<dim>:<tag>": points (type 15) and lines (type 1)
 * give nodes (and edges), surfaces nodes and elements.  Other element
 * types are refused.  max_elems: size limit (0 = none).  Node order is the
 * file's; element orientation is not changed (the caller checks it).
 * 0, or -1 with a message in err. */
int pk_mesh2d_read_msh(const char *path, size_t max_elems, pk_mesh2d *m, char *err, size_t errlen);

/* The set named name, or NULL. */
const pk_mesh2d_set *pk_mesh2d_find(const pk_mesh2d *m, const char *name);

/* A new set (zeroed, named) at the end of m->set; NULL on memory. */
pk_mesh2d_set *pk_mesh2d_add_set(pk_mesh2d *m, const char *name);

/* Sort and deduplicate s->node. */
void pk_mesh2d_set_finish(pk_mesh2d_set *s);

void pk_mesh2d_free(pk_mesh2d *m);

#endif
