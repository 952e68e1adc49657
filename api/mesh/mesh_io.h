/* mesh_io.h — tet meshes from a job: inline JSON or files (Gmsh MSH 2.2 and
 * 4.1 ASCII, TetGen .node/.ele).  The result is checked (pk_mesh_check). */
#ifndef PK_MESH_IO_H
#define PK_MESH_IO_H

#include <jansson.h>
#include <stddef.h>

#include "core/mesh/mesh.h"

/* "mesh": {"nodes": [[x,y,z],...], "tets": [[i,j,k,l],...], "regions": [...]}
 * or {"file": "path"} (.msh → Gmsh; .node/.ele/no extension → TetGen).
 * max_tets: size limit (0 = none).  0, or -1 with a message in err. */
int pk_mesh_from_json(json_t *mesh, size_t max_tets, pk_mesh *m, pk_mesh_report *rep, char *err,
                      size_t errlen);

/* Unchecked readers (for tests); 0 or -1 with err. */
int pk_mesh_read_msh(const char *path, size_t max_tets, pk_mesh *m, char *err, size_t errlen);
int pk_mesh_read_tetgen(const char *path, size_t max_tets, pk_mesh *m, char *err, size_t errlen);

#endif
