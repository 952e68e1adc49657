/* test_fe2_setup.c — the fe2 job's macro setup and stress measures: the
 * rectangle's named edges and corners, a pressure's nodal forces (resultant
 * p·ℓ against the outward normal, whichever way the edge is listed), stage
 * targets ramped linearly, a conflict of two supports named, and the Cauchy
 * stress and von Mises value (2×2 deviator) of known states. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "check.h"
#include "api/fe2/fe2_job.h"
#include "api/fe2/fe2_record.h"

static pk_fe2_job job_of(json_t *in)
{
    pk_fe2_job j = {0};
    j.max_gauss_points = 1000;
    j.mesh = json_object_get(in, "mesh");
    j.bcs = json_object_get(in, "boundary_conditions");
    j.stages = json_object_get(in, "stages");
    return j;
}

static void test_rectangle_pressure(void)
{
    json_t *in = json_loads(
        "{\"mesh\": {\"rectangle\": {\"size\": [2, 3], \"elements\": [2, 3]}},"
        " \"boundary_conditions\": ["
        "  {\"name\": \"lx\", \"type\": \"displacement\", \"on\": \"left\", \"component\": \"x\"},"
        "  {\"name\": \"by\", \"type\": \"displacement\", \"on\": \"bottom\", \"component\": "
        "\"y\"},"
        "  {\"name\": \"ty\", \"type\": \"displacement\", \"on\": \"top\", \"component\": \"y\"},"
        "  {\"name\": \"p\", \"type\": \"pressure\", \"on\": \"right\"}],"
        " \"stages\": [{\"increments\": 2, \"targets\": {\"p\": 0.5}},"
        "              {\"increments\": 4, \"targets\": {\"ty\": -0.3}}]}",
        0, NULL);
    pk_fe2_job j = job_of(in);
    pk_fe2_setup s;
    pk_schema_errors errs = {0};
    CHECK(pk_fe2_setup_build(&j, &s, &errs) == 0);
    CHECK(s.mesh.nnode == 12 && s.mesh.nelem == 6 && pk_fe2_gauss_count(&s.mesh) == 24);
    const pk_mesh2d_set *r = pk_mesh2d_find(&s.sets, "right"),
                        *c = pk_mesh2d_find(&s.sets, "upper_left");
    CHECK(r && r->nnode == 4 && r->nedge == 3 && r->node[0] == 2 && r->node[3] == 11);
    CHECK(c && c->nnode == 1 && c->node[0] == 9);
    /* 4 + 3 + 3 prescribed dofs, each once */
    CHECK(s.nfix == 10);
    double uD[16], f[24], sx = 0, sy = 0;
    pk_fe2_setup_targets(&s, 0, 0.5, uD, f);
    for (size_t n = 0; n < 12; n++)
        sx += f[2 * n], sy += f[2 * n + 1];
    CHECK_NEAR(sx, -0.25 * 3, 1e-14); /* p = 0.25 half-way, ℓ = 3, outward normal +x */
    CHECK_NEAR(sy, 0, 1e-14);
    CHECK_NEAR(f[2 * 5], -0.25 * 1, 1e-14); /* an inner node of the edge: two half sides */
    pk_fe2_setup_targets(&s, 1, 0.25, uD, f);
    for (size_t i = 0; i < s.nfix; i++)
        if (s.fix_bc[i] == 2)
            CHECK_NEAR(uD[i], -0.075, 1e-15);
    pk_fe2_setup_free(&s);
    json_decref(in);
}

static void test_conflict_named(void)
{
    json_t *in = json_loads(
        "{\"mesh\": {\"rectangle\": {\"size\": [1, 1], \"elements\": [1, 1]}},"
        " \"boundary_conditions\": ["
        "  {\"name\": \"a\", \"type\": \"displacement\", \"on\": \"left\", \"component\": \"x\"},"
        "  {\"name\": \"b\", \"type\": \"displacement\", \"on\": \"bottom\", \"component\": \"x\"},"
        "  {\"name\": \"c\", \"type\": \"displacement\", \"on\": \"bottom\", \"component\": "
        "\"y\"}],"
        " \"stages\": [{\"increments\": 1, \"targets\": {\"b\": 0.1}}]}",
        0, NULL);
    pk_fe2_job j = job_of(in);
    pk_fe2_setup s;
    pk_schema_errors errs = {0};
    CHECK(pk_fe2_setup_build(&j, &s, &errs) == 1);
    CHECK(errs.n == 1 && !strcmp(errs.items[0].rule, "conflict") &&
          !strcmp(errs.items[0].pointer, "/boundary_conditions/1") &&
          strstr(errs.items[0].message, "node 0"));
    pk_schema_errors_free(&errs);
    pk_fe2_setup_free(&s);
    json_decref(in);
}

static void test_stress_measures(void)
{
    const double F[4] = {2, 0, 0, 1}, P[4] = {4, 0, 0, 0};
    double sig[4];
    pk_fe2_cauchy(F, P, sig); /* σ = P Fᵀ / det F = diag(8, 0) / 2 */
    CHECK_NEAR(sig[0], 4, 1e-15);
    CHECK(sig[1] == 0 && sig[2] == 0 && sig[3] == 0);
    const double uni[4] = {2, 0, 0, 0}, shear[4] = {0, 1, 1, 0}, hydro[4] = {-3, 0, 0, -3};
    CHECK_NEAR(pk_fe2_von_mises(uni), sqrt(3.0), 1e-15); /* s = diag(1, −1): √(3/2 · 2) */
    CHECK_NEAR(pk_fe2_von_mises(shear), sqrt(3.0), 1e-15);
    CHECK(pk_fe2_von_mises(hydro) == 0);
}

int main(void)
{
    RUN(test_rectangle_pressure);
    RUN(test_conflict_named);
    RUN(test_stress_measures);
    return check_summary();
}
