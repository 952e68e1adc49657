/* dem_pairs.c — geometry under F̄, the candidate list (Verlet list with a skin,
 * from the shared pk_grid) and each candidate's periodic image; contract: dem_contact.h. */
#include "dem_contact.h"

#include <assert.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/base/grow.h"

#include "core/space/mat3.h"
#include "core/space/grid.h"
#include "dem_internal.h"

double pk_dem_geom_set_F(pk_dem_geom *g, const double F[9])
{
    double Fi[9];
    double d = pk_m3_inv(F, Fi);
    if (d == 0 || !isfinite(d))
        return 0;
    memcpy(g->F, F, sizeof g->F);
    memcpy(g->Finv, Fi, sizeof g->Finv);
    return d;
}

void pk_dem_pairs_free(pk_dem_pairs *c)
{
    free(c->i);
    free(c->j);
    free(c->l);
    free(c->len);
    free(c->eps);
    free(c->xb);
    free(c->kf);
    free(c->sh);
    free(c->fa);
    free(c->ord);
    free(c->bofs);
    free(c->jofs);
    free(c->jq);
    free(c->iofs);
    memset(c, 0, sizeof *c);
}

void pk_dem_pairs_stiffness(pk_dem_pairs *c, const int32_t *kclass, const double *kmat,
                            size_t nclass, double kref)
{
    c->kclass = kmat && nclass && kref > 0 ? kclass : NULL;
    c->kmat = kmat;
    c->nclass = nclass;
    c->kref = kref;
}

static int pairs_push(pk_dem_pairs *c, int32_t i, int32_t j)
{
    assert(0 <= i && i < j && (size_t)j < c->np); /* each pair once, i < j */
    if (c->n == c->cap) {
        const size_t cap = pk_grow_cap(c->cap, c->n + 1, 1024);
        const pk_grow_item arrays[] = {
            PK_GROW_ITEM(c->i, 1),
            PK_GROW_ITEM(c->j, 1),
            PK_GROW_ITEM(c->l, 3),
            PK_GROW_ITEM(c->len, 1),
            PK_GROW_ITEM(c->eps, 1),
            PK_GROW_ITEM(c->sh, 3),
            {c->kclass ? (void *)&c->kf : NULL, sizeof *c->kf},
        };
        if (pk_grow(arrays, sizeof arrays / sizeof *arrays, cap) != 0)
            return -1;
        c->cap = cap;
    }
    c->i[c->n] = i;
    c->j[c->n] = j;
    if (c->kclass)
        c->kf[c->n] = c->kmat[(size_t)c->kclass[i] * c->nclass + (size_t)c->kclass[j]] / c->kref;
    c->n++;
    return 0;
}

/* Reference-frame difference s_j − s_i = F⁻¹(x_j − x_i), minimum image:
 * ds = s + t with the lattice vector t = −L∘k, k = round(s/L) (t = 0 on an
 * open box). */
static void ref_image(const pk_dem_geom *g, const double *xi, const double *xj, double ds[3],
                      double t[3])
{
    double d[3] = {xj[0] - xi[0], xj[1] - xi[1], g->dim == 3 ? xj[2] - xi[2] : 0};
    pk_m3_vec(g->Finv, d, ds);
    t[0] = t[1] = t[2] = 0;
    if (g->periodic)
        for (int k = 0; k < g->dim; k++) {
            t[k] = -g->L[k] * nearbyint(ds[k] / g->L[k]);
            ds[k] += t[k];
        }
    if (g->dim == 2)
        ds[2] = 0;
}

static void ref_diff(const pk_dem_geom *g, const double *xi, const double *xj, double ds[3])
{
    double t[3];
    ref_image(g, xi, xj, ds, t);
}

/* Candidate p's lattice shift in the current frame, sh = F̄ t (ref_image). */
static void set_shift(pk_dem_pairs *c, const pk_dem_geom *g, size_t p, const double t[3])
{
    double *sh = &c->sh[3 * p];
    if (t[0] == 0 && t[1] == 0 && t[2] == 0) { /* most pairs: no boundary crossed */
        sh[0] = sh[1] = sh[2] = 0;
        return;
    }
    pk_m3_vec(g->F, t, sh);
    if (g->dim == 2)
        sh[2] = 0;
}

/* The geometry the shifts of c belong to. */
static void shifts_stamp(pk_dem_pairs *c, const pk_dem_geom *g)
{
    memcpy(c->sh_F, g->F, sizeof c->sh_F);
    memcpy(c->sh_L, g->L, sizeof c->sh_L);
    c->sh_dim = g->dim;
    c->sh_periodic = g->periodic;
    c->sh_ok = 1;
}

/* The lattice shift of every candidate at x under g, so that x_j − x_i + sh
 * is the branch vector (the build sets them as it lists the pairs). */
static void pair_shifts(pk_dem_pairs *c, const pk_dem_geom *g, const double *x)
{
    for (size_t p = 0; p < c->n; p++) {
        double ds[3], t[3];
        ref_image(g, &x[3 * (size_t)c->i[p]], &x[3 * (size_t)c->j[p]], ds, t);
        set_shift(c, g, p, t);
    }
    shifts_stamp(c, g);
}

/* The shifts in c belong to g? */
static int shifts_match(const pk_dem_pairs *c, const pk_dem_geom *g)
{
    return c->sh_ok && c->sh_dim == g->dim && c->sh_periodic == g->periodic &&
        memcmp(c->sh_F, g->F, sizeof c->sh_F) == 0 && memcmp(c->sh_L, g->L, sizeof c->sh_L) == 0;
}

void pk_dem_pairs_fit_images(pk_dem_pairs *c, const pk_dem_geom *g, const double *x)
{
    if (g->periodic && !shifts_match(c, g))
        pair_shifts(c, g, x);
}

typedef struct build_ctx {
    pk_dem_pairs *c;
    const pk_dem_geom *g;
    const double *x, *r;
    size_t i;
    double inv_smin, skin;
    int fail;
} build_ctx;

static int visit(size_t j, const double dx[PK_MAXDIM], double dist2, void *vctx)
{
    (void)dx;
    (void)dist2;
    build_ctx *b = vctx;
    if (j <= b->i)
        return 0;
    double ds[3], t[3];
    ref_image(b->g, &b->x[3 * b->i], &b->x[3 * j], ds, t);
    double lim = (b->r[b->i] + b->r[j] + b->skin) * b->inv_smin;
    if (!(ds[0] * ds[0] + ds[1] * ds[1] + ds[2] * ds[2] < lim * lim))
        return 0;
    if (pairs_push(b->c, (int32_t)b->i, (int32_t)j) != 0) {
        b->fail = 1;
        return 1;
    }
    set_shift(b->c, b->g, b->c->n - 1, t);
    return 0;
}

int pk_dem_pairs_build(pk_dem_pairs *c, const pk_dem_geom *g, const double *x, const double *r,
                       size_t np, double skin)
{
    const int dim = g->dim;
    c->n = 0;
    c->skin = skin;
    c->sh_ok = 0;
    c->csr_state = 0;
    if (c->kclass && !c->kf && c->cap) { /* classes set after an earlier build */
        c->kf = malloc(c->cap * sizeof *c->kf);
        if (!c->kf)
            return -1;
    }
    if (c->np != np || !c->xb) {
        free(c->xb);
        c->xb = malloc(3 * (np ? np : 1) * sizeof *c->xb);
        if (!c->xb)
            return -1;
        c->np = np;
    }
    memcpy(c->xb, x, 3 * np * sizeof *x);
    if (np < 2)
        return 0;
    double rmin = INFINITY, rmax = 0;
    for (size_t i = 0; i < np; i++) {
        rmin = fmin(rmin, r[i]);
        rmax = fmax(rmax, r[i]);
    }
    /* |F ds| >= σ_min |ds|: a contact needs |ds| < (R + skin)/σ_min (σ_min >= 1 is
     * not used to shrink the search: factor 1 then) */
    double smin = pk_m3_sigma_min(g->F, dim);
    if (!(smin > 0))
        return -2;
    double inv_smin = fmax(1.0, 1.0 / smin);
    double reach_max = (2 * rmax + skin) * inv_smin;
    pk_box box = {.dim = dim};
    double off[3] = {0, 0, 0};
    if (g->periodic) {
        for (int k = 0; k < dim; k++) {
            if (!(2 * reach_max < g->L[k]))
                return -2;
            box.L[k] = g->L[k];
            box.periodic[k] = true;
        }
    } else {
        double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        for (size_t i = 0; i < np; i++) {
            double s[3];
            pk_m3_vec(g->Finv, &x[3 * i], s);
            for (int k = 0; k < dim; k++) {
                lo[k] = fmin(lo[k], s[k]);
                hi[k] = fmax(hi[k], s[k]);
            }
        }
        for (int k = 0; k < dim; k++) {
            off[k] = reach_max - lo[k];
            box.L[k] = hi[k] - lo[k] + 2 * reach_max;
        }
    }
    pk_particles ref;
    if (pk_particles_init(&ref, dim, np) != 0)
        return -1;
    for (size_t i = 0; i < np; i++) {
        double s[3];
        pk_m3_vec(g->Finv, &x[3 * i], s);
        for (int k = 0; k < 3; k++)
            s[k] = k < dim ? s[k] + off[k] : 0;
        pk_box_wrap(&box, s);
        pk_particles_push(&ref, s, r[i], 0);
    }
    pk_grid grid;
    if (pk_grid_init(&grid, &box, rmin, rmax, 0, np) != 0) {
        pk_particles_free(&ref);
        return -1;
    }
    int rc = 0;
    for (size_t i = 0; i < np && rc == 0; i++)
        if (pk_grid_insert(&grid, &ref, i) != 0)
            rc = -1;
    build_ctx b = {.c = c, .g = g, .x = x, .r = r, .inv_smin = inv_smin, .skin = skin};
    /* grid contact distance is r_i + r_j + extra in reference units */
    for (size_t i = 0; i < np && rc == 0; i++) {
        b.i = i;
        double extra = (r[i] + rmax + skin) * inv_smin - r[i] - rmax;
        pk_grid_query(&grid, &ref, &ref.x[3 * i], r[i], extra, visit, &b);
        if (b.fail)
            rc = -1;
    }
    pk_grid_free(&grid);
    pk_particles_free(&ref);
    /* A candidate's image stays its minimum image until the next build: the
     * box check above gives L_k > 2(2 r_max + skin)/σ_min(F̄); a pair in
     * contact at some later x (grains moved < skin/2 each, so |Δl| < skin)
     * is within (R + 2 skin)/σ_min of its build image in the reference frame
     * and any other image is more than L_k − R/σ_min >= (2 r_max + 2 skin)/σ_min
     * away — the contacts and their l are those of the per-pair minimum image
     * (non-contacts may keep a farther image: still no contact). */
    if (rc == 0)
        shifts_stamp(c, g);
    return rc;
}

/* The skin test with dim a constant (2 or 3): the axis loop unrolled. */
static inline int stale_loop(const pk_dem_pairs *c, const double *x, const int dim)
{
    double lim2 = 0.25 * c->skin * c->skin;
    for (size_t i = 0; i < c->np; i++) {
        double s = 0;
        for (int k = 0; k < dim; k++) {
            double d = x[3 * i + k] - c->xb[3 * i + k];
            s += d * d;
        }
        if (s > lim2)
            return 1;
    }
    return 0;
}

int pk_dem_pairs_stale(const pk_dem_pairs *c, const double *x, int dim)
{
    return dim == 2 ? stale_loop(c, x, 2) : stale_loop(c, x, dim);
}

void pk_dem_branch(const pk_dem_geom *g, const double *xi, const double *xj, double l[3])
{
    if (g->periodic) {
        double ds[3];
        ref_diff(g, xi, xj, ds);
        pk_m3_vec(g->F, ds, l);
    } else {
        for (int k = 0; k < 3; k++)
            l[k] = xj[k] - xi[k];
    }
    if (g->dim == 2)
        l[2] = 0;
}
