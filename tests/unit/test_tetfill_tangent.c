/* test_tetfill_tangent.c — Jerier's four-sphere tangency solve (Eqs. 1–9):
 * the regular-tetrahedron hole, tangency residuals of random quadruples,
 * detection of coplanar (det A ≈ 0) quadruples relative to their scale, and
 * the three-sphere fallback. */
#include <math.h>
#include <string.h>

#include "check.h"
#include "core/base/rng.h"
#include "core/tetfill/tetfill_tangent.h"
#include "core/tetfill/tetfill_tangent_internal.h"

static double residual(const double c[4][3], const double r[4], const double x[3], double rr, int n)
{
    double worst = 0;
    for (int k = 0; k < n; k++) {
        double d2 = 0;
        for (int j = 0; j < 3; j++)
            d2 += (x[j] - c[k][j]) * (x[j] - c[k][j]);
        worst = fmax(worst, fabs(sqrt(d2) - (rr + r[k])));
    }
    return worst;
}

static void test_regular_tetrahedron(void)
{
    /* four mutually touching spheres r = √2 on a regular tet: the hole sphere
     * is r = √3 − √2 at the origin; the other root −(√3 + √2) (enclosing) is
     * dropped */
    double c[4][3] = {{1, 1, 1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}};
    double r[4] = {sqrt(2.0), sqrt(2.0), sqrt(2.0), sqrt(2.0)}, x[2][3], rr[2];
    int n;
    CHECK(pk_tangent_sphere(c, r, 1e-12, x, rr, &n) == PK_TANGENT_OK);
    CHECK(n == 1);
    CHECK_NEAR(rr[0], sqrt(3.0) - sqrt(2.0), 1e-14);
    for (int k = 0; k < 3; k++)
        CHECK_NEAR(x[0][k], 0, 1e-14);
    /* det A = ±48 V_tet (V = 8/3 for this tet) */
    CHECK_NEAR(fabs(pk_tangent_det(c)), 48 * 8.0 / 3, 1e-12);
}

static void test_random_residuals(void)
{
    /* centres uniform in [0,4]³, radii in [0.2, 1]: every returned root is
     * tangent to all four within 1e-9·r_min (the filler's τ, r_min = 0.2);
     * both branches of the root choice occur */
    pk_rng g;
    pk_rng_seed(&g, 11, 0);
    int two = 0, some = 0;
    double worst = 0;
    for (int t = 0; t < 20000; t++) {
        double c[4][3], r[4], x[2][3], rr[2];
        for (int k = 0; k < 4; k++) {
            for (int j = 0; j < 3; j++)
                c[k][j] = pk_rng_range(&g, 0, 4);
            r[k] = pk_rng_range(&g, 0.2, 1);
        }
        int n;
        if (pk_tangent_sphere(c, r, 1e-9 * 0.2, x, rr, &n) != PK_TANGENT_OK)
            continue;
        some += n > 0;
        two += n == 2;
        for (int i = 0; i < n; i++) {
            CHECK(rr[i] > 0);
            worst = fmax(worst, residual(c, r, x[i], rr[i], 4));
        }
    }
    CHECK_MSG(worst <= 1e-9 * 0.2, "worst residual %g", worst);
    CHECK(some > 1000 && two > 100);
}

static void test_coplanar_detected(void)
{
    double c[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0.3, 0.4, 0}}, r[4] = {0.1, 0.2, 0.3, 0.1};
    double x[2][3], rr[2];
    int n = 7;
    CHECK(pk_tangent_sphere(c, r, 1e-9, x, rr, &n) == PK_TANGENT_SINGULAR && n == 0);
    /* nearly coplanar (height 1e-12 over unit edges): singular relative to ℓ³ */
    c[3][2] = 1e-12;
    CHECK(pk_tangent_sphere(c, r, 1e-9, x, rr, &n) == PK_TANGENT_SINGULAR);
    /* the same shape at any scale gets the same verdict: singular at 1e-6
     * and at 1e6 (an absolute test would call the first singular and the
     * second regular), regular with height 1e-3 at both scales */
    for (int s = -1; s <= 1; s += 2) {
        double f = pow(10, 6 * s), cs[4][3], rs[4];
        for (int k = 0; k < 4; k++) {
            for (int j = 0; j < 3; j++)
                cs[k][j] = c[k][j] * f;
            rs[k] = r[k] * f;
        }
        CHECK(pk_tangent_sphere(cs, rs, 1e-9 * f, x, rr, &n) == PK_TANGENT_SINGULAR);
        cs[3][2] = 1e-3 * f;
        CHECK(pk_tangent_sphere(cs, rs, 1e-9 * f, x, rr, &n) == PK_TANGENT_OK);
    }
}

static void test_three_sphere(void)
{
    /* three touching unit spheres in a plane: a sphere of radius ρ tangent to
     * all three sits on the axis through their centroid, both sides */
    double c[3][3] = {{0, 0, 0}, {2, 0, 0}, {1, sqrt(3.0), 0}}, r[3] = {1, 1, 1}, x[2][3];
    double rho = 0.5;
    int n = pk_tangent_sphere3(c, r, rho, x);
    CHECK(n == 2);
    for (int i = 0; i < n; i++) {
        double c4[4][3], r4[4] = {1, 1, 1, 0};
        memcpy(c4, c, sizeof c);
        CHECK(residual(c4, r4, x[i], rho, 3) < 1e-14);
        CHECK_NEAR(x[i][0], 1, 1e-14);
        CHECK_NEAR(x[i][1], sqrt(3.0) / 3, 1e-14);
    }
    CHECK(x[0][2] * x[1][2] < 0);
    /* too small to touch all three: none */
    CHECK(pk_tangent_sphere3(c, r, 0.1, x) == 0);
}

static void test_point_in_tet(void)
{
    double c[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    double in[3] = {0.2, 0.2, 0.2}, out[3] = {0.5, 0.5, 0.5};
    CHECK(pk_point_in_tet(c, in) && !pk_point_in_tet(c, out));
    double swap[3];
    memcpy(swap, c[1], sizeof swap); /* either orientation */
    memcpy(c[1], c[2], sizeof swap);
    memcpy(c[2], swap, sizeof swap);
    CHECK(pk_point_in_tet(c, in) && !pk_point_in_tet(c, out));
}

int main(void)
{
    RUN(test_regular_tetrahedron);
    RUN(test_random_residuals);
    RUN(test_coplanar_detected);
    RUN(test_three_sphere);
    RUN(test_point_in_tet);
    return check_summary();
}
