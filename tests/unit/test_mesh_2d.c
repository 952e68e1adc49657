/* test_mesh_2d.c — the 2D Gmsh reader of the FE² macro mesh: triangles and
 * quadrilaterals from MSH 2.2 and 4.1 ASCII, physical groups as named sets
 * (points and lines: nodes and edges; surfaces: elements), the same mesh
 * from both versions (tests/data/meshes/plate22.msh, plate41.msh: a unit
 * square Q1 and a triangle beside it), and refusals with a reason. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "api/mesh/mesh_io.h"

static const char *data(const char *name)
{
    static char buf[4096];
    const char *src = getenv("PACKD_SRC");
    snprintf(buf, sizeof buf, "%s/tests/data/meshes/%s", src ? src : ".", name);
    return buf;
}

static void check_plate(const pk_mesh2d *m, int with_tip)
{
    CHECK(m->nnode == 5 && m->nelem == 2);
    const int32_t quad[4] = {0, 1, 2, 3}, tri[4] = {1, 4, 2, -1};
    CHECK(memcmp(&m->conn[0], quad, sizeof quad) == 0);
    CHECK(memcmp(&m->conn[4], tri, sizeof tri) == 0);
    CHECK(m->xy[2 * 4] == 2 && m->xy[2 * 4 + 1] == 0.5);
    const pk_mesh2d_set *left = pk_mesh2d_find(m, "left"), *bot = pk_mesh2d_find(m, "bottom side"),
                        *soil = pk_mesh2d_find(m, "soil"), *tip = pk_mesh2d_find(m, "tip");
    CHECK(left && left->nnode == 2 && left->node[0] == 0 && left->node[1] == 3 &&
          left->nedge == 1 && left->edge[0] == 3 && left->edge[1] == 0);
    CHECK(bot && bot->nnode == 2 && bot->nedge == 1 && bot->edge[0] == 0 && bot->edge[1] == 1);
    CHECK(soil && soil->nelem == 2 && soil->nnode == 5 && soil->nedge == 0);
    CHECK(with_tip ? tip && tip->nnode == 1 && tip->node[0] == 4 : tip == NULL);
}

static void test_msh22(void)
{
    pk_mesh2d m;
    char err[512] = "";
    CHECK_MSG(pk_mesh2d_read_msh(data("plate22.msh"), 0, &m, err, sizeof err) == 0, "%s", err);
    check_plate(&m, 1);
    pk_mesh2d_free(&m);
}

static void test_msh41(void)
{
    pk_mesh2d m;
    char err[512] = "";
    CHECK_MSG(pk_mesh2d_read_msh(data("plate41.msh"), 0, &m, err, sizeof err) == 0, "%s", err);
    /* the point entity 5 has no physical group: no "tip" */
    check_plate(&m, 0);
    pk_mesh2d_free(&m);
}

static void test_refusals(void)
{
    pk_mesh2d m;
    char err[512] = "";
    CHECK(pk_mesh2d_read_msh(data("plate22.msh"), 1, &m, err, sizeof err) != 0 &&
          strstr(err, "more than 1 elements"));
    CHECK(pk_mesh2d_read_msh(data("cube22.msh"), 0, &m, err, sizeof err) != 0 &&
          strstr(err, "element type 4"));
    CHECK(pk_mesh2d_read_msh(data("missing.msh"), 0, &m, err, sizeof err) != 0);
}

int main(void)
{
    RUN(test_msh22);
    RUN(test_msh41);
    RUN(test_refusals);
    return check_summary();
}
