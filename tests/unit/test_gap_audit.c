/* test_gap_audit.c — core/space/gap_audit against brute force over all pairs.
 *
 * The audit is what a result file's smallest_gap and pairs_below_delta_d
 * come from, so it is checked here against the plainest possible code (every
 * pair, minimum image): random grains with radii over three decades (its
 * levels), some pairs overlapping, some exactly at the required gap, in 2D
 * and 3D boxes that are periodic, walled or mixed — including periodic boxes
 * narrower than twice the reach (a grain meets another's images), a sparse
 * pair far apart (the horizon has to grow) and N = 0 and 1.  The audit must
 * give the same smallest gap (the same floating-point value: the same
 * expression of the same pair), the same counts and the same wall figures. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>

#include "check.h"
#include "core/space/gap_audit.h"
#include "core/space/particles.h"
#include "core/base/rng.h"

static double brute_gap(const pk_box *b, const pk_particles *p, size_t i, size_t j)
{
    double d2 = 0;
    for (int k = 0; k < b->dim; k++) {
        double d = p->x[3 * j + k] - p->x[3 * i + k];
        if (b->periodic[k])
            d -= b->L[k] * nearbyint(d / b->L[k]);
        d2 += d * d;
    }
    return sqrt(d2) - (p->r[i] + p->r[j]);
}

static void brute(const pk_box *b, const pk_particles *p, double required, double tol,
                  double horizon, pk_gap_report *rep)
{
    *rep = (pk_gap_report){
        .min_gap = horizon, .min_pair = {SIZE_MAX, SIZE_MAX}, .min_wall_gap = INFINITY};
    for (size_t i = 0; i < p->n; i++) {
        for (int k = 0; k < b->dim; k++) {
            if (b->periodic[k])
                continue;
            double c = fmin(p->x[3 * i + k], b->L[k] - p->x[3 * i + k]) - p->r[i];
            rep->min_wall_gap = fmin(rep->min_wall_gap, c);
            rep->walls_below += c < 0.5 * required - tol;
        }
        for (size_t j = i + 1; j < p->n; j++) {
            /* the audit's expression is symmetric in i and j to the bit (d only
             * changes sign, the radii are added before they are subtracted) */
            double g = brute_gap(b, p, i, j);
            if (g >= horizon)
                continue;
            if (g < rep->min_gap)
                rep->min_gap = g;
            rep->pairs_below += g < required - tol;
        }
    }
}

/* n grains, radii log-uniform in [rmin, rmax], centres uniform in the box;
 * every 7th grain is moved next to the one before it at gap `required`
 * (or overlapping it by a tenth of its radius, every 21st). */
static void scatter(const pk_box *b, size_t n, double rmin, double rmax, double required,
                    uint64_t seed, pk_particles *p)
{
    pk_particles_init(p, b->dim, n);
    pk_rng g;
    pk_rng_seed(&g, seed, 0);
    for (size_t i = 0; i < n; i++) {
        double x[3] = {0, 0, 0};
        double r = rmin * pow(rmax / rmin, pk_rng_uniform(&g));
        for (int k = 0; k < b->dim; k++)
            x[k] = b->L[k] * pk_rng_uniform(&g);
        if (i > 0 && i % 7 == 0) {
            const double *y = &p->x[3 * (i - 1)];
            double d = p->r[i - 1] + r + (i % 21 == 0 ? -0.1 * r : required);
            x[0] = y[0] + d; /* along x: past the box on a walled axis is fine */
            for (int k = 1; k < b->dim; k++)
                x[k] = y[k];
        }
        pk_particles_push(p, x, r, 0);
    }
}

static void same(const pk_box *b, const pk_particles *p, double required, double horizon,
                 const char *name)
{
    const double tol = 1e-12;
    pk_gap_report a, e;
    CHECK(pk_gap_audit(b, p, required, tol, horizon, &a) == 0);
    brute(b, p, required, tol, horizon, &e);
    CHECK_MSG(a.min_gap == e.min_gap, "%s: smallest gap %.17g, brute force %.17g", name, a.min_gap,
              e.min_gap);
    CHECK_MSG(a.pairs_below == e.pairs_below, "%s: %zu pairs below, brute force %zu", name,
              a.pairs_below, e.pairs_below);
    CHECK_MSG(a.walls_below == e.walls_below && a.min_wall_gap == e.min_wall_gap,
              "%s: walls %zu / %g, brute force %zu / %g", name, a.walls_below, a.min_wall_gap,
              e.walls_below, e.min_wall_gap);
    if (a.min_pair[0] != SIZE_MAX)
        CHECK_MSG(brute_gap(b, p, a.min_pair[0], a.min_pair[1]) == a.min_gap,
                  "%s: the reported pair does not have the smallest gap", name);
}

static void test_matches_brute_force(void)
{
    const double required = 0.01;
    for (int dim = 2; dim <= 3; dim++)
        for (int kind = 0; kind < 3; kind++) { /* periodic, walled, periodic in x only */
            pk_box b = {.dim = dim, .L = {6, 5, dim == 3 ? 4 : 0}};
            for (int k = 0; k < dim; k++)
                b.periodic[k] = kind == 0 || (kind == 2 && k == 0);
            for (int poly = 0; poly < 2; poly++) {
                pk_particles p;
                double rmax = 0.2, rmin = poly ? 2e-4 : 0.2;
                scatter(&b, dim == 3 ? 1500 : 800, rmin, rmax, required,
                        (uint64_t)(100 * dim + 10 * kind + poly), &p);
                char name[64];
                snprintf(name, sizeof name, "dim %d, box kind %d, %s", dim, kind,
                         poly ? "radii 1:1000" : "equal radii");
                same(&b, &p, required, fmax(required, rmax), name);
                same(&b, &p, 0, rmax, name); /* Δd = 0 */
                pk_particles_free(&p);
            }
        }
}

/* Enough cells that the audit's sort of grains by cell takes two passes
 * (10 000 grains: about 40 000 cells, keys of 16 bits). */
static void test_many_cells(void)
{
    for (int periodic = 0; periodic < 2; periodic++) {
        pk_box b = {.dim = 3, .L = {9, 10, 11}, .periodic = {periodic, periodic, periodic}};
        pk_particles p;
        scatter(&b, 10000, 0.04, 0.06, 0.002, 55 + (uint64_t)periodic, &p);
        same(&b, &p, 0.002, 0.06, periodic ? "many cells, periodic" : "many cells, walled");
        pk_particles_free(&p);
    }
}

static void test_narrow_and_sparse(void)
{
    /* periodic box narrower than twice the reach: a grain meets several images */
    for (int dim = 2; dim <= 3; dim++) {
        pk_box b = {
            .dim = dim, .L = {1.1, 0.9, dim == 3 ? 1.0 : 0}, .periodic = {true, true, true}};
        pk_particles p;
        scatter(&b, 12, 0.05, 0.3, 0.02, 7 + (uint64_t)dim, &p);
        same(&b, &p, 0.02, 0.3, dim == 2 ? "narrow 2D" : "narrow 3D");
        pk_particles_free(&p);
    }
    /* two small grains far apart: no pair within the first horizons */
    pk_box b = {.dim = 3, .L = {100, 100, 100}};
    pk_particles p;
    pk_particles_init(&p, 3, 2);
    pk_particles_push(&p, (double[3]){10, 10, 10}, 0.01, 0);
    pk_particles_push(&p, (double[3]){12, 10, 10}, 0.01, 0);
    same(&b, &p, 0, 5, "sparse, gap 1.98 < horizon 5");
    same(&b, &p, 0, 1, "sparse, gap beyond the horizon");
    pk_particles_free(&p);
    /* N = 0 and 1 */
    pk_particles_init(&p, 3, 1);
    same(&b, &p, 0.1, 1, "no grain");
    pk_particles_push(&p, (double[3]){0.05, 50, 50}, 0.1, 0); /* crossing the wall at x = 0 */
    same(&b, &p, 0.1, 1, "one grain");
    pk_particles_free(&p);
}

int main(void)
{
    RUN(test_matches_brute_force);
    RUN(test_many_cells);
    RUN(test_narrow_and_sparse);
    return check_summary();
}
