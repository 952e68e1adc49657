/* test_rsa_batch.c — the batched path for runs of equal grains (core/rsa/batch/README.md)
 * against plain draws one grain at a time (draws = plain, test.one_at_a_time): same
 * seed → the same packing bit for bit (memcmp of positions, radii, species),
 * the same number of draws and the same stop reason, for 2D and 3D, periodic,
 * walled and mixed axes, with Δd, with grains already present, with several
 * size classes in a row (the rng must be rewound exactly after each run),
 * across batch sizes from 1 attempt to adaptive.  The batched runs here keep
 * plain draws all along (draws = plain); the default (draws = open), which
 * later draws from the open region only, is compared with the plain path
 * statistically in test_rsa_region.c. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "core/rsa/rsa.h"
#include "core/base/rng.h"
#include "core/rsa/batch/rsa_cells.h"

typedef struct setup {
    pk_box box;
    double delta_d;
    uint64_t max_failed;
    size_t n;
    double *d;
    int32_t *sp;
    size_t nfixed;      /* grains present before the run */
    double fixed[4][4]; /* x, y, z, r */
} setup;

/* Runs RSA; batch = 0: plain reference; else batched with that many attempts
 * per batch (SIZE_MAX: adaptive). */
static void place(const setup *u, size_t batch, uint32_t min_run, pk_particles *p, pk_rsa_stats *st)
{
    pk_particles_init(p, u->box.dim, u->n + u->nfixed);
    for (size_t k = 0; k < u->nfixed; k++)
        pk_particles_push(p, u->fixed[k], u->fixed[k][3], 9);
    pk_rsa_params prm = {.delta_d = u->delta_d,
                         .max_failed_draws = u->max_failed,
                         .seed = 21,
                         .draws = PK_RSA_DRAWS_PLAIN,
                         .test = {.one_at_a_time = batch == 0,
                                  .batch_attempts = batch == SIZE_MAX ? 0 : (uint32_t)batch,
                                  .batch_min_run = min_run}};
    CHECK(pk_rsa_place(&u->box, u->d, u->sp, u->n, &prm, NULL, p, st) == 0);
}

static int same(const pk_particles *a, const pk_particles *b)
{
    return a->n == b->n && memcmp(a->x, b->x, 3 * a->n * sizeof(double)) == 0 &&
        memcmp(a->r, b->r, a->n * sizeof(double)) == 0 &&
        memcmp(a->species, b->species, a->n * sizeof(int32_t)) == 0;
}

/* The reference once, then the batched path at each batch size. */
static void compare(const char *name, const setup *u, uint32_t min_run, size_t expect_placed)
{
    static const size_t sizes[] = {1, 7, 1000, 4096, SIZE_MAX};
    pk_particles ref;
    pk_rsa_stats sr;
    place(u, 0, min_run, &ref, &sr);
    printf("  %s: plain placed %zu of %zu, %llu draws, %s\n", name, sr.placed, u->n,
           (unsigned long long)sr.draws, pk_stop_reason_name(sr.reason));
    if (expect_placed)
        CHECK_MSG(sr.placed == expect_placed, "%s: placed %zu", name, sr.placed);
    for (size_t q = 0; q < sizeof sizes / sizeof *sizes; q++) {
        /* B = 1 costs a batch per attempt: only on the small cases */
        if (sizes[q] == 1 && sr.draws > 300000)
            continue;
        pk_particles p;
        pk_rsa_stats sb;
        place(u, sizes[q], min_run, &p, &sb);
        CHECK_MSG(same(&p, &ref), "%s, B = %zu: packing differs (%zu vs %zu grains)", name,
                  sizes[q], p.n, ref.n);
        CHECK_MSG(sb.draws == sr.draws && sb.reason == sr.reason && sb.placed == sr.placed,
                  "%s, B = %zu: draws %llu/%llu reason %d/%d", name, sizes[q],
                  (unsigned long long)sb.draws, (unsigned long long)sr.draws, sb.reason, sr.reason);
        pk_particles_free(&p);
    }
    pk_particles_free(&ref);
}

static void mono(setup *u, int dim, const int periodic[3], double phi, double d, size_t n)
{
    memset(u, 0, sizeof *u);
    double L = dim == 3 ? cbrt((double)n * pk_ball_measure(3, 0.5 * d) / phi)
                        : sqrt((double)n * pk_ball_measure(2, 0.5 * d) / phi);
    u->box = (pk_box){.dim = dim, .L = {L, L, dim == 3 ? L : 0}};
    for (int k = 0; k < dim; k++)
        u->box.periodic[k] = periodic[k];
    u->n = n;
    u->max_failed = 1000000;
    u->d = malloc(n * sizeof *u->d);
    u->sp = calloc(n, sizeof *u->sp);
    for (size_t i = 0; i < n; i++)
        u->d[i] = d;
}

static void unset(setup *u)
{
    free(u->d);
    free(u->sp);
}

/* Monodisperse at φ = 0.30 (3D) / 0.45 (2D), the default run threshold:
 * what the bench and monodisperse jobs take. */
static void test_mono_matches_plain(void)
{
    setup u;
    mono(&u, 3, (int[3]){1, 1, 1}, 0.30, 1.0, 3000);
    compare("3D periodic", &u, 0, 3000);
    unset(&u);
    mono(&u, 2, (int[3]){0, 0, 0}, 0.45, 1.0, 2000);
    u.delta_d = 0.05;
    compare("2D walled, dd 0.05", &u, 0, 2000);
    unset(&u);
    /* with Δd: φ_eff = 0.2·(0.9/0.8)³ = 0.28 */
    mono(&u, 3, (int[3]){1, 0, 1}, 0.20, 0.8, 2500);
    u.delta_d = 0.1;
    compare("3D mixed axes, dd 0.1", &u, 0, 2500);
    unset(&u);
    mono(&u, 2, (int[3]){1, 1, 0}, 0.45, 1.0, 2000);
    compare("2D periodic", &u, 0, 2000);
    unset(&u);
}

/* Three size classes in a row (discrete grading) around present grains, 3D
 * walled with Δd: each class is a batched run; obstacles come from the grid. */
static void test_classes_and_present_grains(void)
{
    setup u;
    memset(&u, 0, sizeof u);
    u.box = (pk_box){.dim = 3, .L = {18, 16, 17}, .periodic = {false, true, false}};
    u.delta_d = 0.08;
    u.max_failed = 1000000;
    size_t cls[3] = {150, 700, 2200};
    double dia[3] = {2.0, 1.2, 0.7};
    u.n = cls[0] + cls[1] + cls[2];
    u.d = malloc(u.n * sizeof *u.d);
    u.sp = malloc(u.n * sizeof *u.sp);
    for (size_t i = 0, c = 0; c < 3; c++)
        for (size_t k = 0; k < cls[c]; k++, i++) {
            u.d[i] = dia[c];
            u.sp[i] = (int32_t)c;
        }
    u.nfixed = 2;
    u.fixed[0][0] = 5, u.fixed[0][1] = 8, u.fixed[0][2] = 6, u.fixed[0][3] = 3.0;
    u.fixed[1][0] = 12, u.fixed[1][1] = 1, u.fixed[1][2] = 12, u.fixed[1][3] = 2.5;
    compare("3 classes + 2 present grains", &u, 1, u.n);
    unset(&u);
}

/* Every grain its own size (continuous sizes), each grain a run of one. */
static void test_distinct_sizes(void)
{
    setup u;
    memset(&u, 0, sizeof u);
    u.box = (pk_box){.dim = 2, .L = {30, 25}, .periodic = {true, false}};
    u.delta_d = 0.03;
    u.max_failed = 100000;
    u.n = 400;
    u.d = malloc(u.n * sizeof *u.d);
    u.sp = calloc(u.n, sizeof *u.sp);
    for (size_t i = 0; i < u.n; i++)
        u.d[i] = 2.0 * pow(0.3, (double)i / (double)(u.n - 1));
    compare("2D distinct sizes, runs of 1", &u, 1, u.n);
    unset(&u);
}

/* More grains than fit: both paths stop after N^F consecutive failures at the
 * same attempt (the batch that crosses it is cut there). */
static void test_failure_stop_matches(void)
{
    setup u;
    mono(&u, 2, (int[3]){0, 0, 0}, 0.80, 1.0, 1200); /* φ 0.8 > RSA saturation 0.547 */
    u.max_failed = 3000;
    compare("2D overfull, N_F 3000", &u, 0, 0);
    pk_particles p;
    pk_rsa_stats st;
    place(&u, SIZE_MAX, 0, &p, &st);
    CHECK(st.reason == PK_STOP_MAX_FAILED_DRAWS && st.placed < u.n && st.placed > 500);
    pk_particles_free(&p);
    unset(&u);
}

/* The store's answers against brute force (minimum image, all pairs), for
 * points near periodic seams, walls and in the interior.  (Bit equality with
 * pk_grid's predicate is what the comparisons with the plain path prove.) */
static void test_cells_predicate_and_neighbours(void)
{
    pk_box b = {.dim = 3, .L = {17.3, 19.1, 6.4}, .periodic = {true, true, false}};
    double r = 0.45, gap = 0.1, lo[3] = {0, 0, r + 0.5 * gap};
    double span[3] = {17.3, 19.1, 6.4 - 2 * lo[2]};
    pk_rsa_cells C;
    CHECK(pk_rsa_cells_init(&C, &b, r, gap, lo, span) == 0);
    pk_rng g;
    pk_rng_seed(&g, 3, 3);
    double pts[400][3];
    for (int i = 0; i < 400; i++)
        for (int k = 0; k < 3; k++)
            pts[i][k] = lo[k] + span[k] * pk_rng_uniform(&g);
    for (int i = 0; i < 200; i++)
        CHECK(pk_rsa_cells_insert(&C, pts[i], (uint32_t)i) == 0);
    int wrong = 0, near = 0;
    uint8_t keep[200] = {0};
    uint32_t key[200], kept[200];
    double off[200][3];
    int seam = 0;
    for (int q = 0; q < 200; q++) {
        key[q] = pk_rsa_cells_key_q(&C, pts[200 + q], off[q]);
        for (int k = 0; k < 3; k++) {
            int64_t i = pk_rsa_cells_coord(&C, k, pts[200 + q][k]);
            seam += i == 0 || i == C.n[k] - 1;
        }
    }
    CHECK(seam > 20); /* points next to seams and walls are among them */
    size_t nkept = pk_rsa_cells_filter(&C, &pts[0][0], &off[0][0], pts[200], NULL, key, 200, kept);
    int ascending = 1;
    for (size_t j = 0; j < nkept; j++) {
        ascending &= j == 0 || kept[j] > kept[j - 1];
        keep[kept[j]] = 1;
    }
    CHECK(ascending);
    for (int q = 200; q < 400; q++) {
        int hit = 0;
        for (int i = 0; i < 200; i++) {
            double s = r + r + gap, d2 = pk_box_dist2(&b, pts[i], pts[q]);
            hit |= d2 < s * s;
            near += d2 < 4 * s * s;
        }
        wrong += keep[q - 200] == hit;
    }
    CHECK_MSG(wrong == 0, "%d of 200 filter answers differ from brute force", wrong);
    CHECK(near > 50); /* the test points do meet neighbours */
    pk_rsa_cells_free(&C);
}

/* The store keeps float offsets and lets the double predicate decide within
 * a band around contact (rsa_cells.h): queries at distance s·(1 + δ) from a
 * stored centre, δ from -1e-3 to 1e-3 down to 0 and ±1 ulp-size, across
 * periodic seams (ghost copies) and next to walls, in 3D and 2D, must get
 * exactly the answers of the exact predicate over all stored centres.  The
 * store holds a cell of four centres here (its pool) and two cells of two
 * (their 16-bit offsets and its band of ±2^-12, δ = ±1.2e-4: the quick test
 * decides beyond it, the pool within). */
static void test_cells_band_matches_exact_predicate(void)
{
    const pk_box boxes[3] = {
        {.dim = 3, .L = {7.9, 6.3, 5.2}, .periodic = {true, false, true}},
        {.dim = 2, .L = {9.7, 8.2, 0}, .periodic = {true, false}},
        /* one cell across the walled y axis: h = 1.88 c, the widest cell
         * the store makes (the 16-bit band's error bound assumes h < 2c) */
        {.dim = 3, .L = {7.9, 3.6, 5.2}, .periodic = {true, false, true}},
    };
    const double delta[] = {-1e-3, -2e-4,  -1.3e-4, -1.1e-4, -1e-4,  -3e-5, -1e-6,
                            -1e-9, -1e-13, -2e-16,  0,       2e-16,  1e-13, 1e-9,
                            1e-6,  3e-5,   1e-4,    1.1e-4,  1.3e-4, 2e-4,  1e-3};
    const int nd = (int)(sizeof delta / sizeof *delta);
    pk_rng g;
    pk_rng_seed(&g, 11, 2);
    for (int t = 0; t < 3; t++) {
        const pk_box *b = &boxes[t];
        double r = 0.61, gap = 0.03, s = r + r + gap, lo[3] = {0, 0, 0}, span[3] = {0, 0, 0};
        for (int k = 0; k < b->dim; k++) {
            lo[k] = b->periodic[k] ? 0 : r + 0.5 * gap;
            span[k] = b->periodic[k] ? b->L[k] : b->L[k] - 2 * lo[k];
        }
        pk_rsa_cells C;
        CHECK(pk_rsa_cells_init(&C, b, r, gap, lo, span) == 0);
        /* few centres (queries at contact with one are mostly clear of the
         * others), four of them in one cell (the pool), eight on seams and walls */
        enum { NS = 16, NQ = 3000 };
        static double pts[NS][3], q[NQ][3];
        memset(pts, 0, sizeof pts); /* z = 0 in 2D, as in the particle array */
        memset(q, 0, sizeof q);
        for (int i = 0; i < NS; i++) {
            for (int k = 0; k < b->dim; k++)
                pts[i][k] = i < 4 ? lo[k] + 0.5 * C.h[k] + 0.3 * C.h[k] * pk_rng_uniform(&g)
                                  : lo[k] + span[k] * pk_rng_uniform(&g);
            if (i >= 4 && i < 12)
                pts[i][i % b->dim] = i % 4 < 2 ? lo[i % b->dim] : lo[i % b->dim] + span[i % b->dim];
            for (int k = 0; i >= 12 && k < b->dim; k++) /* two cells of two: (2,1,1), (4,2,2) */
                pts[i][k] = lo[k] +
                    C.h[k] *
                        ((i < 14 ? 1 + (k == 0) : 2 + 2 * (k == 0)) % C.n[k] +
                         (i % 2 ? 0.8 : 0.15) + 0.05 * pk_rng_uniform(&g));
            CHECK(pk_rsa_cells_insert(&C, pts[i], (uint32_t)i) == 0);
        }
        int nq = 0;
        while (nq < NQ) {
            const double *p = pts[pk_rng_next(&g) % NS];
            double u[3] = {0, 0, 0}, n2 = 0;
            for (int k = 0; k < b->dim; k++) {
                u[k] = pk_rng_normal(&g);
                n2 += u[k] * u[k];
            }
            double f = s * (1 + delta[nq % nd]) / sqrt(n2);
            int inside = 1;
            for (int k = 0; k < b->dim; k++) {
                q[nq][k] = p[k] + f * u[k];
                if (b->periodic[k])
                    q[nq][k] -= b->L[k] * floor(q[nq][k] / b->L[k]);
                inside &= q[nq][k] >= lo[k] && q[nq][k] <= lo[k] + span[k];
            }
            nq += inside;
        }
        static uint32_t key[NQ], kept[NQ];
        static uint8_t keep[NQ];
        static double off[NQ][3];
        for (int i = 0; i < NQ; i++)
            key[i] = pk_rsa_cells_key_q(&C, q[i], off[i]);
        size_t nk = pk_rsa_cells_filter(&C, &pts[0][0], &off[0][0], &q[0][0], NULL, key, NQ, kept);
        memset(keep, 0, sizeof keep);
        for (size_t j = 0; j < nk; j++)
            keep[kept[j]] = 1;
        int wrong = 0, band = 0, open = 0;
        for (int i = 0; i < NQ; i++) {
            int hit = 0;
            double m2 = INFINITY;
            for (int j = 0; j < NS; j++) {
                hit |= pk_rsa_cells_close(&C, pts[j], q[i]);
                m2 = fmin(m2, pk_box_dist2(b, pts[j], q[i]));
            }
            wrong += keep[i] == hit;
            band += fabs(m2 / (s * s) - 1) < 1e-6;
            open += !hit;
        }
        printf("  dim %d: %d queries, %d within 1e-6 of contact, %d kept, %d wrong\n", b->dim, NQ,
               band, open, wrong);
        CHECK_MSG(wrong == 0, "dim %d: %d answers differ from the exact predicate", b->dim, wrong);
        CHECK(band > NQ / 12 && open > NQ / 20); /* the band and both answers are exercised */
        CHECK(C.nextra > 0);                     /* and the overflow pool */
        int two = 0, three = 0; /* cells of two (the 16-bit test) and of three or more */
        for (int i = 0; i < NS; i++) {
            double o[3];
            const uint32_t id = C.cell[pk_rsa_cells_index(pk_rsa_cells_key_q(&C, pts[i], o))].id;
            two += (id & PK_RSA_CELLS_MORE) && !(id & PK_RSA_CELLS_THREE);
            three += (id & PK_RSA_CELLS_MORE) && (id & PK_RSA_CELLS_THREE);
        }
        CHECK(two >= 2 && three >= 3);
        pk_rsa_cells_free(&C);
    }
}

int main(void)
{
    RUN(test_cells_predicate_and_neighbours);
    RUN(test_cells_band_matches_exact_predicate);
    RUN(test_mono_matches_plain);
    RUN(test_classes_and_present_grains);
    RUN(test_distinct_sizes);
    RUN(test_failure_stop_matches);
    return check_summary();
}
