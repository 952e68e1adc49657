/* test_cover_move — re-filing a grain in its covered level moves its cover
 * entries (pk_ugrid_cover_move: only the cells of one ball and not the
 * other change).  After many small moves and resizes (EDMD list rebuilds:
 * a fraction of a cell each, across periodic seams and walls), every cover
 * cell must hold exactly the grains a fresh grid filed at the final
 * positions holds (as sets: the order within a cell may differ), each
 * once; grains leaving for and coming back from the unbounded list
 * (cov_big) go through remove + add. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "grid_fixture.h"
#include "core/space/grid_uniform.h"
#include "core/base/rng.h"

static int cmp_i32(const void *a, const void *b)
{
    const int32_t x = *(const int32_t *)a, y = *(const int32_t *)b;
    return (x > y) - (x < y);
}

/* Cells whose sorted id lists differ, plus ids listed twice in one cell. */
static size_t cover_diff(const pk_ugrid *a, const pk_ugrid *b)
{
    const pk_ugrid_level *lv = &a->lv[a->cov_level];
    const size_t ncell = (size_t)lv->n[0] * (size_t)lv->n[1] * (size_t)lv->n[2];
    size_t bad = 0;
    for (size_t c = 0; c < ncell; c++) {
        const pk_ugrid_cover *x = &a->cov[c], *y = &b->cov[c];
        if (x->n != y->n) {
            bad++;
            continue;
        }
        if (x->n == 0)
            continue;
        int32_t *u = malloc(x->n * sizeof *u), *v = malloc(x->n * sizeof *v);
        memcpy(u, x->ids, x->n * sizeof *u);
        memcpy(v, y->ids, y->n * sizeof *v);
        qsort(u, x->n, sizeof *u, cmp_i32);
        qsort(v, y->n, sizeof *v, cmp_i32);
        for (uint32_t q = 0; q < x->n; q++)
            if (u[q] != v[q] || (q > 0 && u[q] == u[q - 1])) {
                bad++;
                break;
            }
        free(u);
        free(v);
    }
    bad += a->cov_big.n != b->cov_big.n;
    return bad;
}

static size_t listed(const pk_ugrid *g)
{
    const pk_ugrid_level *lv = &g->lv[g->cov_level];
    const size_t ncell = (size_t)lv->n[0] * (size_t)lv->n[1] * (size_t)lv->n[2];
    size_t s = 0;
    for (size_t c = 0; c < ncell; c++)
        s += g->cov[c].n;
    return s;
}

static size_t move_case(int dim, const bool periodic[3], uint64_t seed)
{
    pk_box b;
    pk_particles p;
    pk_rng rng;
    fuller_scene(dim, periodic, seed, &b, &p, &rng); /* grid_fixture.h */
    const size_t n = p.n;
    pk_ugrid g;
    CHECK(pk_ugrid_init(&g, &b, p.r, n, n) == 0);
    CHECK(g.cov_r > 0 && g.covered[0]);
    for (size_t i = 0; i < n; i++)
        CHECK(pk_ugrid_insert(&g, &p, i) == 0);
    const double r2 = p.r[2];
    size_t big_seen = 0;
    for (int step = 0; step < 40; step++) {
        for (size_t i = 0; i < n; i++) {
            /* a fraction of the coarse cells' edge, and a few % of the radius
             * (mostly the same level, sometimes the next) */
            for (int k = 0; k < dim; k++) {
                double *x = &p.x[3 * i + k];
                *x += pk_rng_range(&rng, -0.8, 0.8);
                if (periodic[k])
                    *x = *x < 0 ? *x + b.L[k] : *x >= b.L[k] ? *x - b.L[k] : *x;
                else
                    *x = fmin(fmax(*x, 0), b.L[k]);
            }
            p.r[i] *= pk_rng_range(&rng, 0.97, 1.03);
        }
        if (step == 10)
            p.r[2] = 0.4 * b.L[0]; /* grown past a bounded ball: cov_big */
        if (step == 20)
            p.r[2] = r2; /* and back */
        for (size_t i = 0; i < n; i++)
            CHECK(pk_ugrid_insert(&g, &p, i) == 0);
        big_seen += g.cov_big.n;
    }
    /* reference: a grid with g's geometry (same init radii), every grain
     * filed once at its final place */
    pk_box b0;
    pk_particles p0;
    pk_rng rng0;
    fuller_scene(dim, periodic, seed, &b0, &p0, &rng0); /* the same scene: its init radii */
    pk_ugrid ref;
    CHECK(pk_ugrid_init(&ref, &b, p0.r, n, n) == 0);
    CHECK(ref.cov_level == g.cov_level && ref.cov_r == g.cov_r);
    for (size_t i = 0; i < n; i++)
        CHECK(pk_ugrid_insert(&ref, &p, i) == 0);
    const size_t bad = cover_diff(&g, &ref);
    CHECK_MSG(bad == 0, "dim %d: %zu cover cells differ from a fresh filing", dim, bad);
    CHECK(listed(&g) > n); /* the coarse grains are listed in many cells */
    pk_ugrid_free(&ref);
    pk_ugrid_free(&g);
    pk_particles_free(&p0);
    pk_particles_free(&p);
    return big_seen;
}

static void test_moves_keep_the_cover_exact(void)
{
    bool per[3] = {true, true, true}, mixed[3] = {true, false, true};
    bool walled[3] = {false, false, false};
    size_t big = move_case(3, per, 21);
    big += move_case(3, mixed, 22);
    big += move_case(2, per, 23);
    big += move_case(2, walled, 24);
    CHECK(big >= 1); /* the grown grain went through cov_big (where its ball is too wide) */
}

int main(void)
{
    RUN(test_moves_keep_the_cover_exact);
    return check_summary();
}
