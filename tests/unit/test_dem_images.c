/* test_dem_images.c — the periodic image of each candidate pair is fixed at
 * the list's build (pk_dem_pairs.sh, core/dem/dem_pairs.c): pk_dem_eval must
 * still give the contacts and forces of the minimum image at the positions
 * and F̄ it is given —
 *   - after F̄ changed on the same list, grains not moved (the images are
 *     formed afresh, never stale);
 *   - after grains moved by up to skin/2 without a rebuild (the bound the
 *     build's comment proves: a candidate's image cannot change);
 *   - with grains many periods out of the box (large lattice shifts);
 * 2D (scalar loop and AVX2 lanes) and 3D.  The reference is an independent
 * brute-force search over all pairs and the nearest lattice images. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "core/dem/dem_contact.h"
#include "core/space/mat3.h"
#include "core/base/rng.h"

#define E_N 3.0

typedef struct scene {
    int dim;
    size_t n;
    double L, *x, *r;
    pk_dem_geom g;
} scene;

static void scene_make(scene *s, int dim, const double F[9])
{
    pk_rng rng;
    pk_rng_seed(&rng, 23, (uint64_t)dim);
    s->dim = dim;
    s->n = dim == 2 ? 300 : 250;
    s->L = dim == 2 ? 20 : 9;
    s->x = malloc(3 * s->n * sizeof *s->x);
    s->r = malloc(s->n * sizeof *s->r);
    s->g = (pk_dem_geom){.dim = dim, .periodic = 1, .L = {s->L, s->L, dim == 3 ? s->L : 0}};
    CHECK(pk_dem_geom_set_F(&s->g, F) > 0);
    for (size_t i = 0; i < s->n; i++) {
        double q[3] = {0, 0, 0};
        for (int k = 0; k < dim; k++)
            q[k] = pk_rng_range(&rng, 0, s->L);
        pk_m3_vec(F, q, &s->x[3 * i]);
        s->r[i] = pk_rng_range(&rng, 0.4, 0.8);
    }
}

static void scene_free(scene *s)
{
    free(s->x);
    free(s->r);
}

/* Forces and contact count of the minimum images by brute force: every pair,
 * the reference difference rounded to the box, then the nearest of the
 * neighbouring lattice images in the deformed frame. */
static size_t brute_forces(const scene *s, const double *x, const pk_dem_geom *g, double *f)
{
    const int dim = s->dim;
    memset(f, 0, 3 * s->n * sizeof *f);
    size_t nc = 0;
    for (size_t i = 0; i < s->n; i++)
        for (size_t j = i + 1; j < s->n; j++) {
            double d[3] = {0, 0, 0}, q[3], best[3] = {0, 0, 0}, bl = INFINITY;
            for (int k = 0; k < dim; k++)
                d[k] = x[3 * j + k] - x[3 * i + k];
            pk_m3_vec(g->Finv, d, q);
            for (int k = 0; k < dim; k++)
                q[k] -= s->L * round(q[k] / s->L);
            int m3 = dim == 3 ? 1 : 0;
            for (int a = -1; a <= 1; a++)
                for (int b = -1; b <= 1; b++)
                    for (int e = -m3; e <= m3; e++) {
                        double qs[3] = {q[0] + a * s->L, q[1] + b * s->L,
                                        dim == 3 ? q[2] + e * s->L : 0};
                        double l[3];
                        pk_m3_vec(g->F, qs, l);
                        double len = sqrt(l[0] * l[0] + l[1] * l[1] + l[2] * l[2]);
                        if (len < bl)
                            bl = len, memcpy(best, l, sizeof best);
                    }
            double eps = s->r[i] + s->r[j] - bl;
            if (!(eps >= 0) || !(bl > 0))
                continue;
            nc++;
            for (int k = 0; k < dim; k++) {
                double fa = -E_N * eps * best[k] / bl; /* (4.8) on i */
                f[3 * i + k] += fa;
                f[3 * j + k] -= fa;
            }
        }
    return nc;
}

/* pk_dem_eval through c at (x, g) against the brute force: same contacts,
 * forces equal within tol (absolute, force units). */
static void agree(pk_dem_pairs *c, const scene *s, const double *x, const pk_dem_geom *g,
                  double tol, const char *what)
{
    double *f = malloc(3 * s->n * sizeof *f), *fb = malloc(3 * s->n * sizeof *fb);
    size_t nc = pk_dem_eval(c, g, x, s->r, s->n, E_N, f, NULL, NULL);
    size_t nb = brute_forces(s, x, g, fb);
    double err = 0, fbig = 0;
    for (size_t k = 0; k < 3 * s->n; k++) {
        err = fmax(err, fabs(f[k] - fb[k]));
        fbig = fmax(fbig, fabs(fb[k]));
    }
    CHECK_MSG(nc == nb && err <= tol,
              "dim %d %s (%s): %zu contacts, brute force %zu, max |Δf| %.3g", s->dim, what,
              pk_dem_scalar_only ? "scalar" : "lanes", nc, nb, err);
    CHECK(nb > 20 && fbig > 0.1); /* a real test: contacts with forces */
    free(f);
    free(fb);
}

/* Round-off of the two forms of l (x_j − x_i − F̄L k against F̄(F̄⁻¹(x_j − x_i) − L k))
 * is a few ulp of L ≈ 1e-14 on overlaps ~0.1 and E = 3: 1e-11 leaves 3
 * decades; a stale image would be off by |ΔF̄|·L ≈ 0.1–0.4. */
#define TOL_ROUND 1e-11

static void images_follow(int dim)
{
    double F1[9] = {0.98, 0.25, 0, 0.03, 1.01, 0, 0, 0, 1};
    if (dim == 3)
        F1[2] = 0.08, F1[5] = -0.04, F1[8] = 0.99;
    for (int scalar = 0; scalar <= (dim == 2); scalar++) {
        pk_dem_scalar_only = scalar;
        scene s;
        scene_make(&s, dim, F1);
        const double skin = 0.5;
        pk_dem_pairs c = {0};
        CHECK(pk_dem_pairs_build(&c, &s.g, s.x, s.r, s.n, skin) == 0);
        agree(&c, &s, s.x, &s.g, TOL_ROUND, "at the build");

        /* a new F̄ on the same list, grains where they are: a 2 % shear more
         * (the contacts move by < 0.02·(R + skin) — within the skin, so the
         * list still holds them; the images of pairs across the boundary
         * move by 0.02·L = 0.2–0.4) */
        pk_dem_geom g2 = s.g;
        double F2[9];
        memcpy(F2, F1, sizeof F2);
        F2[1] += 0.02;
        CHECK(pk_dem_geom_set_F(&g2, F2) > 0);
        agree(&c, &s, s.x, &g2, TOL_ROUND, "new F, same list");
        agree(&c, &s, s.x, &s.g, TOL_ROUND, "back to the build's F");

        /* grains moved by 0.49·skin in random directions, no rebuild */
        double *xm = malloc(3 * s.n * sizeof *xm);
        pk_rng rng;
        pk_rng_seed(&rng, 29, (uint64_t)dim);
        for (size_t i = 0; i < s.n; i++) {
            double u[3] = {0, 0, 0}, uu = 0;
            for (int k = 0; k < dim; k++)
                u[k] = pk_rng_range(&rng, -1, 1), uu += u[k] * u[k];
            for (int k = 0; k < 3; k++)
                xm[3 * i + k] = s.x[3 * i + k] + 0.49 * skin * u[k] / sqrt(uu);
        }
        CHECK(!pk_dem_pairs_stale(&c, xm, dim));
        agree(&c, &s, xm, &s.g, TOL_ROUND, "moved < skin/2");

        /* every third grain many periods out: x + F̄(L∘k), |k| up to 1000;
         * round-off of |x| ≈ 2e4 is ulp 4e-12 per coordinate: tol 1e-9 */
        for (size_t i = 0; i < s.n; i += 3) {
            double k[3] = {0, 0, 0}, t[3];
            for (int a = 0; a < dim; a++)
                k[a] = s.L * (double)((int)(i * 7 + (size_t)a * 13) % 2001 - 1000);
            pk_m3_vec(F1, k, t);
            for (int a = 0; a < dim; a++)
                xm[3 * i + a] = s.x[3 * i + a] + t[a];
        }
        for (size_t i = 1; i < s.n; i += 3)
            memcpy(&xm[3 * i], &s.x[3 * i], 3 * sizeof *xm);
        for (size_t i = 2; i < s.n; i += 3)
            memcpy(&xm[3 * i], &s.x[3 * i], 3 * sizeof *xm);
        CHECK(pk_dem_pairs_build(&c, &s.g, xm, s.r, s.n, skin) == 0);
        agree(&c, &s, xm, &s.g, 1e-9, "grains many periods out");
        free(xm);
        pk_dem_pairs_free(&c);
        scene_free(&s);
    }
    pk_dem_scalar_only = 0;
}

static void test_images_2d(void) { images_follow(2); }
static void test_images_3d(void) { images_follow(3); }

int main(void)
{
    RUN(test_images_2d);
    RUN(test_images_3d);
    return check_summary();
}
