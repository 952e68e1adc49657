/* test_rsa_cover.c — core/rsa/rsa_cover against brute force.
 *
 * The cover must answer for the grains it lists (r_j > r_q) exactly as the
 * plainest code does: some listed j with |x − x_j| < r + r_j + Δd (minimum
 * image), for every query radius r <= r_q and point x in the box — including
 * points near the walls, near a periodic seam and queries at r = r_q, and
 * pairs at nearly the contact distance.  2D and 3D, walled, periodic and
 * mixed boxes, radii over a factor 30. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>

#include "check.h"
#include "core/base/rng.h"
#include "core/rsa/rsa_cover.h"
#include "core/space/particles.h"

static int brute(const pk_box *b, const pk_particles *p, double r_q, double gap, const double *x,
                 double r)
{
    for (size_t j = 0; j < p->n; j++) {
        if (!(p->r[j] > r_q))
            continue;
        double d2 = 0;
        for (int k = 0; k < b->dim; k++) {
            double d = p->x[3 * j + k] - x[k];
            if (b->periodic[k] && fabs(d) > 0.5 * b->L[k])
                d -= b->L[k] * nearbyint(d / b->L[k]);
            d2 += d * d;
        }
        double s = r + p->r[j] + gap;
        if (d2 < s * s)
            return 1;
    }
    return 0;
}

static void run_case(const pk_box *b, uint64_t seed)
{
    const double r_min = 0.004, r_max = 0.12, r_q = 0.016, gap = 0.01;
    pk_particles p;
    CHECK(pk_particles_init(&p, b->dim, 600) == 0);
    pk_rng g;
    pk_rng_seed(&g, seed, 1);
    for (size_t i = 0; i < 600; i++) {
        double x[PK_MAXDIM] = {0, 0, 0};
        for (int k = 0; k < b->dim; k++)
            x[k] = b->L[k] * pk_rng_uniform(&g);
        pk_particles_push(&p, x, r_min * pow(r_max / r_min, pk_rng_uniform(&g)), 0);
    }
    pk_rsa_cover c;
    CHECK(pk_rsa_cover_init(&c, b, r_q, gap) == 0);
    for (size_t j = 0; j < p.n; j++)
        CHECK(pk_rsa_cover_add(&c, &p, j) == 0);
    CHECK(c.entries > 0);
    int wrong = 0, hits = 0, misses = 0;
    for (int q = 0; q < 100000; q++) {
        double x[PK_MAXDIM] = {0, 0, 0}, r = q % 5 == 0 ? r_q : r_q * pk_rng_uniform(&g);
        if (q % 3 == 0) {
            /* at a grain's contact distance for the largest query: its
             * ball's edge, where a cell left out would show */
            r = r_q;
            size_t j = (size_t)(pk_rng_uniform(&g) * (double)p.n);
            double s = r + p.r[j] + gap, u[PK_MAXDIM] = {0, 0, 0}, n2 = 0;
            for (int k = 0; k < b->dim; k++) {
                u[k] = pk_rng_uniform(&g) - 0.5;
                n2 += u[k] * u[k];
            }
            double f = s * (1 + 1e-9 * (pk_rng_uniform(&g) - 0.5)) / sqrt(n2);
            for (int k = 0; k < b->dim; k++)
                x[k] = p.x[3 * j + k] + f * u[k];
        } else {
            for (int k = 0; k < b->dim; k++)
                x[k] = b->L[k] * pk_rng_uniform(&g);
        }
        int inside = 1;
        for (int k = 0; k < b->dim; k++) {
            if (b->periodic[k])
                x[k] -= b->L[k] * floor(x[k] / b->L[k]);
            else if (x[k] < 0 || x[k] > b->L[k])
                inside = 0;
        }
        if (!inside)
            continue;
        int want = brute(b, &p, r_q, gap, x, r);
        if (pk_rsa_cover_hits(&c, &p, x, r) != want)
            wrong++;
        hits += want;
        misses += !want;
    }
    CHECK_MSG(wrong == 0, "%d answers differ from brute force", wrong);
    CHECK(hits > 1000 && misses > 1000); /* both answers were asked */
    pk_rsa_cover_free(&c);
    pk_particles_free(&p);
}

static void test_against_brute_force(void)
{
    const pk_box boxes[] = {
        {.dim = 3, .L = {1, 1, 1}, .periodic = {false, false, false}},
        {.dim = 3, .L = {1, 0.8, 1.2}, .periodic = {true, true, true}},
        {.dim = 3, .L = {1.1, 1, 0.9}, .periodic = {true, false, true}},
        {.dim = 2, .L = {2, 1.5, 0}, .periodic = {false, false, false}},
        {.dim = 2, .L = {1.5, 2, 0}, .periodic = {true, false, false}},
        /* a periodic axis only a few cells wide: the balls wrap onto
         * themselves */
        {.dim = 3, .L = {0.6, 1, 1}, .periodic = {true, false, false}},
    };
    for (size_t c = 0; c < sizeof boxes / sizeof *boxes; c++)
        run_case(&boxes[c], 3 + c);
}

/* the budget's count covers every cell a grain is listed in */
static void test_cells_bound(void)
{
    const pk_box b = {.dim = 3, .L = {1, 1, 1}, .periodic = {false, true, false}};
    pk_particles p;
    CHECK(pk_particles_init(&p, 3, 1) == 0);
    const double x[PK_MAXDIM] = {0.3, 0.99, 0.5};
    pk_particles_push(&p, x, 0.1, 0);
    pk_rsa_cover c;
    CHECK(pk_rsa_cover_init(&c, &b, 0.016, 0.01) == 0);
    CHECK(pk_rsa_cover_add(&c, &p, 0) == 0);
    CHECK(c.entries > 0 && (double)c.entries <= pk_rsa_cover_cells_of(&b, 0.016, 0.01, 0.1));
    pk_rsa_cover_free(&c);
    pk_particles_free(&p);
}

int main(void)
{
    RUN(test_against_brute_force);
    RUN(test_cells_bound);
    return check_summary();
}
