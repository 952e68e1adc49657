/* test_dem_rattlers.c — pk_dem_rattlers (which re-tests only the grains
 * whose neighbourhood changed) finds exactly the rattler set of the plain
 * Table 4.3 sweep (every free grain tested, sweeps until no new rattler),
 * on random 2D and 3D packings sparse enough for long rattler cascades,
 * with some grains held.  The reference sweep is written out here from
 * pk_dem_positively_spanning alone. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "check.h"
#include "core/dem/dem_contact.h"
#include "core/dem/dem_rattler.h"
#include "core/base/rng.h"

/* The plain sweep; returns the count, *sweeps the number of sweeps that
 * found a new rattler. */
static size_t reference_rattlers(const pk_dem_pairs *c, int dim, size_t np, const uint8_t *is_free,
                                 uint8_t *rat, int *sweeps)
{
    memset(rat, 0, np);
    double *dirs = malloc(3 * c->n * sizeof *dirs + 24);
    size_t count = 0;
    int repeat = 1;
    *sweeps = 0;
    while (repeat) {
        repeat = 0;
        for (size_t i = 0; i < np; i++) {
            if (!is_free[i] || rat[i])
                continue;
            size_t m = 0;
            for (size_t p = 0; p < c->n; p++) { /* every contact of i with a non-rattler */
                if (!(c->eps[p] >= 0) || !(c->len[p] > 0))
                    continue;
                size_t a = (size_t)c->i[p], b = (size_t)c->j[p];
                if ((a != i && b != i) || rat[a == i ? b : a])
                    continue;
                double s = a == i ? 1.0 : -1.0;
                for (int k = 0; k < 3; k++)
                    dirs[3 * m + k] = k < dim ? s * c->l[3 * p + k] / c->len[p] : 0;
                m++;
            }
            if (!pk_dem_positively_spanning(dirs, m, dim, 1e-9)) {
                rat[i] = 1;
                count++;
                repeat = 1;
            }
        }
        *sweeps += repeat;
    }
    free(dirs);
    return count;
}

static void same_set(int dim)
{
    const size_t np = dim == 2 ? 1500 : 1200;
    const double L = dim == 2 ? 33 : 10.5;
    pk_rng rng;
    pk_rng_seed(&rng, 31, (uint64_t)dim);
    double *x = calloc(3 * np, sizeof *x), *r = malloc(np * sizeof *r);
    uint8_t *is_free = malloc(np), *rat = malloc(np), *ref = malloc(np);
    for (size_t i = 0; i < np; i++) {
        for (int k = 0; k < dim; k++)
            x[3 * i + k] = pk_rng_range(&rng, 0, L);
        r[i] = pk_rng_range(&rng, 0.5, 1.0);
        is_free[i] = i % 17 != 0; /* some held grains (they count as jammed neighbours) */
    }
    pk_dem_geom g = {.dim = dim, .periodic = 1, .L = {L, L, dim == 3 ? L : 0}};
    const double I[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    pk_dem_geom_set_F(&g, I);
    pk_dem_pairs c = {0};
    CHECK(pk_dem_pairs_build(&c, &g, x, r, np, 0.1) == 0);
    size_t nc = pk_dem_eval(&c, &g, x, r, np, 1.0, NULL, NULL, NULL);
    int sweeps;
    clock_t t0 = clock();
    size_t nref = reference_rattlers(&c, dim, np, is_free, ref, &sweeps);
    clock_t t1 = clock();
    size_t n = pk_dem_rattlers(&c, dim, np, is_free, rat);
    clock_t t2 = clock();
    printf("  dim %d: %zu grains, %zu contacts, %zu rattlers in %d productive sweeps "
           "(reference %.2f ms, pk_dem_rattlers %.2f ms)\n",
           dim, np, nc, n, sweeps, 1e3 * (double)(t1 - t0) / CLOCKS_PER_SEC,
           1e3 * (double)(t2 - t1) / CLOCKS_PER_SEC);
    CHECK(n == nref);
    CHECK(memcmp(rat, ref, np) == 0);
    /* not vacuous: rattlers and jammed grains both, and cascades */
    CHECK(nref > np / 20 && nref < np - np / 20);
    CHECK(sweeps >= 3);
    pk_dem_pairs_free(&c);
    free(x), free(r), free(is_free), free(rat), free(ref);
}

static void test_same_set_2d(void) { same_set(2); }
static void test_same_set_3d(void) { same_set(3); }

int main(void)
{
    RUN(test_same_set_2d);
    RUN(test_same_set_3d);
    return check_summary();
}
