#include "dem_contact.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "grid.h"
#include "homog_tensor.h"

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
    if (c->n == c->cap) {
        size_t cap = c->cap ? 2 * c->cap : 1024;
        int32_t *ni = realloc(c->i, cap * sizeof *ni);
        if (ni)
            c->i = ni;
        int32_t *nj = realloc(c->j, cap * sizeof *nj);
        if (nj)
            c->j = nj;
        double *nl = realloc(c->l, 3 * cap * sizeof *nl);
        if (nl)
            c->l = nl;
        double *nn = realloc(c->len, cap * sizeof *nn);
        if (nn)
            c->len = nn;
        double *ne = realloc(c->eps, cap * sizeof *ne);
        if (ne)
            c->eps = ne;
        double *nk = c->kclass ? realloc(c->kf, cap * sizeof *nk) : c->kf;
        if (nk)
            c->kf = nk;
        if (!ni || !nj || !nl || !nn || !ne || (c->kclass && !nk))
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

/* Reference-frame difference s_j − s_i = F⁻¹(x_j − x_i), minimum image. */
static void ref_diff(const pk_dem_geom *g, const double *xi, const double *xj, double ds[3])
{
    double d[3] = {xj[0] - xi[0], xj[1] - xi[1], g->dim == 3 ? xj[2] - xi[2] : 0};
    pk_m3_vec(g->Finv, d, ds);
    if (g->periodic)
        for (int k = 0; k < g->dim; k++)
            ds[k] -= g->L[k] * nearbyint(ds[k] / g->L[k]);
    if (g->dim == 2)
        ds[2] = 0;
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
    double ds[3];
    ref_diff(b->g, &b->x[3 * b->i], &b->x[3 * j], ds);
    double lim = (b->r[b->i] + b->r[j] + b->skin) * b->inv_smin;
    if (ds[0] * ds[0] + ds[1] * ds[1] + ds[2] * ds[2] < lim * lim &&
        pairs_push(b->c, (int32_t)b->i, (int32_t)j) != 0) {
        b->fail = 1;
        return 1;
    }
    return 0;
}

int pk_dem_pairs_build(pk_dem_pairs *c, const pk_dem_geom *g, const double *x, const double *r,
                       size_t np, double skin)
{
    const int dim = g->dim;
    c->n = 0;
    c->skin = skin;
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

/* Round to nearest, ties to even (= nearbyint in the default rounding mode)
 * without a libm call: exact for |v| < 2⁵¹. */
static inline double round_even(double v)
{
    const double big = 0x1.8p52;
    return fabs(v) < 0x1p51 ? (v + big) - big : nearbyint(v);
}

/* Forces are scattered with the sum on i kept in registers while the pairs
 * of one i follow each other (the build lists them by i): the read-modify-
 * write chain through f[i] was the latency bound of the loop. */
#define FLUSH_I(dim_)                                                                          \
    do {                                                                                       \
        if (f && icur != SIZE_MAX)                                                             \
            for (int a_ = 0; a_ < (dim_); a_++)                                                \
                f[3 * icur + a_] += fi[a_];                                                    \
    } while (0)

/* pk_dem_eval for 2D: the same operations as the generic loop with the
 * vanishing third components dropped (x·0 terms), so the same numbers
 * (tests/unit/test_homog_newton.c) at a fraction of the cost — this loop is
 * most of the cost of a DR iteration.  The flags are constants at each call
 * (eval_2d below), so the compiler drops the branches of what is not asked;
 * F and F⁻¹ are read into locals once (the stores to the pair arrays could
 * alias them otherwise). */
static inline size_t eval_2d_loop(pk_dem_pairs *c, const pk_dem_geom *g, const double *x,
                                  const double *r, double E, double *f, double *phi_out,
                                  double S[9], const int per, const int want_phi, const int want_S)
{
    const double F0 = g->F[0], F1 = g->F[1], F3 = g->F[3], F4 = g->F[4];
    const double G0 = g->Finv[0], G1 = g->Finv[1], G3 = g->Finv[3], G4 = g->Finv[4];
    const double L0 = g->L[0], L1 = g->L[1];
    const double iL0 = per ? 1 / L0 : 0, iL1 = per ? 1 / L1 : 0;
    const double *kf = c->kf;
    const int32_t *pi = c->i, *pj = c->j;
    double *pl = c->l, *plen = c->len, *peps = c->eps;
    double phi = 0, fi0 = 0, fi1 = 0, S0 = 0, S1 = 0, S3 = 0, S4 = 0;
    size_t nc = 0, icur = SIZE_MAX;
    /* Two passes: the geometry of every candidate (a long dependent chain
     * per pair: min image, √, overlap), then the forces of the contacts —
     * short loop bodies keep more pairs in flight (measured 15 % faster). */
    for (size_t p = 0; p < c->n; p++) {
        size_t i = (size_t)pi[p], j = (size_t)pj[p];
        double d0 = x[3 * j] - x[3 * i], d1 = x[3 * j + 1] - x[3 * i + 1];
        if (per) { /* ref_diff + F·ds, as pk_dem_branch */
            double s0 = G0 * d0 + G1 * d1, s1 = G3 * d0 + G4 * d1;
            s0 -= L0 * round_even(s0 * iL0);
            s1 -= L1 * round_even(s1 * iL1);
            d0 = F0 * s0 + F1 * s1;
            d1 = F3 * s0 + F4 * s1;
        }
        pl[3 * p] = d0, pl[3 * p + 1] = d1, pl[3 * p + 2] = 0;
        double len = sqrt(d0 * d0 + d1 * d1);
        plen[p] = len;
        peps[p] = r[i] + r[j] - len; /* (4.1) */
    }
    for (size_t p = 0; p < c->n; p++) {
        double eps = peps[p], len = plen[p];
        if (!(eps >= 0) || !(len > 0))
            continue;
        size_t i = (size_t)pi[p], j = (size_t)pj[p];
        double d0 = pl[3 * p], d1 = pl[3 * p + 1];
        nc++;
        double k = kf ? E * kf[p] : E; /* pk_dem_pair_E */
        if (want_phi)
            phi += 0.5 * k * eps * eps; /* (4.3) */
        double t = k * eps / len;       /* (4.8): f_ij = −t l on i, one division */
        double fa0 = -t * d0, fa1 = -t * d1;
        if (f) {
            if (i != icur) {
                if (icur != SIZE_MAX)
                    f[3 * icur] += fi0, f[3 * icur + 1] += fi1;
                icur = i, fi0 = fi1 = 0;
            }
            fi0 += fa0, fi1 += fa1;
            f[3 * j] -= fa0, f[3 * j + 1] -= fa1;
        }
        if (want_S) {
            S0 += fa0 * d0, S1 += fa0 * d1;
            S3 += fa1 * d0, S4 += fa1 * d1;
        }
    }
    if (f && icur != SIZE_MAX)
        f[3 * icur] += fi0, f[3 * icur + 1] += fi1;
    if (want_S)
        S[0] = S0, S[1] = S1, S[3] = S3, S[4] = S4;
    if (phi_out)
        *phi_out = phi;
    return nc;
}

static size_t eval_2d(pk_dem_pairs *c, const pk_dem_geom *g, const double *x, const double *r,
                      double E, double *f, double *energy, double S[9])
{
    if (!g->periodic)
        return eval_2d_loop(c, g, x, r, E, f, energy, S, 0, 1, S != NULL);
    if (S || energy)
        return eval_2d_loop(c, g, x, r, E, f, energy, S, 1, 1, S != NULL);
    return eval_2d_loop(c, g, x, r, E, f, NULL, NULL, 1, 0, 0); /* the DR iteration */
}

size_t pk_dem_eval(pk_dem_pairs *c, const pk_dem_geom *g, const double *x, const double *r,
                   size_t np, double E, double *f, double *energy, double S[9])
{
    const int dim = g->dim;
    if (f)
        memset(f, 0, 3 * np * sizeof *f);
    if (S)
        memset(S, 0, 9 * sizeof *S);
    if (dim == 2)
        return eval_2d(c, g, x, r, E, f, energy, S);
    double phi = 0, fi[3] = {0, 0, 0};
    size_t nc = 0, icur = SIZE_MAX;
    for (size_t p = 0; p < c->n; p++) {
        size_t i = (size_t)c->i[p], j = (size_t)c->j[p];
        double *l = &c->l[3 * p];
        pk_dem_branch(g, &x[3 * i], &x[3 * j], l);
        double len = sqrt(l[0] * l[0] + l[1] * l[1] + l[2] * l[2]);
        double eps = r[i] + r[j] - len; /* (4.1) */
        c->len[p] = len;
        c->eps[p] = eps;
        if (!(eps >= 0) || !(len > 0)) /* (4.2); coincident centres carry no direction */
            continue;
        nc++;
        double k = pk_dem_pair_E(c, p, E);
        phi += 0.5 * k * eps * eps; /* (4.3), each contact once (4.7) */
        double t = k * eps / len;   /* f_ij = −E ε n_ij = −t l on i (4.8) */
        if (i != icur) {
            FLUSH_I(dim);
            icur = i, fi[0] = fi[1] = fi[2] = 0;
        }
        for (int a = 0; a < dim; a++) {
            double fa = -t * l[a];
            fi[a] += fa;
            if (f)
                f[3 * j + a] -= fa;
            if (S)
                for (int b = 0; b < dim; b++)
                    S[3 * a + b] += fa * l[b];
        }
    }
    FLUSH_I(dim);
    if (energy)
        *energy = phi;
    return nc;
}
#undef FLUSH_I

/* k_ij·d with k_ij = E/|l| [ε 1 − R n⊗n] (4.12)₁ (pk_dem_kblock_coef) */
static inline void kblock_apply(int dim, double E, double len, double eps, const double *l,
                                const double *d, double *out)
{
    double a, b, ld = 0;
    pk_dem_kblock_coef(E, len, eps, &a, &b);
    for (int k = 0; k < dim; k++)
        ld += l[k] * d[k];
    for (int k = 0; k < dim; k++)
        out[k] = a * d[k] - b * ld * l[k];
}

/* The K·v loop; pk_dem_kv calls it with dim a constant (2 or 3), so the
 * compiler unrolls the axis loops — the same operations in the same order,
 * at fewer instructions (it runs 40 times per DR estimate refresh). */
static inline void kv_loop(const pk_dem_pairs *c, const int dim, double E, const uint8_t *mask,
                           const double *v, double *out)
{
    for (size_t p = 0; p < c->n; p++) {
        if (!(c->eps[p] >= 0) || !(c->len[p] > 0))
            continue;
        size_t i = (size_t)c->i[p], j = (size_t)c->j[p];
        int mi = mask[i] != 0, mj = mask[j] != 0;
        if (!mi && !mj)
            continue;
        double d[3] = {0, 0, 0}, kd[3];
        for (int a = 0; a < dim; a++)
            d[a] = (mj ? v[3 * j + a] : 0) - (mi ? v[3 * i + a] : 0);
        /* (K v)_i = Σ_j k_ij (v_j − v_i) by (4.14) */
        kblock_apply(dim, pk_dem_pair_E(c, p, E), c->len[p], c->eps[p], &c->l[3 * p], d, kd);
        for (int a = 0; a < dim; a++) {
            if (mi)
                out[3 * i + a] += kd[a];
            if (mj)
                out[3 * j + a] -= kd[a];
        }
    }
}

void pk_dem_kv(const pk_dem_pairs *c, int dim, size_t np, double E, const uint8_t *mask,
               const double *v, double *out)
{
    memset(out, 0, 3 * np * sizeof *out);
    if (dim == 2)
        kv_loop(c, 2, E, mask, v, out);
    else
        kv_loop(c, dim, E, mask, v, out);
}

double pk_dem_gershgorin(const pk_dem_pairs *c, int dim, size_t np, double E, const uint8_t *mask)
{
    double *row = calloc(3 * (np ? np : 1), sizeof *row);
    if (!row)
        return INFINITY;
    for (size_t p = 0; p < c->n; p++) {
        if (!(c->eps[p] >= 0) || !(c->len[p] > 0))
            continue;
        size_t i = (size_t)c->i[p], j = (size_t)c->j[p];
        const double *l = &c->l[3 * p];
        double len = c->len[p], eps = c->eps[p], R = eps + len;
        double cc = pk_dem_pair_E(c, p, E) / len;
        for (int a = 0; a < dim; a++) {
            double s = 0; /* Σ_b |k_ab| */
            for (int b = 0; b < dim; b++)
                s += fabs(cc * ((a == b ? eps : 0) - R * l[a] * l[b] / (len * len)));
            /* the block enters the diagonal of both and the off-diagonal once */
            if (mask[i])
                row[3 * i + a] += s * (mask[j] ? 2 : 1);
            if (mask[j])
                row[3 * j + a] += s * (mask[i] ? 2 : 1);
        }
    }
    double m = 0;
    for (size_t k = 0; k < 3 * np; k++)
        m = fmax(m, row[k]);
    free(row);
    return m;
}
