/* test_dem_parallel.c — the parallel contact evaluation (pk_dem_pairs.par,
 * core/dem/dem_eval_par.c) gives the serial results bit for bit for 1–4
 * threads: forces, contact counts, and for pk_dem_eval the pair arrays l,
 * |l|, ε, the energy and S.  Scenes: random 2D periodic (sheared) and open
 * boxes with overlaps, class-specific stiffness, grains moved after the
 * build (contacts that open and close), a lattice with exact zero branch
 * components (signed zeros) and isolated grains, 3D, a list not in build
 * order (the serial fallback), rebuilds (the per-grain lists refreshed, also
 * for another grain count) and lists shorter than the threads' alignment.
 * Each with the AVX2 lanes and with pk_dem_scalar_only = 1. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "core/dem/dem_contact.h"
#include "core/space/mat3.h"
#include "core/base/par.h"
#include "core/base/rng.h"

typedef struct outcome {
    size_t nc[4], n, np;
    double *f[4]; /* pk_dem_eval with energy and S, with energy, bare; pk_dem_eval_forces */
    double *l, *len, *eps, energy[2], S[9];
} outcome;

static void outcome_free(outcome *o)
{
    for (int k = 0; k < 4; k++)
        free(o->f[k]);
    free(o->l), free(o->len), free(o->eps);
}

static double *fresh(size_t n)
{
    double *p = malloc(n * sizeof *p);
    memset(p, 0x7f, n * sizeof *p); /* every entry must be overwritten */
    return p;
}

static void poison_pairs(pk_dem_pairs *c)
{
    memset(c->l, 0xff, 3 * c->n * sizeof *c->l);
    memset(c->len, 0xff, c->n * sizeof *c->len);
    memset(c->eps, 0xff, c->n * sizeof *c->eps);
}

/* Every evaluation of c at x on pool par (NULL = the serial code). */
static void eval(pk_dem_pairs *c, pk_par *par, const pk_dem_geom *g, const double *x,
                 const double *r, size_t np, outcome *o)
{
    const double E = 2.5;
    c->par = par;
    o->n = c->n;
    o->np = np;
    for (int k = 0; k < 4; k++)
        o->f[k] = fresh(3 * np);
    double S[9];
    memset(S, 0x7f, sizeof S);
    poison_pairs(c);
    o->nc[0] = pk_dem_eval(c, g, x, r, np, E, o->f[0], &o->energy[0], S);
    memcpy(o->S, S, sizeof S);
    o->l = malloc(3 * c->n * sizeof *o->l);
    o->len = malloc(c->n * sizeof *o->len);
    o->eps = malloc(c->n * sizeof *o->eps);
    memcpy(o->l, c->l, 3 * c->n * sizeof *o->l);
    memcpy(o->len, c->len, c->n * sizeof *o->len);
    memcpy(o->eps, c->eps, c->n * sizeof *o->eps);
    poison_pairs(c);
    o->nc[1] = pk_dem_eval(c, g, x, r, np, E, o->f[1], &o->energy[1], NULL); /* Newton's call */
    CHECK(memcmp(c->eps, o->eps, c->n * sizeof *o->eps) == 0);
    o->nc[2] = pk_dem_eval(c, g, x, r, np, E, o->f[2], NULL, NULL);
    CHECK(memcmp(c->l, o->l, 3 * c->n * sizeof *o->l) == 0);
    o->nc[3] = pk_dem_eval_forces(c, g, x, r, np, E, o->f[3]);
    c->par = NULL;
}

/* The outcome on par equals the serial one bit for bit. */
static int same(const outcome *s, const outcome *p)
{
    int ok = s->n == p->n && s->np == p->np;
    for (int k = 0; k < 4 && ok; k++)
        ok = s->nc[k] == p->nc[k] && memcmp(s->f[k], p->f[k], 3 * s->np * sizeof(double)) == 0;
    return ok && memcmp(s->l, p->l, 3 * s->n * sizeof(double)) == 0 &&
        memcmp(s->len, p->len, s->n * sizeof(double)) == 0 &&
        memcmp(s->eps, p->eps, s->n * sizeof(double)) == 0 &&
        memcmp(s->energy, p->energy, sizeof s->energy) == 0 && memcmp(s->S, p->S, sizeof s->S) == 0;
}

/* The scene's serial outcome (lanes and scalar), against 1–4 threads; the
 * serial forces checked not vacuous (contacts and open candidates, Σ f = 0). */
static void compare(pk_dem_pairs *c, const pk_dem_geom *g, const double *x, const double *r,
                    size_t np, const char *what)
{
    for (int scalar = 0; scalar <= 1; scalar++) {
        pk_dem_scalar_only = scalar;
        outcome s;
        eval(c, NULL, g, x, r, np, &s);
        for (int k = 1; k < 4; k++) /* the serial paths agree among themselves */
            CHECK(s.nc[k] == s.nc[0] && memcmp(s.f[k], s.f[0], 3 * np * sizeof(double)) == 0);
        for (int nt = 1; nt <= 4; nt++) {
            pk_par *par = pk_par_new(nt);
            CHECK((par != NULL) == (nt > 1));
            outcome p;
            eval(c, par, g, x, r, np, &p);
            CHECK_MSG(same(&s, &p), "%s: %d threads, scalar %d differ from serial", what, nt,
                      scalar);
            outcome_free(&p);
            pk_par_free(par);
        }
        if (scalar == 0) {
            double sum[3] = {0, 0, 0}, big = 0;
            for (size_t i = 0; i < np; i++)
                for (int a = 0; a < 3; a++) {
                    sum[a] += s.f[0][3 * i + a];
                    big = fmax(big, fabs(s.f[0][3 * i + a]));
                }
            printf("  %s: %zu grains, %zu candidates, %zu contacts, max |f| %.3g\n", what, np, c->n,
                   s.nc[0], big);
            if (c->n > 100) {
                CHECK(s.nc[0] > c->n / 10 && s.nc[0] <= c->n);
                CHECK(big > 0.1);
            }
            /* Σ f = 0: |f| ≲ E·ε·z ≈ 5, up to ~10⁴ terms of 1e-16 relative */
            for (int a = 0; a < 3; a++)
                CHECK_NEAR(sum[a], 0, 1e-10);
        }
        outcome_free(&s);
    }
    pk_dem_scalar_only = 0;
}

typedef struct scene {
    size_t np;
    int dim;
    double *x, *r;
    int32_t *cls;
    pk_dem_geom g;
} scene;

static void scene_free(scene *s) { free(s->x), free(s->r), free(s->cls); }

/* np grains at random in a box of edge L (reference frame) under F. */
static scene random_scene(size_t np, int dim, int periodic, double L, const double F[9],
                          uint64_t stream)
{
    scene s = {.np = np, .dim = dim, .g = {.dim = dim, .periodic = periodic, .L = {L, L, L}}};
    pk_dem_geom_set_F(&s.g, F);
    s.x = calloc(3 * np, sizeof *s.x);
    s.r = malloc(np * sizeof *s.r);
    s.cls = malloc(np * sizeof *s.cls);
    pk_rng rng;
    pk_rng_seed(&rng, 11, stream);
    for (size_t i = 0; i < np; i++) {
        double u[3] = {pk_rng_range(&rng, 0, L), pk_rng_range(&rng, 0, L),
                       dim == 3 ? pk_rng_range(&rng, 0, L) : 0};
        pk_m3_vec(F, u, &s.x[3 * i]);
        s.r[i] = pk_rng_range(&rng, 0.4, 0.9);
        s.cls[i] = (int32_t)(i % 3);
    }
    return s;
}

/* Move every grain by less than skin/2 (the list stays valid): contacts
 * open and close against the build. */
static void jiggle(scene *s, double amp, uint64_t stream)
{
    pk_rng rng;
    pk_rng_seed(&rng, 12, stream);
    for (size_t i = 0; i < s->np; i++)
        for (int k = 0; k < s->dim; k++)
            s->x[3 * i + k] += pk_rng_range(&rng, -amp, amp) / sqrt(3.0);
}

static const double kmat[9] = {1, 0.5, 0.7, 0.5, 2, 0.3, 0.7, 0.3, 1.5};
static const double F2[9] = {0.97, 0.31, 0, -0.04, 1.02, 0, 0, 0, 1};
static const double F3[9] = {0.98, 0.12, 0.05, -0.03, 1.01, 0.02, 0.04, -0.06, 0.99};

static void random_case(int dim, int periodic, int classes)
{
    const double skin = 0.2;
    scene s = dim == 2 ? random_scene(3001, 2, periodic, 60, F2, (uint64_t)(periodic + 2 * classes))
                       : random_scene(2500, 3, periodic, 14, F3, (uint64_t)(4 + periodic));
    pk_dem_pairs c = {0};
    if (classes)
        pk_dem_pairs_stiffness(&c, s.cls, kmat, 3, 1.5);
    CHECK(pk_dem_pairs_build(&c, &s.g, s.x, s.r, s.np, skin) == 0);
    char what[64];
    snprintf(what, sizeof what, "%dD periodic=%d classes=%d", dim, periodic, classes);
    compare(&c, &s.g, s.x, s.r, s.np, what);
    jiggle(&s, 0.49 * skin, 1);
    CHECK(!pk_dem_pairs_stale(&c, s.x, dim));
    strcat(what, " moved");
    compare(&c, &s.g, s.x, s.r, s.np, what);
    pk_dem_pairs_free(&c);
    scene_free(&s);
}

static void test_2d_periodic(void) { random_case(2, 1, 0); }
static void test_2d_periodic_classes(void) { random_case(2, 1, 1); }
static void test_2d_open_box(void) { random_case(2, 0, 0); }
static void test_3d_periodic_classes(void) { random_case(3, 1, 1); }
static void test_3d_open_box(void) { random_case(3, 0, 0); }

/* A square lattice (spacing 1.9 < 2r = 2 in x, 2.5 > 2r in y) on an
 * unsheared periodic box: every branch vector has an exact 0 component, so
 * the pair forces carry −0 (−t·0, summed into +0); every third column
 * removed (grains with a contact on one side only) and a few grains
 * isolated by shrinking them (no contact at all: f = +0). */
static void test_lattice_signed_zeros(void)
{
    const size_t nx = 60, ny = 50;
    const double ax = 1.9, ay = 2.5;
    scene s = {.dim = 2, .g = {.dim = 2, .periodic = 1, .L = {nx * ax, ny * ay, 0}}};
    const double I[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    pk_dem_geom_set_F(&s.g, I);
    s.x = calloc(3 * nx * ny, sizeof *s.x);
    s.r = malloc(nx * ny * sizeof *s.r);
    for (size_t b = 0; b < ny; b++)
        for (size_t a = 0; a < nx; a++) {
            if (a % 3 == 2)
                continue;
            s.x[3 * s.np] = (double)a * ax;
            s.x[3 * s.np + 1] = (double)b * ay;
            s.r[s.np] = (a + b) % 17 == 0 ? 0.3 : 1.0; /* isolated: 0.3 + 1 < 1.9 */
            s.np++;
        }
    pk_dem_pairs c = {0};
    CHECK(pk_dem_pairs_build(&c, &s.g, s.x, s.r, s.np, 0.2) == 0);
    compare(&c, &s.g, s.x, s.r, s.np, "lattice");
    /* the scene has what it is for: −0 components in the serial forces */
    double *f = malloc(3 * s.np * sizeof *f);
    pk_dem_eval(&c, &s.g, s.x, s.r, s.np, 2.5, f, NULL, NULL);
    size_t zero = 0;
    for (size_t k = 0; k < 3 * s.np; k++)
        zero += f[k] == 0 && k % 3 != 2;
    CHECK(zero > s.np); /* every y component and the isolated grains' x */
    free(f);
    pk_dem_pairs_free(&c);
    scene_free(&s);
}

/* A list that is not in build order (two runs swapped): the serial code
 * then sums differently, and the parallel path must fall back to it. */
static void test_list_out_of_order(void)
{
    scene s = random_scene(3001, 2, 1, 60, F2, 9);
    pk_dem_pairs c = {0};
    CHECK(pk_dem_pairs_build(&c, &s.g, s.x, s.r, s.np, 0.2) == 0);
    size_t a = c.n / 3, b = 2 * c.n / 3;
    int32_t ti = c.i[a], tj = c.j[a];
    double sh[3];
    memcpy(sh, &c.sh[3 * a], sizeof sh);
    c.i[a] = c.i[b], c.j[a] = c.j[b];
    memcpy(&c.sh[3 * a], &c.sh[3 * b], sizeof sh);
    c.i[b] = ti, c.j[b] = tj;
    memcpy(&c.sh[3 * b], sh, sizeof sh);
    compare(&c, &s.g, s.x, s.r, s.np, "out of order");
    pk_dem_pairs_free(&c);
    scene_free(&s);
}

/* Rebuilds: after the grains move on and the list is rebuilt the per-grain
 * lists must follow (same grain count), also for fewer grains and a list
 * shortened by hand (another n). */
static void test_rebuild(void)
{
    scene s = random_scene(3001, 2, 1, 60, F2, 10);
    pk_dem_pairs c = {0};
    pk_par *par = pk_par_new(2);
    CHECK(pk_dem_pairs_build(&c, &s.g, s.x, s.r, s.np, 0.2) == 0);
    c.par = par;
    double *f = malloc(3 * s.np * sizeof *f);
    pk_dem_eval_forces(&c, &s.g, s.x, s.r, s.np, 2.5, f); /* per-grain lists built here */
    jiggle(&s, 1.0, 2);
    CHECK(pk_dem_pairs_stale(&c, s.x, 2));
    CHECK(pk_dem_pairs_build(&c, &s.g, s.x, s.r, s.np, 0.2) == 0);
    CHECK(c.par == par); /* the pool survives a rebuild */
    compare(&c, &s.g, s.x, s.r, s.np, "rebuilt");
    c.par = par;
    pk_dem_eval_forces(&c, &s.g, s.x, s.r, s.np, 2.5, f);
    CHECK(pk_dem_pairs_build(&c, &s.g, s.x, s.r, 2000, 0.2) == 0);
    compare(&c, &s.g, s.x, s.r, 2000, "rebuilt, fewer grains");
    c.n -= 3;
    compare(&c, &s.g, s.x, s.r, 2000, "shortened");
    free(f);
    pk_dem_pairs_free(&c);
    pk_par_free(par);
    scene_free(&s);
}

/* Fewer candidates than the threads' ranges of 8: empty parts. */
static void test_tiny_lists(void)
{
    for (size_t np = 2; np <= 12; np += 5) {
        scene s = random_scene(np, 2, 1, 6, F2, 20 + np);
        pk_dem_pairs c = {0};
        CHECK(pk_dem_pairs_build(&c, &s.g, s.x, s.r, s.np, 0.2) == 0);
        compare(&c, &s.g, s.x, s.r, s.np, "tiny");
        pk_dem_pairs_free(&c);
        scene_free(&s);
    }
}

int main(void)
{
    pk_dem_par_min_pairs = 0; /* the parallel path for every list */
    RUN(test_2d_periodic);
    RUN(test_2d_periodic_classes);
    RUN(test_2d_open_box);
    RUN(test_3d_periodic_classes);
    RUN(test_3d_open_box);
    RUN(test_lattice_signed_zeros);
    RUN(test_list_out_of_order);
    RUN(test_rebuild);
    RUN(test_tiny_lists);
    return check_summary();
}
