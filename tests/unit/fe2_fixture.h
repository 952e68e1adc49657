/* fe2_fixture.h — small macro meshes, problems and DEM RVEs shared by the
 * FE² unit tests (static helpers; include once per test binary, after
 * check.h and homog_fixture.h). */
#ifndef PK_FE2_FIXTURE_H
#define PK_FE2_FIXTURE_H

#include <stdlib.h>
#include <string.h>

#include "api/solver/sparse_cholmod.h"
#include "core/fe2/fe2_rve.h"
#include "core/fe2/fe2_solver.h"
#include "core/fe2/fe2_material_linear.h"

/* Mesh from arrays (copied); finished and checked. */
static inline void mesh_from(pk_fe2_mesh *m, size_t nnode, const double *xy, size_t nelem,
                             const int32_t *conn)
{
    memset(m, 0, sizeof *m);
    m->nnode = nnode, m->nelem = nelem;
    m->xy = malloc(2 * nnode * sizeof *m->xy);
    m->conn = malloc(4 * nelem * sizeof *m->conn);
    memcpy(m->xy, xy, 2 * nnode * sizeof *xy);
    memcpy(m->conn, conn, 4 * nelem * sizeof *conn);
    char err[128];
    int rc = pk_fe2_mesh_finish(m, err, sizeof err);
    CHECK_MSG(rc == 0, "%s", err);
}

/* 2×2 Q1 on [0,2]² with the centre node moved off (1,1) and the bottom
 * mid-edge node moved along its edge: no element is a parallelogram. */
static inline void mesh_q1_distorted(pk_fe2_mesh *m)
{
    const double xy[] = {0, 0, 0.8, 0, 2, 0, 0, 1, 1.15, 0.9, 2, 1.2, 0, 2, 1, 2, 2, 2};
    const int32_t conn[] = {0, 1, 4, 3, 1, 2, 5, 4, 3, 4, 7, 6, 4, 5, 8, 7};
    mesh_from(m, 9, xy, 4, conn);
}

/* [0,2] × [0,1] with two interior nodes (6, 7): a distorted Q1 on the left
 * and six triangles (mixed = 1), or the Q1 split in two triangles too. */
static inline void mesh_triangles(pk_fe2_mesh *m, int mixed)
{
    const double xy[] = {0, 0, 1, 0, 2, 0, 2, 1, 1, 1, 0, 1, 0.6, 0.45, 1.4, 0.6};
    const int32_t tri[] = {1, 7, 6, -1, 1, 2, 7, -1, 2, 3, 7, -1, 3, 4, 7, -1,
                           4, 6, 7, -1, 4, 5, 6, -1, 0, 1, 6, -1, 0, 6, 5, -1};
    const int32_t mix[] = {0, 1,  6, 5, 1, 7,  6, -1, 1, 2,  7, -1, 2, 3,
                           7, -1, 3, 4, 7, -1, 4, 6,  7, -1, 4, 5,  6, -1};
    if (mixed)
        mesh_from(m, 8, xy, 7, mix);
    else
        mesh_from(m, 8, xy, 8, tri);
}

/* Nodes on the boundary of the bounding box [x0,x1] × [y0,y1]. */
static inline int on_box(const pk_fe2_mesh *m, size_t a)
{
    double lo[2] = {1e300, 1e300}, hi[2] = {-1e300, -1e300};
    for (size_t b = 0; b < m->nnode; b++)
        for (int k = 0; k < 2; k++)
            lo[k] = fmin(lo[k], m->xy[2 * b + k]), hi[k] = fmax(hi[k], m->xy[2 * b + k]);
    for (int k = 0; k < 2; k++)
        if (m->xy[2 * a + k] == lo[k] || m->xy[2 * a + k] == hi[k])
            return 1;
    return 0;
}

/* Both dofs of every boundary node prescribed: fix [2·nnode], returns the count. */
static inline size_t fix_boundary(const pk_fe2_mesh *m, int32_t *fix)
{
    size_t n = 0;
    for (size_t a = 0; a < m->nnode; a++)
        if (on_box(m, a))
            fix[n++] = (int32_t)(2 * a), fix[n++] = (int32_t)(2 * a + 1);
    return n;
}

static inline pk_fe2_newton_opts newton_opts(void)
{
    pk_fe2_newton_opts o = {
        .rtol = 1e-10, .atol = 1e-14, .max_iter = 20, .line_search = 1, .max_cuts = 6};
    return o;
}

/* A jammed random 2D RVE (n grains, radii in [0.8, 1.2], φ 0.88: overlapping,
 * prestressed) under boundary condition bc; options for the Gauss points. */
static inline void make_rve(size_t n, uint64_t seed, pk_homog_bc bc, pk_homog_rve *rve,
                            pk_homog_opts *o)
{
    pk_box b;
    pk_particles p;
    make_jammed(2, n, 0.88, seed, &b, &p);
    char err[128];
    CHECK(pk_homog_rve_build(&b, &p, bc, 1.0, rve, err, sizeof err) == 0);
    pk_particles_free(&p);
    *o = opts(1.0);
}

#endif
