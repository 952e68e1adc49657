/* test_dem_kblocks.c — the compact stiffness blocks of the Lanczos estimate
 * (core/dem/dem_kblocks.h) give K·v exactly as pk_dem_kv does (same operations,
 * same order: compared with ==), on jammed periodic packings under a sheared
 * F̄, 2D and 3D, with held grains in the mask and with pair-specific
 * stiffness classes. */
#include "check.h"
#include "core/dem/dem_kblocks.h"
#include "homog_fixture.h"

static void check_kv_equal(int dim, size_t n, double phi, int classes)
{
    pk_box b;
    pk_particles p;
    make_jammed(dim, n, phi, 5, &b, &p);
    pk_dem_geom g = {.dim = dim, .periodic = 1, .L = {b.L[0], b.L[1], b.L[2]}};
    double F[9];
    diagF(F, 0.98, 1.01, dim == 3 ? 0.99 : 1.0);
    F[1] = 0.02;
    pk_dem_geom_set_F(&g, F);
    double *x = malloc(3 * n * sizeof *x), *v = malloc(3 * n * sizeof *v);
    double *k1 = malloc(3 * n * sizeof *k1), *k2 = malloc(3 * n * sizeof *k2);
    uint8_t *mask = malloc(n);
    int32_t *cls = malloc(n * sizeof *cls);
    const double kmat[4] = {1.0, 2.5, 2.5, 0.7};
    pk_rng rng;
    pk_rng_seed(&rng, 9, 0);
    for (size_t i = 0; i < n; i++) {
        pk_m3_vec(F, &p.x[3 * i], &x[3 * i]);
        mask[i] = i % 5 != 0; /* held grains: both one-sided block branches */
        cls[i] = (int32_t)(i % 2);
        for (int a = 0; a < 3; a++)
            v[3 * i + a] = a < dim ? pk_rng_range(&rng, -1, 1) : 0;
    }
    pk_dem_pairs c = {0};
    if (classes)
        pk_dem_pairs_stiffness(&c, cls, kmat, 2, 1.0);
    CHECK(pk_dem_pairs_build(&c, &g, x, p.r, n, 0.3) == 0);
    size_t nc = pk_dem_eval(&c, &g, x, p.r, n, 1.3, NULL, NULL, NULL);
    size_t touching = 0; /* contacts with a grain in the mask */
    for (size_t q = 0; q < c.n; q++)
        touching += c.eps[q] >= 0 && c.len[q] > 0 && (mask[c.i[q]] || mask[c.j[q]]);
    pk_dem_kblocks kb = {0};
    CHECK(pk_dem_kblocks_build(&kb, &c, 1.3, mask) == 0);
    CHECK_MSG(kb.n == touching && nc > n && touching < nc, "%zu blocks, %zu touching, %zu contacts",
              kb.n, touching, nc);
    pk_dem_kv(&c, dim, n, 1.3, mask, v, k1);
    pk_dem_kblocks_kv(&kb, dim, n, v, k2);
    size_t bad = 0, held_nonzero = 0;
    for (size_t i = 0; i < n; i++)
        for (int a = 0; a < dim; a++) {
            bad += k1[3 * i + a] != k2[3 * i + a];
            held_nonzero += !mask[i] && k2[3 * i + a] != 0;
        }
    CHECK_MSG(bad == 0, "dim %d classes %d: %zu entries differ", dim, classes, bad);
    CHECK(held_nonzero == 0);
    pk_dem_kblocks_free(&kb);
    pk_dem_pairs_free(&c);
    pk_particles_free(&p);
    free(x), free(v), free(k1), free(k2), free(mask), free(cls);
}

static void test_kblocks_equal_kv_2d(void)
{
    check_kv_equal(2, 150, 0.88, 0);
    check_kv_equal(2, 150, 0.88, 1);
}

static void test_kblocks_equal_kv_3d(void) { check_kv_equal(3, 120, 0.70, 0); }

int main(void)
{
    RUN(test_kblocks_equal_kv_2d);
    RUN(test_kblocks_equal_kv_3d);
    return check_summary();
}
