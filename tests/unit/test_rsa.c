/* test_rsa.c — the neighbour grid, RSA and the gap audit, each checked
 * against brute force (all pairs, minimum image), never against themselves. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "core/space/gap_audit.h"
#include "core/space/grid.h"
#include "core/base/rng.h"
#include "core/rsa/rsa.h"

/* Smallest surface gap over all pairs and smallest wall clearance, O(N²). */
static void brute_gaps(const pk_box *b, const pk_particles *p, double *min_gap, double *min_wall)
{
    *min_gap = INFINITY;
    *min_wall = INFINITY;
    for (size_t i = 0; i < p->n; i++) {
        for (int k = 0; k < b->dim; k++)
            if (!b->periodic[k])
                *min_wall =
                    fmin(*min_wall, fmin(p->x[3 * i + k], b->L[k] - p->x[3 * i + k]) - p->r[i]);
        for (size_t j = i + 1; j < p->n; j++) {
            double g = sqrt(pk_box_dist2(b, &p->x[3 * i], &p->x[3 * j])) - p->r[i] - p->r[j];
            *min_gap = fmin(*min_gap, g);
        }
    }
}

/* Diameters with counts ∝ d^-dim between d_lo and d_hi, sorted descending. */
static double *poly_sizes(size_t n, double d_lo, double d_hi, uint64_t seed)
{
    double *d = malloc(n * sizeof *d);
    pk_rng g;
    pk_rng_seed(&g, seed, 7);
    for (size_t i = 0; i < n; i++)
        d[i] = d_lo * pow(d_hi / d_lo, pk_rng_uniform(&g));
    for (size_t i = 1; i < n; i++) { /* insertion sort, descending */
        double v = d[i];
        size_t j = i;
        while (j > 0 && d[j - 1] < v) {
            d[j] = d[j - 1];
            j--;
        }
        d[j] = v;
    }
    return d;
}

static void run_case(int dim, int periodic, double delta_d, size_t n, double d_lo, double d_hi,
                     double L, pk_particles *p, pk_rsa_stats *st)
{
    pk_box b = {.dim = dim, .L = {L, L, dim == 3 ? L : 0}};
    for (int k = 0; k < dim; k++)
        b.periodic[k] = periodic;
    double *d = poly_sizes(n, d_lo, d_hi, 11);
    int32_t *sp = calloc(n, sizeof *sp);
    pk_particles_init(p, dim, n);
    pk_rsa_params prm = {.delta_d = delta_d, .max_failed_draws = 100000, .seed = 5};
    CHECK(pk_rsa_place(&b, d, sp, n, &prm, NULL, p, st) == 0);
    free(d);
    free(sp);
    double gmin, wmin;
    brute_gaps(&b, p, &gmin, &wmin);
    /* Tolerance 1e-12·L: the placer tests in double precision with strict
     * inequality, so a gap can only be short by round-off. */
    CHECK_MSG(gmin >= delta_d - 1e-12 * L, "dim %d periodic %d: min gap %.17g < Δd %g", dim,
              periodic, gmin, delta_d);
    if (!periodic)
        CHECK_MSG(wmin >= 0.5 * delta_d - 1e-12 * L, "min wall gap %.17g < Δd/2", wmin);
    /* the audit agrees with brute force on the smallest gap */
    pk_gap_report rep;
    CHECK(pk_gap_audit(&b, p, delta_d, 1e-12 * L, d_hi + delta_d, &rep) == 0);
    CHECK_NEAR(rep.min_gap, gmin, 1e-12 * L);
    CHECK(rep.pairs_below == 0);
    CHECK(rep.walls_below == 0);
    if (!periodic)
        CHECK_NEAR(rep.min_wall_gap, wmin, 1e-12 * L);
}

static void test_rsa_2d_walled(void)
{
    pk_particles p;
    pk_rsa_stats st;
    run_case(2, 0, 0.05, 1500, 0.2, 2.0, 40, &p, &st);
    CHECK(st.reason == PK_STOP_COMPLETE && st.placed == 1500);
    pk_particles_free(&p);
}

static void test_rsa_2d_periodic(void)
{
    pk_particles p;
    pk_rsa_stats st;
    run_case(2, 1, 0.05, 1500, 0.2, 2.0, 40, &p, &st);
    CHECK(st.reason == PK_STOP_COMPLETE && st.placed == 1500);
    pk_particles_free(&p);
}

static void test_rsa_3d_walled(void)
{
    pk_particles p;
    pk_rsa_stats st;
    run_case(3, 0, 0.1, 2000, 0.5, 4.0, 40, &p, &st);
    CHECK(st.reason == PK_STOP_COMPLETE && st.placed == 2000);
    pk_particles_free(&p);
}

static void test_rsa_3d_periodic(void)
{
    pk_particles p;
    pk_rsa_stats st;
    run_case(3, 1, 0.1, 2000, 0.5, 4.0, 40, &p, &st);
    CHECK(st.reason == PK_STOP_COMPLETE && st.placed == 2000);
    pk_particles_free(&p);
}

/* Mixed axes: periodic in x only. */
static void test_rsa_mixed_axes(void)
{
    pk_box b = {.dim = 3, .L = {20, 20, 20}, .periodic = {true, false, false}};
    size_t n = 1500;
    double *d = poly_sizes(n, 0.4, 2.0, 3);
    int32_t *sp = calloc(n, sizeof *sp);
    pk_particles p;
    pk_particles_init(&p, 3, n);
    pk_rsa_params prm = {.delta_d = 0.2, .max_failed_draws = 100000, .seed = 9};
    pk_rsa_stats st;
    CHECK(pk_rsa_place(&b, d, sp, n, &prm, NULL, &p, &st) == 0);
    double gmin, wmin;
    brute_gaps(&b, &p, &gmin, &wmin);
    CHECK(gmin >= 0.2 - 1e-11);
    CHECK(wmin >= 0.1 - 1e-11);
    free(d);
    free(sp);
    pk_particles_free(&p);
}

/* Size ratio 1:1000 in 2D: a few coarse grains and many fine ones.  A single
 * grid sized by the coarse grains would put ~all fine grains into a handful
 * of cells; the run must finish and be exact. */
static void test_rsa_ratio_1000(void)
{
    pk_box b = {.dim = 2, .L = {100, 100}, .periodic = {true, true}};
    size_t n_big = 4, n_small = 30000, n = n_big + n_small;
    double *d = malloc(n * sizeof *d);
    int32_t *sp = calloc(n, sizeof *sp);
    for (size_t i = 0; i < n; i++) {
        d[i] = i < n_big ? 20.0 : 0.02;
        sp[i] = i < n_big ? 0 : 1;
    }
    pk_particles p;
    pk_particles_init(&p, 2, n);
    pk_rsa_params prm = {.delta_d = 0.001, .max_failed_draws = 100000, .seed = 1};
    pk_rsa_stats st;
    CHECK(pk_rsa_place(&b, d, sp, n, &prm, NULL, &p, &st) == 0);
    CHECK(st.placed == n);
    pk_gap_report rep;
    CHECK(pk_gap_audit(&b, &p, 0.001, 1e-10, 0.01, &rep) == 0);
    CHECK_MSG(rep.pairs_below == 0, "%zu pairs below Δd (min gap %g)", rep.pairs_below,
              rep.min_gap);
    /* cross-check the audit with brute force on the coarse–fine pairs */
    double gmin = INFINITY;
    for (size_t i = 0; i < n_big; i++)
        for (size_t j = 0; j < p.n; j++)
            if (j != i)
                gmin =
                    fmin(gmin, sqrt(pk_box_dist2(&b, &p.x[3 * i], &p.x[3 * j])) - p.r[i] - p.r[j]);
    CHECK(gmin >= 0.001 - 1e-10);
    free(d);
    free(sp);
    pk_particles_free(&p);
}

static void test_rsa_reproducible(void)
{
    pk_particles a, c, e;
    pk_rsa_stats st;
    run_case(3, 1, 0.0, 800, 0.5, 3.0, 20, &a, &st);
    run_case(3, 1, 0.0, 800, 0.5, 3.0, 20, &c, &st);
    CHECK(a.n == c.n);
    CHECK(memcmp(a.x, c.x, 3 * a.n * sizeof(double)) == 0);
    CHECK(memcmp(a.r, c.r, a.n * sizeof(double)) == 0);
    /* another seed gives another packing */
    pk_box b = {.dim = 3, .L = {20, 20, 20}, .periodic = {true, true, true}};
    double *d = poly_sizes(800, 0.5, 3.0, 11);
    int32_t *sp = calloc(800, sizeof *sp);
    pk_particles_init(&e, 3, 800);
    pk_rsa_params prm = {.delta_d = 0, .max_failed_draws = 100000, .seed = 6};
    pk_rsa_place(&b, d, sp, 800, &prm, NULL, &e, &st);
    CHECK(memcmp(a.x, e.x, 3 * a.n * sizeof(double)) != 0);
    free(d);
    free(sp);
    pk_particles_free(&a);
    pk_particles_free(&c);
    pk_particles_free(&e);
}

/* Asking for more than fits ends cleanly with what was placed. */
static void test_rsa_overfull_stops_cleanly(void)
{
    pk_box b = {.dim = 2, .L = {10, 10}, .periodic = {false, false}};
    size_t n = 400; /* 400 unit disks: φ = 3.14 > 1 — cannot fit */
    double *d = malloc(n * sizeof *d);
    int32_t *sp = calloc(n, sizeof *sp);
    for (size_t i = 0; i < n; i++)
        d[i] = 1.0;
    pk_particles p;
    pk_particles_init(&p, 2, n);
    pk_rsa_params prm = {.delta_d = 0, .max_failed_draws = 20000, .seed = 2};
    pk_rsa_stats st;
    CHECK(pk_rsa_place(&b, d, sp, n, &prm, NULL, &p, &st) == 0);
    CHECK(st.reason == PK_STOP_MAX_FAILED_DRAWS || st.reason == PK_STOP_SATURATED);
    CHECK(st.placed == p.n && st.placed > 40 && st.placed < n);
    double gmin, wmin;
    brute_gaps(&b, &p, &gmin, &wmin);
    CHECK(gmin >= -1e-12 && wmin >= -1e-12);
    free(d);
    free(sp);
    pk_particles_free(&p);
}

static void test_rsa_no_room(void)
{
    pk_box b = {.dim = 3, .L = {5, 5, 5}};
    double d[1] = {6.0};
    int32_t sp[1] = {0};
    pk_particles p;
    pk_particles_init(&p, 3, 1);
    pk_rsa_params prm = {.delta_d = 0, .max_failed_draws = 10, .seed = 2};
    pk_rsa_stats st;
    CHECK(pk_rsa_place(&b, d, sp, 1, &prm, NULL, &p, &st) == 0);
    CHECK(st.reason == PK_STOP_NO_ROOM && st.placed == 0);
    pk_particles_free(&p);
}

static void test_rsa_cancel(void)
{
    pk_box b = {.dim = 3, .L = {30, 30, 30}, .periodic = {true, true, true}};
    size_t n = 5000;
    double *d = malloc(n * sizeof *d);
    int32_t *sp = calloc(n, sizeof *sp);
    for (size_t i = 0; i < n; i++)
        d[i] = 1.0;
    volatile sig_atomic_t cancel = 1;
    pk_monitor mon = {.cancel = &cancel};
    pk_particles p;
    pk_particles_init(&p, 3, n);
    pk_rsa_params prm = {.delta_d = 0, .max_failed_draws = 1000, .seed = 2};
    pk_rsa_stats st;
    CHECK(pk_rsa_place(&b, d, sp, n, &prm, &mon, &p, &st) == 0);
    CHECK(st.reason == PK_STOP_CANCELLED);
    CHECK(st.placed < n);
    free(d);
    free(sp);
    pk_particles_free(&p);
}

/* Physics: RSA of equal spheres saturates at φ ≈ 0.3841 (Torquato et al.,
 * 2006); equal disks at ≈ 0.5473.  A finite run stops below saturation but
 * close to it (approach ∝ t^(-1/d)): require φ in [0.33, 0.3841] (3D) and
 * [0.48, 0.5473] (2D).  The lower bounds were set 2–3 % below what N_F = 1e5
 * reaches for these sizes, so that a broken placer that stops early fails. */
static void test_rsa_saturation(void)
{
    for (int dim = 2; dim <= 3; dim++) {
        double L = dim == 3 ? 16 : 60;
        pk_box b = {.dim = dim, .L = {L, L, dim == 3 ? L : 0}, .periodic = {true, true, true}};
        size_t n = dim == 3 ? 4000 : 6000;
        double *d = malloc(n * sizeof *d);
        int32_t *sp = calloc(n, sizeof *sp);
        for (size_t i = 0; i < n; i++)
            d[i] = 1.0;
        pk_particles p;
        pk_particles_init(&p, dim, n);
        pk_rsa_params prm = {.delta_d = 0, .max_failed_draws = 100000, .seed = 3};
        pk_rsa_stats st;
        CHECK(pk_rsa_place(&b, d, sp, n, &prm, NULL, &p, &st) == 0);
        double phi = pk_particles_solid_measure(&p) / pk_box_measure(&b);
        printf("  RSA saturation dim %d: phi = %.4f (%zu grains)\n", dim, phi, p.n);
        if (dim == 3)
            CHECK(phi > 0.33 && phi < 0.3841);
        else
            CHECK(phi > 0.48 && phi < 0.5473);
        free(d);
        free(sp);
        pk_particles_free(&p);
    }
}

typedef struct {
    size_t *found;
    size_t n;
} collect_ctx;

static int collect(size_t j, const double dx[3], double d2, void *vctx)
{
    collect_ctx *c = vctx;
    c->found[c->n++] = j;
    return 0;
}

static int cmp_size(const void *a, const void *b)
{
    size_t x = *(const size_t *)a, y = *(const size_t *)b;
    return (x > y) - (x < y);
}

/* The grid reports exactly the brute-force neighbour set, every grain once,
 * across levels, periodic seams and after moves/removals. */
/* wall_gap: "half" keeps every wall clearance >= Δd/2, "none" only keeps the
 * grains inside the walls (the gaps between grains stay >= Δd) — and then some
 * grains come closer to a wall than Δd/2.  Both the one-grain-at-a-time path
 * (polydisperse, plain and open draws) and the batched path (equal grains). */
static void test_rsa_wall_gap(void)
{
    const double dd = 0.5, L = 12;
    pk_box b = {.dim = 3, .L = {L, L, L}};
    for (int mono = 0; mono < 2; mono++)
        for (int draws = 0; draws < 2; draws++)
            for (int wg = 0; wg < 2; wg++) {
                size_t n = 1200;
                double *d = mono ? malloc(n * sizeof *d) : poly_sizes(n, 0.6, 1.5, 3);
                for (size_t i = 0; mono && i < n; i++)
                    d[i] = 1.0;
                int32_t *sp = calloc(n, sizeof *sp);
                pk_particles p;
                pk_particles_init(&p, 3, n);
                pk_rsa_params prm = {.delta_d = dd,
                                     .max_failed_draws = 20000,
                                     .seed = 4,
                                     .draws = draws ? PK_RSA_DRAWS_PLAIN : PK_RSA_DRAWS_OPEN,
                                     .wall_gap = wg ? PK_RSA_WALL_GAP_NONE : PK_RSA_WALL_GAP_HALF};
                pk_rsa_stats st;
                CHECK(pk_rsa_place(&b, d, sp, n, &prm, NULL, &p, &st) == 0);
                CHECK_MSG(st.placed > 100, "mono %d draws %d wg %d placed %zu", mono, draws, wg,
                          st.placed);
                double gmin, wmin;
                brute_gaps(&b, &p, &gmin, &wmin);
                CHECK_MSG(gmin >= dd - 1e-12 * L, "mono %d wall_gap %d: min gap %.17g", mono, wg,
                          gmin);
                if (wg)
                    CHECK_MSG(wmin >= -1e-12 * L && wmin < 0.1 * dd,
                              "mono %d draws %d wall_gap none: min wall clearance %.17g", mono,
                              draws, wmin);
                else
                    CHECK_MSG(wmin >= 0.5 * dd - 1e-12 * L,
                              "mono %d draws %d wall_gap half: min wall clearance %.17g", mono,
                              draws, wmin);
                free(d);
                free(sp);
                pk_particles_free(&p);
            }
    pk_rsa_params bad = {.delta_d = dd, .max_failed_draws = 10, .wall_gap = 2};
    pk_particles p;
    pk_particles_init(&p, 3, 1);
    double d1 = 1;
    int32_t s1 = 0;
    CHECK(pk_rsa_place(&b, &d1, &s1, 1, &bad, NULL, &p, NULL) == -1);
    pk_particles_free(&p);
}

static void test_grid_query_matches_brute_force(void)
{
    for (int dim = 2; dim <= 3; dim++)
        for (int per = 0; per <= 1; per++) {
            pk_box b = {.dim = dim, .L = {10, 7, dim == 3 ? 9 : 0}};
            for (int k = 0; k < dim; k++)
                b.periodic[k] = per;
            size_t n = 600;
            pk_particles p;
            pk_particles_init(&p, dim, n);
            pk_rng g;
            pk_rng_seed(&g, 42, (uint64_t)(dim * 2 + per));
            for (size_t i = 0; i < n; i++) {
                double x[3] = {pk_rng_range(&g, 0, b.L[0]), pk_rng_range(&g, 0, b.L[1]),
                               dim == 3 ? pk_rng_range(&g, 0, b.L[2]) : 0};
                pk_particles_push(&p, x, 0.005 * pow(200, pk_rng_uniform(&g)), 0);
            }
            pk_grid grid;
            double gap = 0.05;
            CHECK(pk_grid_init(&grid, &b, 0.005, 1.0, gap, n) == 0);
            for (size_t i = 0; i < n; i++)
                pk_grid_insert(&grid, &p, i);
            /* move a third, remove a tenth */
            for (size_t i = 0; i < n; i += 3) {
                p.x[3 * i] = pk_rng_range(&g, 0, b.L[0]);
                p.r[i] *= 1.5;
                pk_grid_update(&grid, &p, i);
            }
            /* grow some in place beyond the init range (a growing EDMD grain):
             * its level's bound must follow even though its cell is unchanged */
            for (size_t i = 2; i < n; i += 7) {
                p.r[i] *= 2.5;
                pk_grid_update(&grid, &p, i);
            }
            for (size_t i = 1; i < n; i += 10)
                pk_grid_remove(&grid, i);
            size_t *found = malloc(n * sizeof *found), *want = malloc(n * sizeof *want);
            int mismatches = 0;
            for (int q = 0; q < 200; q++) {
                double x[3] = {pk_rng_range(&g, 0, b.L[0]), pk_rng_range(&g, 0, b.L[1]),
                               dim == 3 ? pk_rng_range(&g, 0, b.L[2]) : 0};
                double r = 0.01 * pow(100, pk_rng_uniform(&g)), extra = 0.1;
                collect_ctx c = {found, 0};
                pk_grid_query(&grid, &p, x, r, extra, collect, &c);
                size_t nw = 0;
                for (size_t j = 0; j < n; j++) {
                    if (j % 10 == 1)
                        continue;
                    double s = r + p.r[j] + gap + extra;
                    if (pk_box_dist2(&b, x, &p.x[3 * j]) < s * s)
                        want[nw++] = j;
                }
                qsort(found, c.n, sizeof *found, cmp_size);
                if (c.n != nw || memcmp(found, want, nw * sizeof *want) != 0)
                    mismatches++;
            }
            CHECK_MSG(mismatches == 0, "dim %d periodic %d: %d of 200 queries differ", dim, per,
                      mismatches);
            free(found);
            free(want);
            pk_grid_free(&grid);
            pk_particles_free(&p);
        }
}

int main(void)
{
    RUN(test_grid_query_matches_brute_force);
    RUN(test_rsa_2d_walled);
    RUN(test_rsa_2d_periodic);
    RUN(test_rsa_3d_walled);
    RUN(test_rsa_3d_periodic);
    RUN(test_rsa_mixed_axes);
    RUN(test_rsa_ratio_1000);
    RUN(test_rsa_reproducible);
    RUN(test_rsa_overfull_stops_cleanly);
    RUN(test_rsa_no_room);
    RUN(test_rsa_cancel);
    RUN(test_rsa_saturation);
    RUN(test_rsa_wall_gap);
    return check_summary();
}
