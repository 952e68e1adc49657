/* test_dem_lanes.c — the AVX2 geometry lanes of the 2D pk_dem_eval
 * (core/dem/dem_eval_loops.c) give the scalar loop's numbers bit for bit: l, |l|,
 * ε of every candidate, the contact count, forces, energy and the contact
 * sum S.  Sheared periodic and open boxes, uniform and class-specific
 * stiffness, candidate counts spanning several evaluation blocks with short
 * last groups of lanes, and one grain a thousand periods out (its pairs'
 * lattice shifts, added in both paths, are large).  Without AVX2 both
 * paths are the scalar one: the cases are a SKIP, not a pass. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "core/dem/dem_contact.h"
#include "core/space/mat3.h"
#include "core/base/rng.h"

typedef struct outcome {
    size_t nc, n;
    double *f, *l, *len, *eps, energy, S[9];
} outcome;

static void outcome_free(outcome *o) { free(o->f), free(o->l), free(o->len), free(o->eps); }

static void *dup(const void *p, size_t bytes)
{
    void *q = malloc(bytes);
    memcpy(q, p, bytes);
    return q;
}

/* Evaluate at x twice per mode: with energy and S (the checks' path) and
 * with forces only (the DR iteration's path; its forces must equal the
 * first's too).  Then pk_dem_eval_forces (the relaxations' evaluation,
 * geometry in block buffers) with the pair arrays poisoned: the same forces
 * and count (it reads none of them), and pk_dem_eval without outputs puts
 * the same geometry back (pk_relax_geom_refresh). */
static void eval(pk_dem_pairs *c, const pk_dem_geom *g, const double *x, const double *r, size_t np,
                 int scalar, outcome *o)
{
    pk_dem_scalar_only = scalar;
    double *f2 = malloc(3 * np * sizeof *f2);
    o->f = malloc(3 * np * sizeof *o->f);
    o->nc = pk_dem_eval(c, g, x, r, np, 2.5, o->f, &o->energy, o->S);
    CHECK(pk_dem_eval(c, g, x, r, np, 2.5, f2, NULL, NULL) == o->nc);
    CHECK(memcmp(f2, o->f, 3 * np * sizeof *f2) == 0);
    o->n = c->n;
    o->l = dup(c->l, 3 * c->n * sizeof *c->l);
    o->len = dup(c->len, c->n * sizeof *c->len);
    o->eps = dup(c->eps, c->n * sizeof *c->eps);
    for (size_t p = 0; p < c->n; p++) {
        c->l[3 * p] = c->l[3 * p + 1] = c->l[3 * p + 2] = NAN;
        c->len[p] = c->eps[p] = NAN;
    }
    memset(f2, 0x7f, 3 * np * sizeof *f2); /* overwritten, not accumulated into */
    CHECK(pk_dem_eval_forces(c, g, x, r, np, 2.5, f2) == o->nc);
    CHECK(memcmp(f2, o->f, 3 * np * sizeof *f2) == 0);
    CHECK(pk_dem_eval(c, g, x, r, np, 2.5, NULL, NULL, NULL) == o->nc);
    CHECK(memcmp(c->l, o->l, 3 * c->n * sizeof *c->l) == 0);
    CHECK(memcmp(c->len, o->len, c->n * sizeof *c->len) == 0);
    CHECK(memcmp(c->eps, o->eps, c->n * sizeof *c->eps) == 0);
    pk_dem_scalar_only = 0;
    free(f2);
}

static void same_numbers(int periodic, int classes, int far)
{
    const size_t np = 3001; /* ≈ 7000 candidates: many blocks, a short last group */
    const double L = 60;
    pk_rng rng;
    pk_rng_seed(&rng, 5, (uint64_t)(4 * periodic + 2 * classes + far));
    double *x = calloc(3 * np, sizeof *x), *r = malloc(np * sizeof *r);
    int32_t *cls = malloc(np * sizeof *cls);
    const double F[9] = {0.97, 0.31, 0, -0.04, 1.02, 0, 0, 0, 1};
    pk_dem_geom g = {.dim = 2, .periodic = periodic, .L = {L, L, 0}};
    CHECK(pk_dem_geom_set_F(&g, F) != 0);
    for (size_t i = 0; i < np; i++) {
        double s[3] = {pk_rng_range(&rng, 0, L), pk_rng_range(&rng, 0, L), 0};
        pk_m3_vec(F, s, &x[3 * i]);
        r[i] = pk_rng_range(&rng, 0.4, 0.9);
        cls[i] = (int32_t)(i % 3);
    }
    const double kmat[9] = {1, 0.5, 0.7, 0.5, 2, 0.3, 0.7, 0.3, 1.5};
    pk_dem_pairs c = {0};
    if (classes)
        pk_dem_pairs_stiffness(&c, cls, kmat, 3, 1.5);
    if (far) { /* one grain moved by a thousand box lengths */
        x[0] += 1000 * L;
        x[1] -= 1000 * L;
    }
    CHECK(pk_dem_pairs_build(&c, &g, x, r, np, 0.2) == 0);
    if (c.n % 4 == 0) /* a short last group of lanes (any sub-list is a valid candidate list) */
        c.n--;
    outcome v, s;
    eval(&c, &g, x, r, np, 0, &v);
    eval(&c, &g, x, r, np, 1, &s);
    printf("  periodic=%d classes=%d far=%d: candidates=%zu contacts=%zu\n", periodic, classes, far,
           c.n, v.nc);
    CHECK(c.n > 5000 && c.n % 4 != 0);
    CHECK(v.nc > 500 && v.nc < c.n); /* contacts and open candidates both present */
    CHECK(v.nc == s.nc);
    CHECK(memcmp(v.l, s.l, 3 * c.n * sizeof *v.l) == 0);
    CHECK(memcmp(v.len, s.len, c.n * sizeof *v.len) == 0);
    CHECK(memcmp(v.eps, s.eps, c.n * sizeof *v.eps) == 0);
    CHECK(memcmp(v.f, s.f, 3 * np * sizeof *v.f) == 0);
    CHECK(memcmp(&v.energy, &s.energy, sizeof v.energy) == 0);
    CHECK(memcmp(v.S, s.S, sizeof v.S) == 0);
    /* the forces balance (Σ f_i = 0 up to round-off: |f| ≈ E·ε ≲ 2.5, a few
     * thousand terms of 1e-16 relative) — the evaluation is not vacuous */
    double fs0 = 0, fs1 = 0, fbig = 0;
    for (size_t i = 0; i < np; i++) {
        fs0 += v.f[3 * i], fs1 += v.f[3 * i + 1];
        fbig = fmax(fbig, fabs(v.f[3 * i]));
    }
    CHECK(fbig > 0.1);
    CHECK_NEAR(fs0, 0, 1e-10);
    CHECK_NEAR(fs1, 0, 1e-10);
    outcome_free(&v);
    outcome_free(&s);
    pk_dem_pairs_free(&c);
    free(x), free(r), free(cls);
}

static void test_periodic_uniform(void) { same_numbers(1, 0, 0); }
static void test_periodic_classes(void) { same_numbers(1, 1, 0); }
static void test_open_box(void) { same_numbers(0, 0, 0); }
static void test_far_image(void) { same_numbers(1, 0, 1); }

int main(void)
{
    if (!pk_dem_lanes_available()) {
        const char *why =
            "this CPU has no AVX2: the lanes would be the scalar loop compared with itself";
        SKIP(test_periodic_uniform, "%s", why);
        SKIP(test_periodic_classes, "%s", why);
        SKIP(test_open_box, "%s", why);
        SKIP(test_far_image, "%s", why);
        return 0;
    }
    RUN(test_periodic_uniform);
    RUN(test_periodic_classes);
    RUN(test_open_box);
    RUN(test_far_image);
    return check_summary();
}
