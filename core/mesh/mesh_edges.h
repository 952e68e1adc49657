/* mesh_edges.h — the unique edges of a tet mesh (Jerier step 2 puts a sphere
 * on each; the mean edge length sets the size rule ℓ ≈ 8 r̄). */
#ifndef PK_MESH_EDGES_H
#define PK_MESH_EDGES_H

#include <stddef.h>
#include <stdint.h>

#include "mesh.h"

typedef struct pk_mesh_edge_list {
    size_t n;
    int32_t *v; /* [n][2], v[2i] < v[2i+1], sorted */
} pk_mesh_edge_list;

int pk_mesh_edges(const pk_mesh *m, pk_mesh_edge_list *el);
void pk_mesh_edges_free(pk_mesh_edge_list *el);
double pk_mesh_edge_length(const pk_mesh *m, const pk_mesh_edge_list *el, size_t i);

#endif
