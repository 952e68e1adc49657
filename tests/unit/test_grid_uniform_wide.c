/* test_grid_uniform_wide.c — wide queries of core/space/grid_uniform.h (boxes of
 * several cells per axis, as the coarse grains' list rebuilds) against a
 * brute-force scan: every grain within r + r_j of the query point by the
 * minimum image is reported once.  Walled axes hold grains whose centres
 * lie outside the box (EDMD's bounding spheres are centred ahead of a
 * grain: up to a skin beyond a wall), filed in the end cells; query points
 * lie outside too, by less than their radius: the end cells of a walled
 * axis must reach past the wall. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "core/space/grid_uniform.h"
#include "core/base/rng.h"

static int count_hit(size_t j, const double dx[PK_MAXDIM], double dist2, void *ctx)
{
    (void)dx;
    (void)dist2;
    ((int *)ctx)[j]++;
    return 0;
}

/* Squared distance, minimum image on the periodic axes only. */
static double dist2(const pk_box *b, const double *a, const double *c)
{
    double s = 0;
    for (int k = 0; k < b->dim; k++) {
        double d = a[k] - c[k];
        if (b->periodic[k])
            d -= b->L[k] * round(d / b->L[k]);
        s += d * d;
    }
    return s;
}

/* A coordinate in [0, L) on a periodic axis; on a walled one in
 * [-out, L + out), half of the time within 1 + out of a wall. */
static double coord(pk_rng *rng, const pk_box *b, int k, double out)
{
    if (b->periodic[k])
        return pk_rng_range(rng, 0, b->L[k]);
    if (pk_rng_range(rng, 0, 1) < 0.5)
        return pk_rng_range(rng, -out, b->L[k] + out);
    const double u = pk_rng_range(rng, -out, 1);
    return pk_rng_range(rng, 0, 1) < 0.5 ? u : b->L[k] - u;
}

static void wide_case(int dim, const bool periodic[3], uint64_t seed)
{
    pk_box b;
    memset(&b, 0, sizeof b);
    b.dim = dim;
    for (int k = 0; k < dim; k++) {
        b.L[k] = (dim == 3 ? 16.0 : 30.0) + 2 * k;
        b.periodic[k] = periodic[k];
    }
    const size_t n = dim == 3 ? 2500 : 1500;
    pk_particles p;
    pk_particles_init(&p, dim, n);
    pk_rng rng;
    pk_rng_seed(&rng, seed, 9);
    for (size_t i = 0; i < n; i++) { /* radii 0.2 .. 0.4, plus a few of 1.5 */
        double x[3] = {0, 0, 0};
        for (int k = 0; k < dim; k++)
            x[k] = coord(&rng, &b, k, 1.0);
        pk_particles_push(&p, x, i % 50 == 0 ? 1.5 : pk_rng_range(&rng, 0.2, 0.4), 0);
    }
    pk_ugrid g;
    CHECK(pk_ugrid_init(&g, &b, p.r, n, n) == 0);
    for (size_t i = 0; i < n; i++)
        CHECK(pk_ugrid_insert(&g, &p, i) == 0);
    int *seen = calloc(n, sizeof *seen);
    size_t wrong = 0, total = 0;
    for (int qn = 0; qn < 600; qn++) {
        /* up to ~0.3 L (no axis taken whole); outside a wall by less than
         * the radius (as EDMD's ahead centres: the ball reaches into the box) */
        const double r = pk_rng_range(&rng, 0.5, 5.0);
        double x[3] = {0, 0, 0};
        for (int k = 0; k < dim; k++)
            x[k] = coord(&rng, &b, k, fmin(1.5, 0.8 * r));
        memset(seen, 0, n * sizeof *seen);
        pk_ugrid_query(&g, &p, x, r, count_hit, seen);
        for (size_t j = 0; j < n; j++) {
            const double d2 = dist2(&b, x, &p.x[3 * j]), s = r + p.r[j];
            if (fabs(sqrt(d2) - s) < 1e-12 * s) /* at contact to round-off: either way */
                continue;
            const int want = d2 < s * s;
            total += want;
            wrong += seen[j] != want;
        }
    }
    CHECK_MSG(wrong == 0, "dim %d: %zu of %zu pairs wrong", dim, wrong, total);
    CHECK(total > 600 * 20); /* wide queries: tens of grains each */
    free(seen);
    pk_ugrid_free(&g);
    pk_particles_free(&p);
}

static void test_wide_queries(void)
{
    bool per[3] = {true, true, true}, mixed[3] = {false, true, false};
    bool walled[3] = {false, false, false};
    wide_case(3, per, 31);
    wide_case(3, mixed, 32);
    wide_case(3, walled, 33);
    wide_case(2, walled, 34);
    wide_case(2, per, 35);
}

int main(void)
{
    RUN(test_wide_queries);
    return check_summary();
}
