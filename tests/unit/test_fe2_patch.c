/* test_fe2_patch.c — the macro mesh of FE² and the patch tests with the
 * linear elastic surrogate (Meier 2009 ch. 6; issue 26 "Patch tests"):
 * prescribed linear boundary displacements reproduce the uniform strain at
 * every Gauss point and the exact interior displacements (Q1, triangles,
 * mixed); a pressure on one edge with rollers gives the uniform stress. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "homog_fixture.h"
#include "fe2_fixture.h"
#include "core/fe2/fe2_fields.h"

static const double H[4] = {0.01, 0.003, -0.002, -0.005}; /* ∇u: 11, 12, 21, 22 */

/* Areas, Gauss points and the checks of pk_fe2_mesh_finish. */
static void test_mesh(void)
{
    pk_fe2_mesh m;
    mesh_triangles(&m, 1);
    CHECK(pk_fe2_gauss_count(&m) == 4 + 6);
    double area = 0, X[2], w;
    size_t e;
    for (size_t g = 0; g < pk_fe2_gauss_count(&m); g++) {
        pk_fe2_gauss_point(&m, g, X, &e, &w);
        CHECK(e == (g < 4 ? 0 : g - 3));
        area += w;
    }
    CHECK_NEAR(area, 2.0, 1e-14);
    pk_fe2_gauss_point(&m, 4, X, &e, NULL); /* centroid of triangle (1, 7, 6) */
    CHECK_NEAR(X[0], (1 + 1.4 + 0.6) / 3, 1e-15);
    CHECK_NEAR(X[1], (0 + 0.6 + 0.45) / 3, 1e-15);
    /* body force: Σ = b · area */
    double *f = calloc(2 * m.nnode, sizeof *f), b[2] = {0.5, -2}, s[2] = {0, 0};
    pk_fe2_body_force(&m, b, f);
    for (size_t a = 0; a < m.nnode; a++)
        s[0] += f[2 * a], s[1] += f[2 * a + 1];
    CHECK_NEAR(s[0], 1.0, 1e-14);
    CHECK_NEAR(s[1], -4.0, 1e-14);
    free(f);
    /* a clockwise element and an out-of-range node are refused */
    char err[160];
    int32_t c0[4];
    memcpy(c0, m.conn, sizeof c0);
    m.conn[1] = c0[3], m.conn[3] = c0[1];
    CHECK(pk_fe2_mesh_finish(&m, err, sizeof err) != 0 && strstr(err, "element 0"));
    memcpy(m.conn, c0, sizeof c0);
    m.conn[4 * 2 + 1] = 8;
    CHECK(pk_fe2_mesh_finish(&m, err, sizeof err) != 0 && strstr(err, "element 2"));
    pk_fe2_mesh_free(&m);

    CHECK(pk_fe2_mesh_rectangle(3, 2, 3, 2, &m) == 0);
    CHECK(m.nnode == 12 && m.nelem == 6 && pk_fe2_gauss_count(&m) == 24);
    CHECK(m.conn[4 * 4 + 0] == 5 && m.conn[4 * 4 + 2] == 10); /* element (1, 1) */
    area = 0;
    for (size_t g = 0; g < 24; g++) {
        pk_fe2_gauss_point(&m, g, X, &e, &w);
        area += w;
    }
    CHECK_NEAR(area, 6.0, 1e-14);
    pk_fe2_mesh_free(&m);
}

/* Linear boundary displacements u = H·X on every boundary node: F = 1 + H
 * at every Gauss point and u = H·X at the free interior nodes (1e-12). */
static void patch_displacement(pk_fe2_mesh *m, const char *name)
{
    pk_fe2_linear_elastic le = {.lambda = 2.0, .mu = 1.3};
    pk_fe2_material mat = pk_fe2_linear_elastic_material(&le);
    int32_t *fix = malloc(2 * m->nnode * sizeof *fix);
    size_t nfix = fix_boundary(m, fix);
    pk_fe2_problem pb = {m, &mat, nfix, fix, &pk_sparse_cholmod, NULL, NULL};
    double *uD = malloc(nfix * sizeof *uD), *fz = calloc(2 * m->nnode, sizeof *fz);
    for (size_t k = 0; k < nfix; k++) {
        const double *X = &m->xy[2 * (size_t)(fix[k] / 2)];
        const int i = fix[k] % 2;
        uD[k] = H[2 * i] * X[0] + H[2 * i + 1] * X[1];
    }
    pk_fe2_state s;
    CHECK(pk_fe2_state_init(&s, m) == 0);
    pk_fe2_newton_opts o = newton_opts();
    pk_fe2_step_report rep;
    int rc = pk_fe2_step(&pb, &o, &s, uD, fz, &rep, NULL);
    CHECK_MSG(rc == 0, "%s: %s", name, rep.why);
    CHECK(rep.cuts == 0 && rep.nparts == 1 && rep.parts[0].n <= 3);
    double worst = 0;
    for (size_t g = 0; g < s.ngp; g++)
        for (int I = 0; I < 4; I++)
            worst = fmax(worst, fabs(s.F[4 * g + I] - ((I == 0 || I == 3) + H[I])));
    for (size_t a = 0; a < m->nnode; a++)
        for (int i = 0; i < 2; i++)
            worst = fmax(
                worst,
                fabs(s.u[2 * a + i] - (H[2 * i] * m->xy[2 * a] + H[2 * i + 1] * m->xy[2 * a + 1])));
    CHECK_MSG(worst < 1e-12, "%s: strain/displacement error %g", name, worst);
    printf("  %-10s Gauss points %zu, free dofs %zu, residuals", name, s.ngp, 2 * m->nnode - nfix);
    for (int k = 0; k < rep.parts[0].n; k++)
        printf(" %.2e", rep.parts[0].res[k]);
    printf(", max error %.1e\n", worst);
    pk_fe2_state_free(&s);
    free(fix), free(uD), free(fz);
}

static void test_patch_q1(void)
{
    pk_fe2_mesh m;
    mesh_q1_distorted(&m);
    patch_displacement(&m, "Q1");
    pk_fe2_mesh_free(&m);
}

static void test_patch_triangles(void)
{
    pk_fe2_mesh m;
    mesh_triangles(&m, 0);
    patch_displacement(&m, "triangles");
    pk_fe2_mesh_free(&m);
    mesh_triangles(&m, 1);
    patch_displacement(&m, "mixed");
    pk_fe2_mesh_free(&m);
}

/* Pressure p on the right edge, rollers on the left (u_x = 0) and bottom
 * (u_y = 0): P̄ = −p e₁⊗e₁ at every Gauss point, the reaction p·height. */
static void patch_traction(pk_fe2_mesh *m, const char *name)
{
    const double p = 0.02;
    pk_fe2_linear_elastic le = {.lambda = 2.0, .mu = 1.3};
    pk_fe2_material mat = pk_fe2_linear_elastic_material(&le);
    double xmax = 0, ymax = 0;
    for (size_t a = 0; a < m->nnode; a++)
        xmax = fmax(xmax, m->xy[2 * a]), ymax = fmax(ymax, m->xy[2 * a + 1]);
    int32_t *fix = malloc(2 * m->nnode * sizeof *fix), right[8];
    size_t nfix = 0, nright = 0;
    for (size_t a = 0; a < m->nnode; a++) {
        if (m->xy[2 * a] == 0)
            fix[nfix++] = (int32_t)(2 * a);
        if (m->xy[2 * a + 1] == 0)
            fix[nfix++] = (int32_t)(2 * a + 1);
        if (m->xy[2 * a] == xmax)
            right[nright++] = (int32_t)a;
    }
    CHECK(nright == 2 || nright == 3);
    double *f = calloc(2 * m->nnode, sizeof *f), *uD = calloc(nfix, sizeof *uD);
    const double t[2] = {-p, 0};
    /* the right edge's segments, bottom to top */
    for (size_t i = 0; i < nright; i++)
        for (size_t j = 0; j < nright; j++)
            if (m->xy[2 * right[j] + 1] > m->xy[2 * right[i] + 1]) {
                int next = 1;
                for (size_t k = 0; k < nright; k++)
                    next &= !(m->xy[2 * right[k] + 1] > m->xy[2 * right[i] + 1] &&
                              m->xy[2 * right[k] + 1] < m->xy[2 * right[j] + 1]);
                if (next)
                    pk_fe2_edge_traction(m, right[i], right[j], t, f);
            }
    pk_fe2_problem pb = {m, &mat, nfix, fix, &pk_sparse_cholmod, NULL, NULL};
    pk_fe2_state s;
    CHECK(pk_fe2_state_init(&s, m) == 0);
    pk_fe2_newton_opts o = newton_opts();
    pk_fe2_step_report rep;
    CHECK_MSG(pk_fe2_step(&pb, &o, &s, uD, f, &rep, NULL) == 0, "%s", rep.why);
    double worst = 0;
    for (size_t g = 0; g < s.ngp; g++)
        for (int I = 0; I < 4; I++)
            worst = fmax(worst, fabs(s.P[4 * g + I] - (I == 0 ? -p : 0)));
    CHECK_MSG(worst < 1e-12 * p, "%s: stress error %g", name, worst);
    CHECK_NEAR(rep.reaction[0], p * ymax, 1e-13);
    CHECK_NEAR(rep.reaction[1], 0, 1e-13);
    printf("  %-10s P11 = %.15g (want %g), reaction %.15g\n", name, s.P[0], -p, rep.reaction[0]);
    pk_fe2_state_free(&s);
    free(fix), free(f), free(uD);
}

static void test_patch_traction(void)
{
    pk_fe2_mesh m;
    mesh_q1_distorted(&m);
    patch_traction(&m, "Q1");
    pk_fe2_mesh_free(&m);
    mesh_triangles(&m, 1);
    patch_traction(&m, "mixed");
    pk_fe2_mesh_free(&m);
}

/* Shoelace area of the deformed element e. */
static double deformed_area(const pk_fe2_mesh *m, size_t e, const double *u)
{
    const int nen = pk_fe2_elem_nodes(m, e);
    double a = 0;
    for (int k = 0; k < nen; k++) {
        const size_t p = (size_t)m->conn[4 * e + k], q = (size_t)m->conn[4 * e + (k + 1) % nen];
        const double xp = m->xy[2 * p] + u[2 * p], yp = m->xy[2 * p + 1] + u[2 * p + 1];
        const double xq = m->xy[2 * q] + u[2 * q], yq = m->xy[2 * q + 1] + u[2 * q + 1];
        a += 0.5 * (xp * yq - xq * yp);
    }
    return a;
}

/* σ̄ = J⁻¹P̄F̄ᵀ inverts P̄ = Jσ̄F̄⁻ᵀ; von Mises of uniaxial and shear stress;
 * the deformed volume equals the shoelace areas of the deformed elements
 * under random nodal displacements (Q1 and triangles). */
static void test_fields(void)
{
    const double F[4] = {1.02, 0.03, -0.01, 0.97}, sig[4] = {-0.3, 0.05, 0.05, -0.1};
    const double J = F[0] * F[3] - F[1] * F[2];
    const double Fit[4] = {F[3] / J, -F[2] / J, -F[1] / J, F[0] / J}; /* F⁻ᵀ */
    double P[4], s[4];
    for (int i = 0; i < 2; i++)
        for (int k = 0; k < 2; k++)
            P[2 * i + k] = J * (sig[2 * i] * Fit[k] + sig[2 * i + 1] * Fit[2 + k]);
    pk_fe2_cauchy(F, P, s);
    for (int I = 0; I < 4; I++)
        CHECK_NEAR(s[I], sig[I], 1e-15);
    const double uni[4] = {2, 0, 0, 0}, shear[4] = {0, 1, 1, 0};
    CHECK_NEAR(pk_fe2_von_mises(uni), 2 * sqrt(0.75), 1e-15);
    CHECK_NEAR(pk_fe2_von_mises(shear), sqrt(3.0), 1e-15);
    for (int which = 0; which < 2; which++) {
        pk_fe2_mesh m;
        if (which)
            mesh_triangles(&m, 1);
        else
            mesh_q1_distorted(&m);
        double *u = malloc(2 * m.nnode * sizeof *u), *R = malloc(2 * m.nnode * sizeof *R);
        pk_rng rng;
        pk_rng_seed(&rng, 9, 0);
        for (size_t d = 0; d < 2 * m.nnode; d++)
            u[d] = pk_rng_range(&rng, -0.1, 0.1);
        /* the Gauss points' F̄ through the residual's evaluation round */
        pk_fe2_state st;
        CHECK(pk_fe2_state_init(&st, &m) == 0);
        pk_fe2_linear_elastic le = {1, 1};
        pk_fe2_material mat = pk_fe2_linear_elastic_material(&le);
        int32_t fix[32];
        size_t nfix = 0;
        for (size_t d = 0; d < 2 * m.nnode; d++)
            fix[nfix++] = (int32_t)d;
        pk_fe2_problem pb = {&m, &mat, nfix, fix, &pk_sparse_cholmod, NULL, NULL};
        pk_fe2_newton_opts o = newton_opts();
        pk_fe2_step_report rep;
        double fz[32] = {0};
        CHECK(pk_fe2_step(&pb, &o, &st, u, fz, &rep, NULL) == 0);
        double want = 0;
        for (size_t e = 0; e < m.nelem; e++)
            want += deformed_area(&m, e, u);
        CHECK_NEAR(pk_fe2_deformed_volume(&m, st.F), want, 1e-14);
        pk_fe2_state_free(&st);
        free(u), free(R);
        pk_fe2_mesh_free(&m);
    }
}

int main(void)
{
    RUN(test_mesh);
    RUN(test_patch_q1);
    RUN(test_patch_triangles);
    RUN(test_patch_traction);
    RUN(test_fields);
    return check_summary();
}
