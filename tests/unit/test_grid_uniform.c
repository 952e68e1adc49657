/* test_grid_uniform.c — core/space/grid_uniform.h (the dense cell levels under
 * EDMD's neighbour lists) against a brute-force pair scan: every query must
 * report exactly the grains within r + r_j by the minimum image, once. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "grid_fixture.h"
#include "core/space/grid_uniform.h"
#include "core/base/rng.h"

typedef struct hits {
    int *seen; /* times each grain was reported */
} hits;

static int count_hit(size_t j, const double dx[PK_MAXDIM], double dist2, void *ctx)
{
    (void)dx;
    (void)dist2;
    ((hits *)ctx)->seen[j]++;
    return 0;
}

/* n grains, radii log-uniform over [rmin, rmax] (several levels when the
 * ratio exceeds 2), random positions (wrapped); then moves and re-files
 * a third of them with new radii (growth beyond the init range included,
 * as EDMD does) and checks every query against the brute force. */
static void compare(int dim, const bool periodic[3], size_t n, double rmin, double rmax,
                    uint64_t seed)
{
    pk_box b;
    memset(&b, 0, sizeof b);
    b.dim = dim;
    for (int k = 0; k < dim; k++) {
        b.L[k] = 10.0 + 3 * k;
        b.periodic[k] = periodic[k];
    }
    pk_particles p;
    pk_particles_init(&p, dim, n);
    pk_rng rng;
    pk_rng_seed(&rng, seed, 9);
    for (size_t i = 0; i < n; i++) {
        double x[3] = {0, 0, 0};
        for (int k = 0; k < dim; k++)
            x[k] = pk_rng_range(&rng, 0, b.L[k]);
        double r = rmin * pow(rmax / rmin, pk_rng_range(&rng, 0, 1));
        pk_particles_push(&p, x, r, 0);
    }
    pk_ugrid g;
    CHECK(pk_ugrid_init(&g, &b, p.r, n, n) == 0);
    for (size_t i = 0; i < n; i++)
        CHECK(pk_ugrid_insert(&g, &p, i) == 0);
    for (size_t i = 0; i < n; i += 3) { /* move, grow (up to 1.5 rmax) and re-file */
        for (int k = 0; k < dim; k++)
            p.x[3 * i + k] = pk_rng_range(&rng, 0, b.L[k]);
        p.r[i] *= pk_rng_range(&rng, 0.5, 1.5);
        CHECK(pk_ugrid_insert(&g, &p, i) == 0);
    }
    int *seen = calloc(n, sizeof *seen);
    size_t wrong = 0, total = 0;
    for (size_t i = 0; i < n; i++) {
        memset(seen, 0, n * sizeof *seen);
        hits h = {seen};
        pk_ugrid_query(&g, &p, &p.x[3 * i], p.r[i], count_hit, &h);
        for (size_t j = 0; j < n; j++) {
            double d2 = pk_box_dist2(&b, &p.x[3 * i], &p.x[3 * j]);
            double s = p.r[i] + p.r[j];
            /* pairs within 1e-12 relative of contact may go either way */
            if (fabs(sqrt(d2) - s) < 1e-12 * s)
                continue;
            int want = d2 < s * s;
            total += want;
            if (seen[j] != want)
                wrong++;
        }
    }
    CHECK_MSG(wrong == 0, "dim %d: %zu of %zu pairs wrong", dim, wrong, total);
    CHECK(total > n); /* the case has pairs (mean radius ~ cell size) */
    /* remove: a removed grain is never reported */
    pk_ugrid_remove(&g, 0);
    memset(seen, 0, n * sizeof *seen);
    hits h = {seen};
    pk_ugrid_query(&g, &p, &p.x[0], 2 * rmax, count_hit, &h);
    CHECK(seen[0] == 0);
    free(seen);
    pk_ugrid_free(&g);
    pk_particles_free(&p);
}

static void test_periodic_3d_one_size(void)
{
    bool per[3] = {true, true, true};
    compare(3, per, 600, 0.6, 0.6, 1);
}

static void test_periodic_3d_ratio_16(void)
{
    bool per[3] = {true, true, true};
    compare(3, per, 600, 0.1, 1.6, 2);
}

static void test_mixed_walls_3d(void)
{
    bool per[3] = {true, false, true};
    compare(3, per, 500, 0.2, 1.2, 3);
}

static void test_2d_walled_and_periodic(void)
{
    bool walled[3] = {false, false, false}, per[3] = {true, true, false};
    compare(2, walled, 400, 0.1, 1.0, 4);
    compare(2, per, 400, 0.1, 1.0, 5);
}

/* Grains as big as the box: whole periodic axes are scanned once each. */
static void test_reach_beyond_box(void)
{
    bool per[3] = {true, true, true};
    compare(3, per, 60, 1.0, 4.0, 6);
}

/* Many fines and few coarse grains (counts ∝ d^-2.5 over 1:16, as the
 * Fuller-like EDMD case): the coarse levels are covered (grid_uniform.h), and
 * the fines' queries read the cover; periodic, walled and 2D; grains moved,
 * resized, removed, and one grown to 0.4 L.  (Caught by mutation: cover
 * balls r_j + cov_r/2, slab distances one cell too far, removes that leave
 * the grain listed.) */
static size_t cover_case(int dim, const bool periodic[3], uint64_t seed)
{
    size_t big = 0;
    pk_box b;
    pk_particles p;
    pk_rng rng;
    fuller_scene(dim, periodic, seed, &b, &p, &rng);
    const size_t n = p.n;
    pk_ugrid g;
    CHECK(pk_ugrid_init(&g, &b, p.r, n, n) == 0);
    CHECK(g.cov_r > 0 && g.covered[0]); /* the fines' level is the busiest: coarser ones covered */
    for (size_t i = 0; i < n; i++)
        CHECK(pk_ugrid_insert(&g, &p, i) == 0);
    for (int round = 0; round < 3; round++) {
        for (size_t i = (size_t)round; i < n; i += 4) { /* move, resize, re-file */
            for (int k = 0; k < dim; k++)
                p.x[3 * i + k] = pk_rng_range(&rng, 0, b.L[k]);
            p.r[i] *= pk_rng_range(&rng, 0.6, 1.5);
            CHECK(pk_ugrid_insert(&g, &p, i) == 0);
        }
        if (round == 1)
            pk_ugrid_remove(&g, 1);
        if (round == 2) { /* grown far past the cover's balls: tested by every cover query */
            p.r[2] = 0.4 * b.L[0];
            CHECK(pk_ugrid_insert(&g, &p, 2) == 0);
            big = g.cov_big.n; /* 1 when its ball would span too many cells */
            CHECK(big <= 1);
        }
        int *seen = calloc(n, sizeof *seen);
        size_t wrong = 0, total = 0, covered_queries = 0;
        for (size_t i = 0; i < n; i++) {
            memset(seen, 0, n * sizeof *seen);
            hits h = {seen};
            pk_ugrid_query(&g, &p, &p.x[3 * i], p.r[i], count_hit, &h);
            covered_queries += p.r[i] <= g.cov_r;
            for (size_t j = 0; j < n; j++) {
                double d2 = pk_box_dist2(&b, &p.x[3 * i], &p.x[3 * j]);
                double s = p.r[i] + p.r[j];
                if (fabs(sqrt(d2) - s) < 1e-12 * s) /* as compare() */
                    continue;
                int want = d2 < s * s && !(round >= 1 && j == 1);
                total += want;
                if (seen[j] != want)
                    wrong++;
            }
        }
        CHECK_MSG(wrong == 0, "dim %d round %d: %zu of %zu pairs wrong", dim, round, wrong, total);
        CHECK_MSG(covered_queries > n / 3, "%zu of %zu queries read the cover", covered_queries, n);
        CHECK(total > n);
        free(seen);
    }
    pk_ugrid_free(&g);
    pk_particles_free(&p);
    return big;
}

static void test_cover_of_coarse_levels(void)
{
    bool per[3] = {true, true, true}, mixed[3] = {true, false, true},
         walled[3] = {false, false, false};
    size_t big = cover_case(3, per, 11);
    big += cover_case(3, mixed, 12);
    big += cover_case(2, per, 13);
    big += cover_case(2, walled, 14);
    CHECK(big >= 1); /* the grown grain went to cov_big at least once */
}

static void test_min_image3(void)
{
    const double L[3] = {10, 0, 4}, inv_L[3] = {0.1, 0, 0.25};
    double d[3] = {6, 7.5, -2.5};
    pk_min_image3(L, inv_L, d);
    CHECK_NEAR(d[0], -4, 1e-15);
    CHECK_NEAR(d[1], 7.5, 0); /* walled axis untouched */
    CHECK_NEAR(d[2], 1.5, 1e-15);
    double e[3] = {-14, 0, 9};
    pk_min_image3(L, inv_L, e);
    CHECK_NEAR(e[0], -4, 1e-15);
    CHECK_NEAR(e[2], 1, 1e-15);
}

int main(void)
{
    RUN(test_periodic_3d_one_size);
    RUN(test_periodic_3d_ratio_16);
    RUN(test_mixed_walls_3d);
    RUN(test_2d_walled_and_periodic);
    RUN(test_reach_beyond_box);
    RUN(test_cover_of_coarse_levels);
    RUN(test_min_image3);
    return check_summary();
}
