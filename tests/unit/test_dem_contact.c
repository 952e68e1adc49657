/* test_dem_contact.c — contact law (Meier 2009 (4.3)–(4.16)), periodic detection with
 * the shared grid, rattler test (Table 4.3 generalised). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "core/dem/dem_contact.h"
#include "core/dem/dem_rattler.h"
#include "core/space/mat3.h"
#include "core/base/rng.h"

static void geom_init(pk_dem_geom *g, int dim, int periodic, double L, const double F[9])
{
    memset(g, 0, sizeof *g);
    g->dim = dim;
    g->periodic = periodic;
    g->L[0] = g->L[1] = g->L[2] = L;
    double I[9];
    pk_m3_identity(I);
    pk_dem_geom_set_F(g, F ? F : I);
}

/* Force = −∂Φ/∂x (4.8) and K = ∂²Φ/∂x∂x (4.12) by central differences on a
 * small overlapping cluster.  h = 1e-6 on unit-size data: truncation O(h²)
 * ≈ 1e-12, round-off ≈ 1e-16/1e-6 = 1e-10 → tolerance 1e-7 relative. */
static void check_derivatives(int dim)
{
    double x[3 * 4] = {0, 0, 0, 1.9, 0.1, 0.05, 0.9, 1.7, -0.1, 1.0, 0.6, 1.2};
    double r[4] = {1.0, 0.95, 1.05, 0.9};
    if (dim == 2)
        for (int i = 0; i < 4; i++)
            x[3 * i + 2] = 0;
    pk_dem_geom g;
    geom_init(&g, dim, 0, 0, NULL);
    pk_dem_pairs c = {0};
    CHECK(pk_dem_pairs_build(&c, &g, x, r, 4, 0.5) == 0);
    CHECK(c.n == 6);
    double E = 7.0, f[12], phi;
    size_t nc = pk_dem_eval(&c, &g, x, r, 4, E, f, &phi, NULL);
    CHECK(nc >= 4);
    const double h = 1e-6;
    uint8_t all[4] = {1, 1, 1, 1};
    double fsum[3] = {0, 0, 0};
    for (size_t i = 0; i < 4; i++)
        for (int a = 0; a < dim; a++) {
            fsum[a] += f[3 * i + a];
            double xp[12], xm[12], ep, em, fp[12], fm[12];
            memcpy(xp, x, sizeof xp);
            memcpy(xm, x, sizeof xm);
            xp[3 * i + a] += h;
            xm[3 * i + a] -= h;
            pk_dem_eval(&c, &g, xp, r, 4, E, fp, &ep, NULL);
            pk_dem_eval(&c, &g, xm, r, 4, E, fm, &em, NULL);
            CHECK_NEAR(f[3 * i + a], -(ep - em) / (2 * h), 1e-7 * E);
            /* column (i,a) of K = −∂f/∂x_(i,a) */
            double v[12] = {0}, Kv[12];
            v[3 * i + a] = 1;
            pk_dem_eval(&c, &g, x, r, 4, E, NULL, NULL, NULL);
            pk_dem_kv(&c, dim, 4, E, all, v, Kv);
            for (size_t j = 0; j < 4; j++)
                for (int b = 0; b < dim; b++)
                    CHECK_NEAR(Kv[3 * j + b], -(fp[3 * j + b] - fm[3 * j + b]) / (2 * h), 1e-6 * E);
        }
    for (int a = 0; a < dim; a++)
        CHECK_NEAR(fsum[a], 0, 1e-13 * E); /* Newton's third law (4.9) */
    /* rigid translation: K·t = 0 (4.14) */
    double t[12] = {0}, Kt[12];
    for (int i = 0; i < 4; i++)
        t[3 * i] = 1, t[3 * i + 1] = -0.5;
    pk_dem_eval(&c, &g, x, r, 4, E, NULL, NULL, NULL);
    pk_dem_kv(&c, dim, 4, E, all, t, Kt);
    for (int k = 0; k < 12; k++)
        CHECK_NEAR(Kt[k], 0, 1e-12 * E);
    /* Gershgorin bounds the Rayleigh quotient of any vector */
    double gb = pk_dem_gershgorin(&c, dim, 4, E, all);
    double v[12], Kv[12], vv = 0, vKv = 0;
    for (int k = 0; k < 12; k++)
        v[k] = (k % 3 < dim) ? sin(1.3 * k + 0.2) : 0;
    pk_dem_kv(&c, dim, 4, E, all, v, Kv);
    for (int k = 0; k < 12; k++)
        vv += v[k] * v[k], vKv += v[k] * Kv[k];
    CHECK(vKv / vv <= gb);
    pk_dem_pairs_free(&c);
}

static void test_forces_and_stiffness_2d(void) { check_derivatives(2); }
static void test_forces_and_stiffness_3d(void) { check_derivatives(3); }

/* Candidate pairs under a sheared periodic F̄ contain every contact that a
 * brute-force search over all images finds (min image in the deformed
 * lattice), and each contact's branch vector is that image. */
static void test_periodic_detection_sheared(void)
{
    for (int dim = 2; dim <= 3; dim++) {
        pk_rng rng;
        pk_rng_seed(&rng, 11, (uint64_t)dim);
        const size_t n = dim == 2 ? 300 : 250;
        const double L = dim == 2 ? 20 : 9;
        double *x = malloc(3 * n * sizeof *x), *r = malloc(n * sizeof *r);
        double F[9] = {0.97, 0.35, 0, 0.02, 1.01, 0, 0, 0, 1};
        if (dim == 3)
            F[2] = 0.1, F[5] = -0.05, F[8] = 0.98;
        pk_dem_geom g;
        geom_init(&g, dim, 1, L, F);
        for (size_t i = 0; i < n; i++) {
            double s[3] = {0, 0, 0};
            for (int k = 0; k < dim; k++)
                s[k] = pk_rng_range(&rng, 0, L);
            pk_m3_vec(F, s, &x[3 * i]);
            r[i] = pk_rng_range(&rng, 0.4, 0.8);
        }
        pk_dem_pairs c = {0};
        CHECK(pk_dem_pairs_build(&c, &g, x, r, n, 0.0) == 0);
        size_t nc = pk_dem_eval(&c, &g, x, r, n, 1, NULL, NULL, NULL);
        size_t brute = 0;
        for (size_t i = 0; i < n; i++)
            for (size_t j = i + 1; j < n; j++) {
                double best = INFINITY;
                int m = dim == 3 ? 1 : 0;
                for (int a = -2; a <= 2; a++)
                    for (int b = -2; b <= 2; b++)
                        for (int e = -m; e <= m; e++) {
                            double ds[3], sh[3] = {a * L, b * L, e * L}, l[3], d[3];
                            for (int k = 0; k < 3; k++)
                                d[k] = x[3 * j + k] - x[3 * i + k];
                            pk_m3_vec(g.Finv, d, ds);
                            for (int k = 0; k < 3; k++)
                                ds[k] = k < dim ? ds[k] + sh[k] : 0;
                            pk_m3_vec(F, ds, l);
                            best = fmin(best, sqrt(l[0] * l[0] + l[1] * l[1] + l[2] * l[2]));
                        }
                brute += best <= r[i] + r[j];
            }
        CHECK_MSG(nc == brute, "dim %d: grid %zu contacts, brute force %zu", dim, nc, brute);
        CHECK(nc > 10);
        /* too-small box for this deformation is refused, not silently wrong */
        double Fbig[9] = {0.1, 0, 0, 0, 1, 0, 0, 0, 1};
        pk_dem_geom_set_F(&g, Fbig);
        CHECK(pk_dem_pairs_build(&c, &g, x, r, n, 0.0) == -2);
        pk_dem_pairs_free(&c);
        free(x);
        free(r);
    }
}

static void dirs2(double *d, const double *deg, int m)
{
    for (int k = 0; k < m; k++) {
        d[3 * k] = cos(deg[k] * M_PI / 180);
        d[3 * k + 1] = sin(deg[k] * M_PI / 180);
        d[3 * k + 2] = 0;
    }
}

/* Remark 4.6 and its special cases in 2D (180°, 4×90°) */
static void test_jamming_test_2d(void)
{
    double d[3 * 8];
    double four[] = {0, 90, 180, 270};
    dirs2(d, four, 4);
    CHECK(pk_dem_positively_spanning(d, 4, 2, 1e-9)); /* literal Table 4.3 gets this wrong */
    double two[] = {0, 180};
    dirs2(d, two, 2);
    CHECK(!pk_dem_positively_spanning(d, 2, 2, 1e-9));
    double tri[] = {10, 130, 250};
    dirs2(d, tri, 3);
    CHECK(pk_dem_positively_spanning(d, 3, 2, 1e-9));
    double half[] = {0, 60, 120, 179.9};
    dirs2(d, half, 4);
    CHECK(!pk_dem_positively_spanning(d, 4, 2, 1e-9));
    double edge[] = {0, 90, 180}; /* closed half-plane: rattler */
    dirs2(d, edge, 3);
    CHECK(!pk_dem_positively_spanning(d, 3, 2, 1e-9));
}

static void test_jamming_test_3d(void)
{
    const double s = 1 / sqrt(3.0);
    double tet[12] = {s, s, s, s, -s, -s, -s, s, -s, -s, -s, s};
    CHECK(pk_dem_positively_spanning(tet, 4, 3, 1e-9));
    double oct[18] = {1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1};
    CHECK(pk_dem_positively_spanning(oct, 6, 3, 1e-9));
    CHECK(!pk_dem_positively_spanning(oct, 5, 3, 1e-9)); /* −z missing: hemisphere z >= 0 */
    double planar[12] = {1, 0, 0, 0, 1, 0, -1, 0, 0, 0, -1, 0}; /* all in z = 0 */
    CHECK(!pk_dem_positively_spanning(planar, 4, 3, 1e-9));
}

/* Iterated removal: a free grain jammed only through a rattler becomes a
 * rattler itself (Table 4.3's repeat loop). */
static void test_rattler_cascade(void)
{
    /* fixed ring A..D around free grain P at the origin; free grain Q sits
     * outside touching P and one fixed grain only. */
    double x[3 * 7] = {0, 0, 0, 2, 0, 0, 0, 2, 0, -2, 0, 0, 0, -2, 0, 4, 0, 0, 2, 2, 0};
    double r[7] = {1.01, 1.01, 1.01, 1.01, 1.01, 1.01, 1.01};
    uint8_t fr[7] = {1, 0, 0, 0, 0, 1, 0}, rat[7];
    pk_dem_geom g;
    geom_init(&g, 2, 0, 0, NULL);
    pk_dem_pairs c = {0};
    pk_dem_pairs_build(&c, &g, x, r, 7, 0.1);
    pk_dem_eval(&c, &g, x, r, 7, 1, NULL, NULL, NULL);
    CHECK(pk_dem_rattlers(&c, 2, 7, fr, rat) == 1);
    CHECK(rat[0] == 0 && rat[5] == 1);
    /* remove the fixed grains below and left of P: P rests on 2 contacts → rattler */
    uint8_t fr2[7] = {1, 0, 0, 1, 1, 1, 0};
    CHECK(pk_dem_rattlers(&c, 2, 7, fr2, rat) == 4);
    pk_dem_pairs_free(&c);
}

int main(void)
{
    RUN(test_forces_and_stiffness_2d);
    RUN(test_forces_and_stiffness_3d);
    RUN(test_periodic_detection_sheared);
    RUN(test_jamming_test_2d);
    RUN(test_jamming_test_3d);
    RUN(test_rattler_cascade);
    return check_summary();
}
