/* test_homog_relax_move.c — the 2D SSE2 move of pk_relax_move
 * (core/homog/homog_relax.c) gives the generic loop's x, v and stale flag bit for
 * bit: DR's first step (cv = 0) and later steps, FIRE-like coefficients,
 * held grains left untouched, the skin test on both sides of its limit, and
 * NaN/Inf entries passed through alike. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "core/homog/homog_relax.h"
#include "core/base/rng.h"

typedef struct state {
    double *x, *v;
} state;

static state run(const double *x0, const double *v0, const double *f, const uint8_t *is_free,
                 size_t np, pk_relax_coef cf, const pk_dem_pairs *c, int scalar, int *stale,
                 double acc[2])
{
    state s = {malloc(3 * np * sizeof *s.x), malloc(3 * np * sizeof *s.v)};
    memcpy(s.x, x0, 3 * np * sizeof *s.x);
    memcpy(s.v, v0, 3 * np * sizeof *s.v);
    pk_relax_scalar_move = scalar;
    *stale = acc ? pk_relax_move_acc(s.x, s.v, f, is_free, np, 2, cf, c, acc)
                 : pk_relax_move(s.x, s.v, f, is_free, np, 2, cf, c);
    pk_relax_scalar_move = 0;
    return s;
}

/* skin_far: grain 7 is moved beyond half the skin (stale = 1 expected) */
static void same_bits(pk_relax_coef cf, int skin_far, int nonfinite, uint64_t seed)
{
    const size_t np = 1001;
    pk_rng rng;
    pk_rng_seed(&rng, seed, 11);
    double *x = malloc(3 * np * sizeof *x), *v = malloc(3 * np * sizeof *v),
           *f = malloc(3 * np * sizeof *f), *xb = malloc(3 * np * sizeof *xb);
    uint8_t *is_free = malloc(np);
    for (size_t k = 0; k < 3 * np; k++) {
        xb[k] = pk_rng_range(&rng, -50, 50);
        x[k] = xb[k] + pk_rng_range(&rng, -0.01, 0.01);
        v[k] = pk_rng_range(&rng, -1, 1);
        f[k] = pk_rng_range(&rng, -3, 3);
    }
    for (size_t i = 0; i < np; i++)
        is_free[i] = i % 17 != 3; /* some held grains */
    if (skin_far)
        x[3 * 7] = xb[3 * 7] + 0.3;
    if (nonfinite) {
        f[3 * 20] = NAN;
        v[3 * 21 + 1] = INFINITY;
        x[3 * 22] = -INFINITY;
    }
    pk_dem_pairs c = {.xb = xb, .np = np, .skin = 0.2};
    int st_a, st_b;
    state a = run(x, v, f, is_free, np, cf, &c, 1, &st_a, NULL);
    state b = run(x, v, f, is_free, np, cf, &c, 0, &st_b, NULL);
    CHECK(st_a == st_b);
    /* with the increments' sums (v·v, v·f): the same moves and the same sums */
    double sa[2] = {0.5, -0.25}, sb[2] = {0.5, -0.25};
    int st_c, st_d;
    state ca = run(x, v, f, is_free, np, cf, &c, 1, &st_c, sa);
    state cb = run(x, v, f, is_free, np, cf, &c, 0, &st_d, sb);
    CHECK(st_c == st_a && st_d == st_a);
    CHECK(memcmp(ca.x, a.x, 3 * np * sizeof *a.x) == 0 &&
          memcmp(cb.v, a.v, 3 * np * sizeof *a.v) == 0);
    CHECK(memcmp(sa, sb, sizeof sa) == 0);
    if (!nonfinite) { /* the sums themselves, against a plain loop (added to what acc held;
                        * another order of ~2,000 terms of order 1: 1e-12 relative) */
        double vv = 0, vf = 0;
        for (size_t i = 0; i < np; i++)
            for (int k = 0; k < 2 && is_free[i]; k++)
                vv += a.v[3 * i + k] * a.v[3 * i + k], vf += a.v[3 * i + k] * f[3 * i + k];
        CHECK_NEAR(sa[0], 0.5 + vv, 1e-12 * (1 + vv));
        CHECK_NEAR(sa[1], -0.25 + vf, 1e-12 * (1 + fabs(vf)) + 1e-12 * vv);
    }
    free(ca.x), free(ca.v), free(cb.x), free(cb.v);
    CHECK(st_a == skin_far);
    CHECK(memcmp(a.x, b.x, 3 * np * sizeof *a.x) == 0);
    CHECK(memcmp(a.v, b.v, 3 * np * sizeof *a.v) == 0);
    /* held grains and the third components untouched */
    int kept = 1;
    for (size_t i = 0; i < np; i++) {
        kept &= b.x[3 * i + 2] == x[3 * i + 2] && b.v[3 * i + 2] == v[3 * i + 2];
        if (!is_free[i])
            kept &= memcmp(&b.x[3 * i], &x[3 * i], 3 * sizeof *x) == 0 &&
                memcmp(&b.v[3 * i], &v[3 * i], 3 * sizeof *v) == 0;
    }
    CHECK(kept);
    /* the move did move (a test that cannot pass on a no-op) */
    CHECK(b.x[3 * 1] != x[3 * 1]);
    free(a.x), free(a.v), free(b.x), free(b.v);
    free(x), free(v), free(f), free(xb), free(is_free);
}

static void dr_first_step(void) { same_bits((pk_relax_coef){0.01, 0, 0.005}, 0, 0, 1); }
static void dr_step(void) { same_bits((pk_relax_coef){0.01, 0.93, 0.0187}, 0, 0, 2); }
static void fire_step(void) { same_bits((pk_relax_coef){0.05, 0.9, 0.013}, 0, 0, 3); }
static void stale_flag(void) { same_bits((pk_relax_coef){0.01, 0.93, 0.0187}, 1, 0, 4); }
static void nonfinite(void) { same_bits((pk_relax_coef){0.01, 0.93, 0.0187}, 1, 1, 5); }

int main(void)
{
    RUN(dr_first_step);
    RUN(dr_step);
    RUN(fire_step);
    RUN(stale_flag);
    RUN(nonfinite);
    return check_summary();
}
