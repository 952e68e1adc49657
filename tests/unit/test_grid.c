/* test_grid.c — core/space/grid's queries against brute force over all grains.
 *
 * Under pk_grid_init_dense a level keeps one head per cell when it has few
 * cells per grain and hashed buckets otherwise (grid.h); both must answer as the plainest code does:
 * every registered grain within r + r_j + gap + extra of the point (minimum
 * image) visited exactly once, and pk_grid_overlaps true exactly when one is
 * closer than contact.  Checked in 2D and 3D, walled, periodic and mixed
 * boxes, radii over two decades (four levels), after inserts, moves and
 * removes, with a capacity that makes the finest level dense and one that
 * leaves it hashed. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "core/base/rng.h"
#include "core/space/grid.h"
#include "core/space/particles.h"

typedef struct seen {
    int *count; /* visits per grain */
    int bad;    /* a visit whose distance disagrees with the grain's */
    const pk_particles *p;
    const double *x;
} seen;

static double min_image_d2(const pk_box *b, const double *a, const double *c)
{
    double d2 = 0;
    for (int k = 0; k < b->dim; k++) {
        double d = c[k] - a[k];
        if (b->periodic[k])
            d -= b->L[k] * nearbyint(d / b->L[k]);
        d2 += d * d;
    }
    return d2;
}

static int visit(size_t j, const double dx[PK_MAXDIM], double dist2, void *ctx)
{
    seen *s = ctx;
    s->count[j]++;
    double d2 = dx[0] * dx[0] + dx[1] * dx[1] + dx[2] * dx[2];
    if (fabs(d2 - dist2) > 1e-9 * (1 + dist2))
        s->bad = 1;
    return 0;
}

/* n grains in box b, a grid with capacity cap; queries at random points
 * after inserts, after moving a third and removing a sixth.  want_dense:
 * the finest level must be dense (1) or hashed (0). */
static void run_case(const pk_box *b, size_t n, size_t cap, int want_dense, uint64_t seed)
{
    const double r_min = 0.0099, r_max = 0.08, gap = 0.005, extra = 0.02;
    pk_particles p;
    CHECK(pk_particles_init(&p, b->dim, n) == 0);
    pk_rng g;
    pk_rng_seed(&g, seed, 1);
    for (size_t i = 0; i < n; i++) {
        double x[PK_MAXDIM] = {0, 0, 0};
        for (int k = 0; k < b->dim; k++)
            x[k] = b->L[k] * pk_rng_uniform(&g);
        double r = r_min * pow(r_max / r_min, pk_rng_uniform(&g));
        pk_particles_push(&p, x, r, 0);
    }
    pk_grid grid;
    CHECK(pk_grid_init_dense(&grid, b, r_min, r_max, gap, cap) == 0);
    CHECK(grid.nlevel == 4);
    CHECK_MSG(grid.lv[grid.nlevel - 1].dense == want_dense, "finest level dense %d, want %d",
              grid.lv[grid.nlevel - 1].dense, want_dense);
    for (size_t i = 0; i < n; i++)
        CHECK(pk_grid_insert(&grid, &p, i) == 0);
    char *in = malloc(n);
    memset(in, 1, n);
    int *count = calloc(n, sizeof *count);
    int mismatches = 0, overlaps_wrong = 0, hits = 0;
    for (int round = 0; round < 2; round++) {
        if (round == 1) {
            for (size_t i = 0; i < n; i += 3) {
                for (int k = 0; k < b->dim; k++)
                    p.x[3 * i + k] = b->L[k] * pk_rng_uniform(&g);
                CHECK(pk_grid_update(&grid, &p, i) == 0);
            }
            for (size_t i = 1; i < n; i += 6) {
                pk_grid_remove(&grid, i);
                in[i] = 0;
            }
        }
        for (int q = 0; q < 400; q++) {
            double x[PK_MAXDIM] = {0, 0, 0};
            for (int k = 0; k < b->dim; k++)
                x[k] = b->L[k] * pk_rng_uniform(&g);
            double r = r_min * pow(r_max / r_min, pk_rng_uniform(&g));
            memset(count, 0, n * sizeof *count);
            seen s = {.count = count, .p = &p, .x = x};
            pk_grid_query(&grid, &p, x, r, extra, visit, &s);
            int overlap = 0;
            for (size_t j = 0; j < n; j++) {
                double d2 = min_image_d2(b, x, &p.x[3 * j]);
                double reach = r + p.r[j] + gap + extra, contact = r + p.r[j] + gap;
                int want = in[j] && d2 < reach * reach;
                if (count[j] != want)
                    mismatches++;
                hits += want;
                overlap |= in[j] && d2 < contact * contact;
            }
            CHECK(!s.bad);
            if (pk_grid_overlaps(&grid, &p, x, r) != overlap)
                overlaps_wrong++;
        }
    }
    CHECK_MSG(mismatches == 0, "%d visits differ from brute force", mismatches);
    CHECK_MSG(overlaps_wrong == 0, "%d overlap answers differ", overlaps_wrong);
    CHECK(hits > 100); /* the queries found grains: the check bites */
    free(in);
    free(count);
    pk_grid_free(&grid);
    pk_particles_free(&p);
}

static const pk_box boxes[] = {
    {.dim = 3, .L = {1, 1, 1}, .periodic = {false, false, false}},
    {.dim = 3, .L = {1, 0.8, 1.2}, .periodic = {true, true, true}},
    {.dim = 3, .L = {1.1, 1, 0.9}, .periodic = {true, false, true}},
    {.dim = 2, .L = {2, 1.5, 0}, .periodic = {false, false, false}},
    {.dim = 2, .L = {1.5, 2, 0}, .periodic = {true, false, false}},
};

/* a capacity large enough for one head per cell of the finest level (its
 * ≤ 64 000 cells against 4 per grain of 20 000) */
static void test_dense_levels(void)
{
    for (size_t c = 0; c < sizeof boxes / sizeof *boxes; c++)
        run_case(&boxes[c], 1500, 20000, 1, 11 + c);
}

/* a 3D box 4× wider: the finest level's 8·10⁶ cells exceed the dense budget
 * of a 6000-grain grid, so it hashes */
static void test_hashed_levels(void)
{
    const pk_box wide = {.dim = 3, .L = {4, 4, 4}, .periodic = {true, false, false}};
    run_case(&wide, 6000, 6000, 0, 7);
}

int main(void)
{
    RUN(test_dense_levels);
    RUN(test_hashed_levels);
    return check_summary();
}
