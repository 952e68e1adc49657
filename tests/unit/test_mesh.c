/* test_mesh.c — tet mesh checks, box mesher, point location / boundary
 * distance (against brute force) and the mesh readers (Gmsh MSH 2.2 and 4.1
 * ASCII, TetGen, inline JSON) on small stored meshes in tests/data/meshes/
 * (a 6 mm cube of 1127 tets and a Ø8 × 10 cylinder of 443 tets, both made
 * by Gmsh 4 from the .geo lines in tests/data/meshes/README). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "core/mesh/mesh.h"
#include "api/mesh/mesh_io.h"
#include "core/mesh/mesh_locate.h"
#include "core/base/rng.h"

static const char *data(const char *name)
{
    static char buf[4096];
    const char *src = getenv("PACKD_SRC");
    snprintf(buf, sizeof buf, "%s/tests/data/meshes/%s", src ? src : ".", name);
    return buf;
}

static int make(pk_mesh *m, const double *x, size_t nn, const int32_t *t, size_t nt)
{
    if (pk_mesh_alloc(m, nn, nt) != 0)
        return -1;
    memcpy(m->x, x, 3 * nn * sizeof *x);
    memcpy(m->t, t, 4 * nt * sizeof *t);
    return 0;
}

/* ∮ x·n dA = 3 V (divergence theorem): the boundary is closed and outward. */
static double flux(const pk_mesh *m)
{
    double s = 0;
    for (size_t f = 0; f < m->nbface; f++) {
        const double *a = &m->x[3 * (size_t)m->bface[3 * f]],
                     *b = &m->x[3 * (size_t)m->bface[3 * f + 1]],
                     *c = &m->x[3 * (size_t)m->bface[3 * f + 2]];
        double u[3], v[3], n[3], g[3];
        for (int k = 0; k < 3; k++) {
            u[k] = b[k] - a[k];
            v[k] = c[k] - a[k];
            g[k] = (a[k] + b[k] + c[k]) / 3;
        }
        n[0] = u[1] * v[2] - u[2] * v[1];
        n[1] = u[2] * v[0] - u[0] * v[2];
        n[2] = u[0] * v[1] - u[1] * v[0];
        s += 0.5 * (g[0] * n[0] + g[1] * n[1] + g[2] * n[2]);
    }
    return s;
}

static void test_box_mesh(void)
{
    pk_mesh m;
    char err[256];
    double L[3] = {2, 3, 4};
    CHECK(pk_mesh_box(&m, L, 1, 0, err, sizeof err) == 0);
    CHECK(m.ntet == 6 * 2 * 3 * 4);
    CHECK_NEAR(m.volume, 24, 1e-12);                    /* exact up to round-off */
    CHECK(m.nbface == 2 * 2 * (2 * 3 + 3 * 4 + 2 * 4)); /* two triangles per boundary square */
    CHECK_NEAR(flux(&m), 3 * 24, 1e-9);
    for (size_t e = 0; e < m.ntet; e++)
        CHECK(pk_mesh_tet_volume(&m, e) > 0);
    pk_mesh_free(&m);
    CHECK(pk_mesh_box(&m, L, 0.01, 1000, err, sizeof err) != 0 && strstr(err, "limit"));
    /* mean edge → (3 + 3√2 + √3)/7 h for many cubes (the placer's size rule);
     * 20³ cubes: the extra boundary edges shift it by ~1/20 of the axis share */
    double L20[3] = {20, 20, 20};
    CHECK(pk_mesh_box(&m, L20, 1, 0, err, sizeof err) == 0);
    CHECK_NEAR(m.edge_mean, (3 + 3 * sqrt(2.0) + sqrt(3.0)) / 7, 0.02);
    pk_mesh_free(&m);
}

static void test_reoriented_and_sliver(void)
{
    /* tet 0 inverted, tet 1 a sliver (height 1e-3 over a unit triangle) */
    double x[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, -1e-3};
    int32_t t[] = {0, 2, 1, 3, 0, 2, 1, 4};
    pk_mesh m;
    pk_mesh_report rep;
    char err[256];
    CHECK(make(&m, x, 5, t, 2) == 0);
    CHECK_MSG(pk_mesh_check(&m, 0, &rep, err, sizeof err) == 0, "%s", err);
    CHECK(rep.reoriented == 1);
    CHECK(rep.slivers == 1 && rep.first_sliver == 1);
    CHECK_NEAR(m.volume, 1.0 / 6 + 1e-3 / 6, 1e-15);
    CHECK(m.nbface == 6);
    CHECK_NEAR(flux(&m), 3 * m.volume, 1e-12);
    pk_mesh_free(&m);
}

static void check_refused(const double *x, size_t nn, const int32_t *t, size_t nt, const char *want)
{
    pk_mesh m;
    char err[256] = "";
    CHECK(make(&m, x, nn, t, nt) == 0);
    int rc = pk_mesh_check(&m, 0, NULL, err, sizeof err);
    CHECK_MSG(rc != 0 && strstr(err, want), "rc %d, message \"%s\", wanted \"%s\"", rc, err, want);
    pk_mesh_free(&m);
}

static void test_refusals(void)
{
    double x[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, -1, 1, 1, -1, 0.5, 0, 0, 0.3, 0.3, 0.3};
    /* zero volume: node 3 in the plane of 0,1,2 */
    double flat[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0};
    int32_t t0[] = {0, 1, 2, 3};
    check_refused(flat, 4, t0, 1, "tet 0 has zero volume");
    int32_t dup[] = {0, 1, 1, 3};
    check_refused(x, 8, dup, 1, "tet 0 uses node 1 twice");
    int32_t range[] = {0, 1, 2, 9};
    check_refused(x, 8, range, 1, "tet 0 refers to node 9");
    /* three tets on one face: non-manifold */
    int32_t three[] = {0, 1, 2, 3, 0, 1, 2, 4, 0, 1, 2, 5};
    check_refused(x, 8, three, 3, "non-manifold mesh: face (0, 1, 2)");
    /* two tets on the same side of a face overlap */
    int32_t same[] = {0, 1, 2, 3, 0, 1, 2, 7};
    check_refused(x, 8, same, 2, "overlap");
    /* hanging node 6 on edge (0,1): the face (0,1,2) of tet 0 meets two
     * faces (0,6,2), (6,1,2) of the tets below — non-conforming */
    int32_t hang[] = {0, 1, 2, 3, 0, 6, 2, 4, 6, 1, 2, 4};
    check_refused(x, 8, hang, 3, "non-conforming");
    /* two tets touching along an edge only: a non-manifold boundary edge */
    double xe[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, -1, 0, 0, 0, -1};
    int32_t edge[] = {0, 1, 2, 3, 0, 1, 5, 4};
    check_refused(xe, 6, edge, 2, "non-manifold");
}

/* Brute force: point in some tet, distance to the nearest boundary face. */
static long brute_locate(const pk_mesh *m, const double *p)
{
    for (size_t e = 0; e < m->ntet; e++) {
        double c[4][3];
        for (int k = 0; k < 4; k++)
            memcpy(c[k], &m->x[3 * (size_t)m->t[4 * e + (size_t)k]], sizeof c[k]);
        double V = 0, s = 0;
        /* inside ⇔ the four sub-volumes add up to the volume */
        for (int k = 0; k < 4; k++) {
            double d[4][3];
            memcpy(d, c, sizeof d);
            memcpy(d[k], p, sizeof d[k]);
            double u[3], v[3], w[3];
            for (int j = 0; j < 3; j++) {
                u[j] = d[1][j] - d[0][j];
                v[j] = d[2][j] - d[0][j];
                w[j] = d[3][j] - d[0][j];
            }
            s += fabs(u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) +
                      u[2] * (v[0] * w[1] - v[1] * w[0])) /
                6;
        }
        V = pk_mesh_tet_volume(m, e);
        if (s <= V * (1 + 1e-9))
            return (long)e;
    }
    return -1;
}

static double brute_boundary(const pk_mesh *m, const double *p)
{
    double best = INFINITY;
    for (size_t f = 0; f < m->nbface; f++) {
        double q[3];
        pk_closest_on_triangle(p, &m->x[3 * (size_t)m->bface[3 * f]],
                               &m->x[3 * (size_t)m->bface[3 * f + 1]],
                               &m->x[3 * (size_t)m->bface[3 * f + 2]], q);
        best = fmin(best,
                    sqrt((p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) +
                         (p[2] - q[2]) * (p[2] - q[2])));
    }
    return best;
}

static void test_locate_cylinder(void)
{
    pk_mesh m;
    char err[512];
    CHECK_MSG(pk_mesh_read_msh(data("cylinder41.msh"), 0, &m, err, sizeof err) == 0, "%s", err);
    CHECK(pk_mesh_check(&m, 0, NULL, err, sizeof err) == 0);
    double lo[3];
    memcpy(lo, m.lo, sizeof lo);
    pk_mesh_translate(&m, lo);
    pk_mesh_locator L;
    CHECK(pk_mesh_locator_init(&L, &m) == 0);
    pk_rng rng;
    pk_rng_seed(&rng, 5, 0);
    int agree = 1;
    for (int i = 0; i < 2000 && agree; i++) {
        double p[3];
        for (int k = 0; k < 3; k++)
            p[k] = pk_rng_range(&rng, -0.5, m.hi[k] + 0.5);
        long a = pk_mesh_locate(&L, p), b = brute_locate(&m, p);
        /* both inside or both outside (a point on a shared face may land in
         * either tet) */
        agree = (a < 0) == (b < 0);
        CHECK_MSG(agree, "point %g %g %g: grid %ld brute %ld", p[0], p[1], p[2], a, b);
        double d = brute_boundary(&m, p), reach = 1.0;
        double g = pk_mesh_boundary_distance(&L, p, reach, NULL, NULL);
        /* within reach the same face distance (round-off only); beyond, none */
        if (d < reach)
            CHECK_NEAR(g, d, 1e-12);
        else
            CHECK(isinf(g));
    }
    pk_mesh_locator_free(&L);
    pk_mesh_free(&m);
}

static void same_mesh(const char *a, const char *b)
{
    pk_mesh m1, m2;
    char err[512];
    int r1 = strstr(a, ".msh") ? pk_mesh_read_msh(data(a), 0, &m1, err, sizeof err)
                               : pk_mesh_read_tetgen(data(a), 0, &m1, err, sizeof err);
    CHECK_MSG(r1 == 0, "%s", err);
    int r2 = strstr(b, ".msh") ? pk_mesh_read_msh(data(b), 0, &m2, err, sizeof err)
                               : pk_mesh_read_tetgen(data(b), 0, &m2, err, sizeof err);
    CHECK_MSG(r2 == 0, "%s", err);
    if (r1 || r2)
        return;
    CHECK(m1.nnode == m2.nnode && m1.ntet == m2.ntet);
    CHECK(memcmp(m1.x, m2.x, 3 * m1.nnode * sizeof *m1.x) == 0);
    CHECK(memcmp(m1.t, m2.t, 4 * m1.ntet * sizeof *m1.t) == 0);
    pk_mesh_free(&m1);
    pk_mesh_free(&m2);
}

static void test_readers(void)
{
    pk_mesh m;
    pk_mesh_report rep;
    char err[512];
    /* the cube: 340 nodes, 1127 tets, volume 6³ exactly (planar faces) */
    CHECK(pk_mesh_read_msh(data("cube22.msh"), 0, &m, err, sizeof err) == 0);
    CHECK(pk_mesh_check(&m, 0, &rep, err, sizeof err) == 0);
    CHECK(m.nnode == 340 && m.ntet == 1127);
    CHECK_NEAR(m.volume, 216, 1e-9);
    CHECK_NEAR(flux(&m), 3 * 216, 1e-8);
    CHECK(m.region[0] == 3); /* MSH 2.2: physical tag */
    pk_mesh_free(&m);
    /* the cylinder r = 4, h = 10: the faceted volume is a little under π r² h */
    CHECK(pk_mesh_read_msh(data("cylinder22.msh"), 0, &m, err, sizeof err) == 0);
    CHECK(pk_mesh_check(&m, 0, &rep, err, sizeof err) == 0);
    CHECK(m.volume < M_PI * 160 && m.volume > 0.95 * M_PI * 160);
    CHECK_NEAR(flux(&m), 3 * m.volume, 1e-8);
    pk_mesh_free(&m);
    same_mesh("cube22.msh", "cube41.msh");
    same_mesh("cylinder22.msh", "cylinder41.msh");
    same_mesh("cube22.msh", "cube.node");
    same_mesh("cube.ele", "cube.node");
    /* size limit and errors name the file and line */
    CHECK(pk_mesh_read_msh(data("cube41.msh"), 1000, &m, err, sizeof err) != 0 &&
          strstr(err, "limit"));
    CHECK(pk_mesh_read_tetgen(data("cube.node"), 1000, &m, err, sizeof err) != 0 &&
          strstr(err, "limit"));
    CHECK(pk_mesh_read_msh(data("cube.node"), 0, &m, err, sizeof err) != 0 &&
          strstr(err, "not a Gmsh"));
    CHECK(pk_mesh_read_msh(data("missing.msh"), 0, &m, err, sizeof err) != 0 &&
          strstr(err, "cannot open"));
}

static void test_inline_json(void)
{
    json_error_t je;
    json_t *j = json_loads("{\"nodes\": [[0,0,0],[1,0,0],[0,1,0],[0,0,1],[1,1,1]],"
                           " \"tets\": [[0,2,1,3],[1,2,3,4]], \"regions\": [4, 5]}",
                           0, &je);
    pk_mesh m;
    pk_mesh_report rep;
    char err[256];
    CHECK_MSG(pk_mesh_from_json(j, 0, &m, &rep, err, sizeof err) == 0, "%s", err);
    CHECK(m.ntet == 2 && rep.reoriented == 1 && m.region[1] == 5);
    CHECK_NEAR(m.volume, 1.0 / 6 + 1.0 / 3, 1e-15);
    pk_mesh_free(&m);
    CHECK(pk_mesh_from_json(j, 1, &m, &rep, err, sizeof err) != 0 && strstr(err, "limit"));
    json_decref(j);
    j = json_loads("{\"nodes\": [[0,0,0],[1,0,0],[0,1,0],[0,0,1]], \"tets\": [[0,1,2,7]]}", 0, &je);
    CHECK(pk_mesh_from_json(j, 0, &m, &rep, err, sizeof err) != 0 && strstr(err, "tet 0"));
    json_decref(j);
}

int main(void)
{
    RUN(test_box_mesh);
    RUN(test_reoriented_and_sliver);
    RUN(test_refusals);
    RUN(test_locate_cylinder);
    RUN(test_readers);
    RUN(test_inline_json);
    return check_summary();
}
